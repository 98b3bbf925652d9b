#include "tile_renderer.h"

#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/math.h>

#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <cmath>

namespace hairvox::raster {

namespace {

/// Radiance finite and non-negative, averages finite. Branch-free integer
/// tests on the bits, or-ed together, so that the loops vectorise: every
/// fragment's results pass through here.
bool isValid(std::span<const float> r, std::size_t radianceFloats) {
    std::uint32_t bad = 0;
    for (std::size_t i = 0; i < radianceFloats; ++i) {
        // Finite and not negative: below 0x7f800000, or −0.
        const std::uint32_t bits = std::bit_cast<std::uint32_t>(r[i]);
        bad |= std::uint32_t(bits >= 0x7f800000u) & std::uint32_t(bits != 0x80000000u);
    }
    for (std::size_t i = radianceFloats; i < r.size(); ++i)
        bad |= std::uint32_t((std::bit_cast<std::uint32_t>(r[i]) & 0x7f800000u) == 0x7f800000u);
    return bad == 0;
}

/// Adaptive rate: a segment is probed at this many points (t = 0, ½, 1) when
/// it has more visible fragments than that in a tile.
constexpr std::size_t kProbePoints = 3;

/// Adaptive rate: whether a segment's shading is smooth enough to interpolate,
/// from its results a, m, b at t = 0, ½, 1 (radiance floats, ≥ 0): the
/// midpoint's distance from the ends' interpolation against the segment's
/// mean radiance,
///     Σ_k |m_k − (a_k + b_k)/2|  ≤  τ · Σ_k (a_k + m_k + b_k)/3,
/// summed over every radiance float (each layer, each channel), so that no
/// lobe's error hides behind another's.
bool smoothAlong(const float* a, const float* m, const float* b, std::size_t radianceFloats,
                 float tolerance) {
    float error = 0, mean = 0;
    for (std::size_t k = 0; k < radianceFloats; ++k) {
        error += std::abs(m[k] - 0.5f * (a[k] + b[k]));
        mean += (a[k] + m[k] + b[k]) * (1.0f / 3.0f);
    }
    return error <= tolerance * mean;
}

} // namespace

ShadingPoint TileRenderer::pointOnSegment(std::uint32_t local, float t) const {
    const std::uint32_t k = s_.pointOf[local];
    const Vec3f& p0 = ctx_.groom.points[k];
    const Vec3f& p1 = ctx_.groom.points[k + 1];
    ShadingPoint sp;
    sp.position = hairvox::lerp(t, p0, p1);
    sp.tangent = shadingTangent(ctx_.tangents[k], ctx_.tangents[k + 1], t,
                                normalizeOr(p1 - p0, Vec3f(0.0f, 1.0f, 0.0f)));
    sp.toCamera = normalizeOr(ctx_.camera.position() - sp.position, sp.tangent);
    sp.strand = s_.strandOf[local];
    sp.segment = k;
    return sp;
}

ShadingPoint TileRenderer::pointAtVertex(std::uint32_t point, std::uint32_t strand) const {
    ShadingPoint sp;
    sp.position = ctx_.groom.points[point];
    sp.tangent = ctx_.tangents[point];
    sp.toCamera = normalizeOr(ctx_.camera.position() - sp.position, sp.tangent);
    sp.strand = strand;
    sp.segment = point + 1 < ctx_.groom.strandStart[strand + 1] ? point : point - 1;
    return sp;
}

template <typename Where>
void TileRenderer::shadeBatch(std::size_t count, Where&& where) {
    throwIfInterrupted(); // an expensive shader (exact mode) makes a tile long
    s_.results.resize(count * stride_);
    // Isolated: a shader may run its own parallel loops (the global
    // term's lookups), and oneTBB allows a thread waiting in one to take
    // another tile's task ("Work Isolation"), which would reuse this
    // thread's scratch (s_) under this tile. (The shader's and the global
    // term's per-thread arrays, ThreadScratch, take their own storage when
    // re-entered. Debian's oneTBB 2021.8 was not seen to re-enter: none in
    // 2,000 nested loops at 2, 4 and 8 threads.)
    tbb::this_task_arena::isolate([&] {
        ctx_.shader.shade(std::span(s_.points.data(), count),
                          std::span(s_.results.data(), count * stride_));
    });
    result_.shadingPoints += count;
    for (std::size_t i = 0; i < count; ++i) {
        const std::span<float> r(s_.results.data() + i * stride_, stride_);
        if (isValid(r, ctx_.radianceFloats))
            continue;
        ++result_.invalid;
        if (result_.warnings.size() < kMaxWarnings) {
            std::string values;
            for (float x : r)
                values += strCat(values.empty() ? "" : " ", x);
            result_.warnings.push_back(strCat("shader returned a non-finite or negative value ",
                                              where(i), " for ", s_.points[i], ": [", values,
                                              "]; set to black"));
        }
        std::fill(r.begin(), r.end(), 0.0f);
    }
}

void TileRenderer::accumulate(const Visible& v, const float* __restrict r) {
    // restrict: the sums and the results never overlap, so the loop vectorises.
    float* __restrict sum = s_.pixelSum.data() + std::size_t(v.pixel) * stride_;
    const float w = v.weight;
    for (std::size_t k = 0; k < stride_; ++k)
        sum[k] += w * r[k];
}

std::string TileRenderer::pixelName(std::uint32_t pixel) const {
    return strCat("at pixel (", x0_ + int(pixel % std::uint32_t(width_)), ", ",
                  y0_ + int(pixel / std::uint32_t(width_)), ")");
}

void TileRenderer::groupVisibleBySegment() {
    s_.segmentStart.assign(bins_.size() + 1, 0);
    for (const Visible& v : s_.visible)
        ++s_.segmentStart[v.local + 1];
    for (std::size_t i = 0; i < bins_.size(); ++i)
        s_.segmentStart[i + 1] += s_.segmentStart[i];
    s_.grouped.resize(s_.visible.size());
    s_.cursor.assign(s_.segmentStart.begin(), s_.segmentStart.end() - 1);
    for (const Visible& v : s_.visible)
        s_.grouped[s_.cursor[v.local]++] = v;
    s_.visible.swap(s_.grouped);
}

void TileRenderer::shadeFragments() {
    s_.pixelSum.assign(std::size_t(area_) * stride_, 0.0f);
    interpolateTail();
    groupVisibleBySegment();
    shadeEach(s_.visible);
}

template <typename PointAt>
void TileRenderer::shadeInto(std::size_t n, PointAt&& pointAt, const char* where,
                             std::vector<float>& out) {
    out.resize(n * stride_);
    for (std::size_t begin = 0; begin < n; begin += kShadeBatch) {
        const std::size_t count = std::min(kShadeBatch, n - begin);
        s_.points.resize(count);
        for (std::size_t i = 0; i < count; ++i)
            s_.points[i] = pointAt(begin + i);
        shadeBatch(count, [&](std::size_t) { return std::string(where); });
        std::copy_n(s_.results.begin(), count * stride_,
                    out.begin() + std::ptrdiff_t(begin * stride_));
    }
}

void TileRenderer::shadeEach(std::span<const Visible> fragments) {
    for (std::size_t begin = 0; begin < fragments.size(); begin += kShadeBatch) {
        const std::size_t count = std::min(kShadeBatch, fragments.size() - begin);
        s_.points.resize(count);
        for (std::size_t i = 0; i < count; ++i) {
            if (begin + i + kPrefetchAhead < fragments.size()) {
                const std::uint32_t k = s_.pointOf[fragments[begin + i + kPrefetchAhead].local];
                prefetch(&ctx_.groom.points[k]);
                prefetch(&ctx_.groom.points[k + 1]);
                prefetch(&ctx_.tangents[k]);
                prefetch(&ctx_.tangents[k + 1]);
            }
            const Visible& v = fragments[begin + i];
            s_.points[i] = pointOnSegment(v.local, v.t);
        }
        shadeBatch(count, [&](std::size_t i) { return pixelName(fragments[begin + i].pixel); });
        for (std::size_t i = 0; i < count; ++i)
            accumulate(fragments[begin + i], s_.results.data() + i * stride_);
    }
}

void TileRenderer::shadeVertices() {
    s_.pixelSum.assign(std::size_t(area_) * stride_, 0.0f);
    interpolateVertices(s_.visible);
}

void TileRenderer::interpolateTail() {
    const std::uint64_t shaded = result_.shadingPoints;
    interpolateVertices(s_.tail);
    result_.tailFragments += s_.tail.size();
    result_.tailVertices += result_.shadingPoints - shaded;
}

void TileRenderer::interpolateVertices(std::span<const Visible> fragments) {
    if (fragments.empty())
        return;
    s_.vertexSlot.assign(bins_.size(), kNoSlot);
    for (const Visible& v : fragments)
        s_.vertexSlot[v.local] = 0;
    s_.slotPoint.clear();
    s_.slotStrand.clear();
    for (std::size_t i = 0; i < bins_.size(); ++i) {
        if (s_.vertexSlot[i] == kNoSlot)
            continue;
        const std::uint32_t k = s_.pointOf[i];
        if (s_.slotPoint.empty() || s_.slotPoint.back() != k) {
            s_.slotPoint.push_back(k);
            s_.slotStrand.push_back(s_.strandOf[i]);
        }
        s_.vertexSlot[i] = static_cast<std::uint32_t>(s_.slotPoint.size() - 1);
        s_.slotPoint.push_back(k + 1);
        s_.slotStrand.push_back(s_.strandOf[i]);
    }
    shadeInto(
        s_.slotPoint.size(),
        [&](std::size_t j) { return pointAtVertex(s_.slotPoint[j], s_.slotStrand[j]); },
        "at a strand vertex", s_.vertexResults);
    result_.interpolated += fragments.size();
    for (const Visible& v : fragments) {
        const float* a = s_.vertexResults.data() + std::size_t(s_.vertexSlot[v.local]) * stride_;
        accumulateLerp(v, v.t, a, a + stride_);
    }
}

void TileRenderer::shadeAdaptive() {
    s_.pixelSum.assign(std::size_t(area_) * stride_, 0.0f);
    interpolateTail();
    groupVisibleBySegment();
    auto fragmentsOf = [&](std::size_t i) {
        return s_.segmentStart[i + 1] - s_.segmentStart[i];
    };
    s_.probed.clear();
    for (std::size_t i = 0; i < bins_.size(); ++i)
        if (fragmentsOf(i) > kProbePoints)
            s_.probed.push_back(static_cast<std::uint32_t>(i));
    shadeInto(
        kProbePoints * s_.probed.size(),
        [&](std::size_t j) {
            return pointOnSegment(s_.probed[j / kProbePoints], 0.5f * float(j % kProbePoints));
        },
        "probing a segment", s_.probeResults);

    s_.probeOf.assign(bins_.size(), kNoSlot);
    for (std::size_t p = 0; p < s_.probed.size(); ++p) {
        const float* a = s_.probeResults.data() + kProbePoints * p * stride_;
        if (smoothAlong(a, a + stride_, a + 2 * stride_, ctx_.radianceFloats,
                        ctx_.settings.shadingTolerance)) {
            s_.probeOf[s_.probed[p]] = static_cast<std::uint32_t>(p);
            ++result_.smoothSegments;
            result_.interpolated += fragmentsOf(s_.probed[p]);
        }
    }
    result_.probedSegments += s_.probed.size();

    // The fragments of the other segments, shaded in segment order.
    s_.grouped.clear();
    for (const Visible& v : s_.visible) {
        const std::uint32_t p = s_.probeOf[v.local];
        if (p == kNoSlot) {
            s_.grouped.push_back(v);
            continue;
        }
        const float* a = s_.probeResults.data() + kProbePoints * p * stride_;
        const float* m = a + stride_;
        const float u = 2.0f * v.t;
        if (u > 1.0f)
            accumulateLerp(v, u - 1.0f, m, m + stride_);
        else
            accumulateLerp(v, u, a, m);
    }
    shadeEach(s_.grouped);
}

void TileRenderer::accumulateLerp(const Visible& v, float u, const float* __restrict a,
                                  const float* __restrict b) {
    float* __restrict sum = s_.pixelSum.data() + std::size_t(v.pixel) * stride_;
    const float w = v.weight;
    for (std::size_t k = 0; k < stride_; ++k)
        sum[k] += w * hairvox::lerp(u, a[k], b[k]);
}

void TileRenderer::finishShading() {
    TileOutput beauty = output(ctx_.beautyLayer);
    std::vector<TileOutput>& radiance = s_.radianceOutputs;
    std::vector<TileOutput>& average = s_.averageOutputs;
    radiance.clear();
    average.clear();
    for (std::size_t layer : ctx_.radianceLayer)
        radiance.push_back(output(layer));
    for (std::size_t layer : ctx_.averageLayer)
        average.push_back(output(layer));
    for (std::uint32_t p = 0; p < area_; ++p) {
        const float w = s_.pixels[p].hairWeight;
        const std::size_t i = tileIndex(p);
        // Zero where no fragment was shaded: nothing accumulated.
        const float* sum = s_.pixelSum.data() + std::size_t(p) * stride_;
        for (std::size_t l = 0; l < radiance.size(); ++l)
            for (std::size_t c = 0; c < 3; ++c) {
                radiance[l].set(i, c, sum[3 * l + c]);
                beauty.add(i, c, sum[3 * l + c]);
            }
        const float invW = w > 0 ? 1.0f / w : 0.0f;
        std::size_t k = ctx_.radianceFloats;
        for (std::size_t l = 0; l < average.size(); ++l) {
            const auto channels = static_cast<std::size_t>(ctx_.layout.averages[l].channels);
            for (std::size_t c = 0; c < channels; ++c)
                average[l].set(i, c, sum[k + c] * invW);
            k += channels;
        }
    }
}

} // namespace hairvox::raster
