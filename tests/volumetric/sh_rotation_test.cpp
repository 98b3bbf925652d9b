#include "test_util.h"

#include <hairvox/core/rng.h>
#include <hairvox/core/sampling.h>
#include <hairvox/volumetric/sh_rotation.h>
#include <hairvox/volumetric/spherical_harmonics.h>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace hairvox {
namespace {

constexpr int L = SphericalHarmonics::kMaxOrder, nc = SphericalHarmonics::coefficients(L);

float synthesise(const float* c, const Vec3f& w, int order) {
    std::array<float, SphericalHarmonics::kMaxCoefficients> y{};
    SphericalHarmonics::evaluate(w, order, y.data());
    float v = 0;
    for (int i = 0; i < SphericalHarmonics::coefficients(order); ++i)
        v += c[i] * y[std::size_t(i)];
    return v;
}

TEST(ShFrameRotation, TheRotatedExpansionIsTheFieldSeenFromTheFibersFrame) {
    Pcg32 rng(3);
    std::vector<Vec3f> tangents = {Vec3f(0, 0, 1), Vec3f(0, 0, -1), Vec3f(1, 0, 0),
                                   glm::normalize(Vec3f(1e-8f, 0, 1))};
    for (int i = 0; i < 12; ++i)
        tangents.push_back(uniformSphere(rng.uniformFloat(), rng.uniformFloat()));
    for (const int order : {1, 4, L}) {
        const int n = SphericalHarmonics::coefficients(order);
        for (const Vec3f& u : tangents) {
            // Two channels of random coefficients, every band as strong.
            std::vector<float> c(2 * std::size_t(n)), r(2 * std::size_t(n));
            for (float& v : c)
                v = rng.uniform(-1, 1);
            const ShFrameRotation frame(u, order);
            frame.apply(c.data(), r.data(), 2);
            EXPECT_NEAR(glm::dot(frame.e1(), u), 0, 1e-6f);
            EXPECT_NEAR(glm::dot(frame.e2(), u), 0, 1e-6f);
            EXPECT_NEAR(glm::dot(glm::cross(frame.e1(), frame.e2()), u), 1, 1e-6f);
            for (int k = 0; k < 8; ++k) {
                const Vec3f local = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
                const Vec3f world = local.x * frame.e1() + local.y * frame.e2() + local.z * u;
                for (int ch = 0; ch < 2; ++ch)
                    EXPECT_NEAR(synthesise(r.data() + ch * n, local, order),
                                synthesise(c.data() + ch * n, world, order), 2e-4f)
                        << "order " << order << ", tangent " << u << ", channel " << ch;
            }
        }
    }
}

TEST(ShFrameRotation, KeepsEachBandsEnergy) {
    // A rotation is orthogonal band by band: Σ_m c_lm² is kept.
    Pcg32 rng(5);
    std::vector<float> c(nc), r(nc);
    for (float& v : c)
        v = rng.uniform(-1, 1);
    const ShFrameRotation frame(glm::normalize(Vec3f(0.3f, -0.8f, 0.2f)), L);
    frame.apply(c.data(), r.data(), 1);
    for (int l = 0; l <= L; ++l) {
        double a = 0, b = 0;
        for (int i = l * l; i < (l + 1) * (l + 1); ++i) {
            a += double(c[std::size_t(i)]) * double(c[std::size_t(i)]);
            b += double(r[std::size_t(i)]) * double(r[std::size_t(i)]);
        }
        EXPECT_NEAR(b, a, 1e-5 * a) << "band " << l;
    }
}

TEST(ShFrameRotation, LanesRotateEachFrameAsItAloneAndEveryTargetAlike) {
    // 13 frames in one call (lanes 13–15 unused), 3 channels: each lane must
    // be that frame's apply() bit for bit, on every SIMD target the host runs.
    constexpr std::size_t K = ShFrameRotation::kLanes, frames = 13;
    Pcg32 rng(11);
    std::vector<ShFrameRotation> f;
    std::vector<float> in(3 * nc * K), planar(frames * 3 * nc);
    for (std::size_t k = 0; k < frames; ++k) {
        f.emplace_back(
            k == 0 ? Vec3f(0, 0, 1) : uniformSphere(rng.uniformFloat(), rng.uniformFloat()), L);
        for (int i = 0; i < 3 * nc; ++i)
            planar[k * 3 * nc + std::size_t(i)] = in[std::size_t(i) * K + k] = rng.uniform(-1, 1);
    }
    const auto lanes = [&] {
        std::vector<float> out(3 * nc * K);
        ShFrameRotation::applyLanes(f, in.data(), out.data(), 3);
        std::vector<float> used;
        for (std::size_t k = 0; k < frames; ++k)
            for (int i = 0; i < 3 * nc; ++i)
                used.push_back(out[std::size_t(i) * K + k]);
        return used;
    };
    std::vector<float> alone(frames * 3 * nc);
    for (std::size_t k = 0; k < frames; ++k)
        f[k].apply(planar.data() + k * 3 * nc, alone.data() + k * 3 * nc, 3);
    EXPECT_EQ(std::memcmp(lanes().data(), alone.data(), alone.size() * sizeof(float)), 0);
    test::forEachSimdTarget([&] {
        EXPECT_EQ(std::memcmp(lanes().data(), alone.data(), alone.size() * sizeof(float)), 0);
    });
    EXPECT_THROW(ShFrameRotation::applyLanes({}, in.data(), in.data(), 1), std::invalid_argument);
}

} // namespace
} // namespace hairvox
