#include "shade_kernel.h"

#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/shading/dual_scattering_shader.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <span>
#include <stdexcept>

namespace hairvox {

namespace {

std::uint64_t paramsDigest(const FiberParams& p) {
    Hasher h;
    p.hashInto(h);
    return h.digest();
}

DualScatteringTables tablesFor(const DualScatteringTables& tables, float d_b) {
    return tables.options().d_b == d_b ? tables : tables.withBackwardDensity(d_b);
}

} // namespace

DualScatteringShader::DualScatteringShader(const MarschnerBcsdf& bcsdf,
                                           const DualScatteringTables& tables,
                                           const DualScatteringParams& params)
    : bcsdf_(bcsdf)
    , tables_(tablesFor(tables, params.d_b))
    , params_(params) {
    params_.validate();
    if (paramsDigest(bcsdf.params()) != paramsDigest(tables.params()))
        throw std::invalid_argument(strCat("DualScatteringShader: tables built for ",
                                           tables.params(), " used with ", bcsdf.params()));
}

namespace {

/// The kernel's view of the shader, for a light of angular variance
/// `spread2` per axis (rad²): θ_i spread by it spreads θ_h = (θ_i + θ_o)/2 by
/// a quarter of it, a variance every longitudinal lobe adds to its own.
detail::ShadeKernelParams kernelParams(const DualScatteringShader& shader, float spread2 = 0) {
    detail::ShadeKernelParams p{detail::marschnerView(shader.bcsdf()),
                                detail::tablesView(shader.tables()), shader.params().d_b};
    if (spread2 > 0) {
        p.lightVariance = 0.25f * spread2;
        for (std::size_t lobe = 0; lobe < 3; ++lobe) {
            const LongitudinalLobe M(p.fs.alpha[lobe], p.fs.variance[lobe] + p.lightVariance);
            p.fs.variance[lobe] += p.lightVariance;
            p.fs.scale[lobe] = M.scale();
            p.fs.invTwoVariance[lobe] = M.invTwoVariance();
        }
    }
    return p;
}

/// The kernel's global-term rows of one point (detail::kV ... kSigma2B).
std::array<float, detail::kGlobalTermRows> globalTermRows(const GlobalTerm& g) {
    return {g.V, g.T_s.r, g.T_s.g, g.T_s.b, g.sigma2_f.r, g.sigma2_f.g, g.sigma2_f.b};
}

/// The shader at one point given by its angles: ShadeResult's 15 floats,
/// then f_s^scatter(σ_f²) and f_back(σ_f²).
std::array<float, detail::kShadeRows + detail::kShadeTermRows>
shadeOneAngle(const DualScatteringShader& shader, const FiberAngles& a, const GlobalTerm& g) {
    const auto angles = std::bit_cast<std::array<float, detail::kAngleRows>>(a);
    const auto term = globalTermRows(g);
    std::array<float, detail::kShadeRows + detail::kShadeTermRows> out;
    detail::shadeAngle(kernelParams(shader), angles.data(), term.data(), out.data());
    return out;
}

Rgb rgbAt(std::span<const float> values, std::size_t first) {
    return {values[first], values[first + 1], values[first + 2]};
}

ShadeResult shadeResultOf(std::span<const float> v) {
    return {rgbAt(v, 0), rgbAt(v, 3), rgbAt(v, 6), rgbAt(v, 9), rgbAt(v, 12)};
}

constexpr std::size_t kGlobalTermRow = detail::kDirectionRows;
constexpr std::size_t kIrradianceRow = kGlobalTermRow + detail::kGlobalTermRows;

} // namespace

void ShadeBatch::reset(std::size_t count) {
    static_assert(kInputRows == kIrradianceRow + 3 && kOutputRows == detail::kShadeRows &&
                  kGlobalTermFirstRow == kGlobalTermRow);
    count_ = count;
    // Whole vectors, plus one: rows a power of two apart (1024 points: 4 KiB)
    // would all map to the same L1 cache sets and evict each other.
    const std::size_t capacity =
        ((count + detail::kBatchAlignment - 1) / detail::kBatchAlignment + 1) *
        detail::kBatchAlignment;
    if (capacity != capacity_) {
        capacity_ = capacity;
        // Zeros in the padding: the kernel reads whole vectors.
        inputs_.assign(kInputRows * capacity_, 0.0f);
        radiance_.resize(kOutputRows * capacity_);
    }
    std::fill(radiance_.begin(), radiance_.end(), 0.0f);
}

void ShadeBatch::setView(std::size_t i, const Vec3f& wo, const Vec3f& u) {
    for (int c = 0; c < 3; ++c) {
        const auto uc = static_cast<std::size_t>(c);
        in(detail::kWoX + uc, i) = wo[c];
        in(detail::kUX + uc, i) = u[c];
    }
}

void ShadeBatch::setIncident(std::size_t i, const Vec3f& wi, const Rgb& E) {
    for (int c = 0; c < 3; ++c) {
        const auto uc = static_cast<std::size_t>(c);
        in(detail::kWiX + uc, i) = wi[c];
        in(kIrradianceRow + uc, i) = E[c];
    }
}

void ShadeBatch::setIncident(const Vec3f& wi, const Rgb& E) {
    for (int c = 0; c < 3; ++c) {
        const auto uc = static_cast<std::size_t>(c);
        std::fill_n(&in(detail::kWiX + uc, 0), count_, wi[c]);
        std::fill_n(&in(kIrradianceRow + uc, 0), count_, E[c]);
    }
}

ShadeResult ShadeBatch::radiance(std::size_t i) const {
    std::array<float, kOutputRows> v;
    for (std::size_t r = 0; r < kOutputRows; ++r)
        v[r] = radiance_[r * capacity_ + i];
    return shadeResultOf(v);
}

void DualScatteringShader::shade(ShadeBatch& batch, float spread2) const {
    if (batch.count_ == 0)
        return;
    const std::size_t n = batch.count_, capacity = batch.capacity_;
    const float* in = batch.inputs_.data();
    detail::shadeDirections(kernelParams(*this, spread2), {n, capacity, in},
                            {n, capacity, in + kGlobalTermRow * capacity},
                            {n, capacity, in + kIrradianceRow * capacity},
                            {n, capacity, batch.radiance_.data()});
}

ShadeResult DualScatteringShader::shade(const Vec3f& wi, const Vec3f& wo, const Vec3f& u,
                                        const GlobalTerm& g) const {
    const std::array<float, detail::kDirectionRows> directions{wi.x, wi.y, wi.z, wo.x, wo.y,
                                                               wo.z, u.x,  u.y,  u.z};
    const auto term = globalTermRows(g);
    const std::array<float, 3> irradiance{1.0f, 1.0f, 1.0f};
    std::array<float, detail::kShadeRows> radiance{};
    detail::shadeDirection(kernelParams(*this), directions.data(), term.data(), irradiance.data(),
                           radiance.data());
    return shadeResultOf(radiance);
}

ShadeResult DualScatteringShader::shade(const FiberAngles& a, const GlobalTerm& g) const {
    return shadeResultOf(shadeOneAngle(*this, a, g));
}

Rgb DualScatteringShader::fBack(const FiberAngles& a, const Rgb& sigma2) const {
    GlobalTerm g;
    g.sigma2_f = sigma2;
    return rgbAt(shadeOneAngle(*this, a, g), detail::kShadeRows + 3);
}

Rgb DualScatteringShader::fsScatter(const FiberAngles& a, const Rgb& sigma2_f) const {
    GlobalTerm g;
    g.sigma2_f = sigma2_f;
    return rgbAt(shadeOneAngle(*this, a, g), detail::kShadeRows);
}

} // namespace hairvox
