#include "tile_renderer.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace hairvox::raster {

TileRenderer::TileRenderer(const RenderContext& ctx, TileScratch& s, int tile)
    : ctx_(ctx)
    , s_(s)
    , stride_(ctx.stride) {
    tx_ = tile % ctx.tilesX;
    ty_ = tile / ctx.tilesX;
    x0_ = tx_ * kTileSize;
    y0_ = ty_ * kTileSize;
    x1_ = std::min(ctx.camera.width(), x0_ + kTileSize);
    y1_ = std::min(ctx.camera.height(), y0_ + kTileSize);
    width_ = x1_ - x0_;
    area_ = static_cast<std::uint32_t>(width_ * (y1_ - y0_));
    bins_ = {ctx.binSegments.data() + ctx.binStart[std::size_t(tile)],
             ctx.binSegments.data() + ctx.binStart[std::size_t(tile) + 1]};
    if (ctx.settings.shadingRate != ShadingRate::Vertex)
        tailTransmittance_ = ctx.settings.tailTransmittance;
}

TileResult TileRenderer::run() {
    const Clock::time_point start = Clock::now();
    prepare();
    rasterizeAndComposite();
    finishCoverage();
    const Clock::time_point shadeStart = Clock::now();
    switch (ctx_.settings.shadingRate) {
    case ShadingRate::Fragment:
        shadeFragments();
        break;
    case ShadingRate::Vertex:
        shadeVertices();
        break;
    case ShadingRate::Adaptive:
        shadeAdaptive();
        break;
    }
    finishShading();
    result_.shadeSeconds = secondsSince(shadeStart);
    result_.rasterSeconds = secondsSince(start) - result_.shadeSeconds;
    result_.fragments = result_.composited + result_.behindOpaque;
    return std::move(result_);
}

void TileRenderer::prepare() {
    const std::size_t n = bins_.size();
    s_.ribbons.resize(n);
    s_.zMin.resize(n);
    s_.order.resize(n);
    s_.strandOf.resize(n);
    s_.pointOf.resize(n);
    s_.keys.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        if (i + 2 * kPrefetchAhead < n)
            prefetch(&ctx_.segments[bins_[i + 2 * kPrefetchAhead]]);
        if (i + kPrefetchAhead < n) {
            const std::uint32_t k = ctx_.segments[bins_[i + kPrefetchAhead]].firstPoint;
            prefetch(&ctx_.projected[k]);
            prefetch(&ctx_.projected[k + 1].invZ); // the pair's end: the next line at most
        }
        s_.ribbons[i] = *ctx_.ribbon(bins_[i]);
        s_.zMin[i] = 1.0f / std::max(s_.ribbons[i].invZ0, s_.ribbons[i].invZ1);
        s_.pointOf[i] = ctx_.segments[bins_[i]].firstPoint;
        s_.strandOf[i] = ctx_.segments[bins_[i]].strand;
        // (zMin, index) as one integer: positive floats order like their bits.
        s_.keys[i] = (std::uint64_t(std::bit_cast<std::uint32_t>(s_.zMin[i])) << 32) | i;
    }
    std::sort(s_.keys.begin(), s_.keys.end());
    for (std::size_t i = 0; i < n; ++i)
        s_.order[i] = static_cast<std::uint32_t>(s_.keys[i]);
    s_.pixels.assign(area_, PixelState{});
    openPixels_ = area_;
    openRows_.fill(0);
    std::fill_n(openRows_.begin(), y1_ - y0_, lowBits(width_));
    s_.pending.clear();
    s_.visible.clear();
    s_.tail.clear();
    if (ctx_.surfaces.empty())
        return;
    for (int y = y0_; y < y1_; ++y)
        for (int x = x0_; x < x1_; ++x) {
            const std::size_t i =
                std::size_t(y) * std::size_t(ctx_.camera.width()) + std::size_t(x);
            if (ctx_.surfaces.coverage[i] > 0)
                s_.pending.push_back({ctx_.surfaces.depth[i], ctx_.surfaces.coverage[i], 0,
                                      kSurfaceFragment, pixelIndex(x, y)});
        }
}

bool TileRenderer::anyOpenUnder(const ScreenRibbon& r) const {
    const auto clampTo = [](double v, int lo, int hi) {
        return static_cast<int>(std::clamp(v, double(lo), double(hi)));
    };
    const int xb = clampTo(std::floor(r.xMin), x0_, x1_) - x0_;
    const int xe = clampTo(std::ceil(r.xMax), x0_, x1_) - x0_;
    const int yb = clampTo(std::floor(r.yMin), y0_, y1_) - y0_;
    const int ye = clampTo(std::ceil(r.yMax), y0_, y1_) - y0_;
    if (xb >= xe)
        return false;
    const std::uint32_t columns = lowBits(xe - xb) << xb;
    for (int y = yb; y < ye; ++y)
        if (openRows_[std::size_t(y)] & columns)
            return true;
    return false;
}

void TileRenderer::rasterizeAndComposite() {
    const std::size_t n = s_.order.size();
    auto open = [&](int x, int y) {
        // The row's mask (cleared with pixels[].closed): one word, not a PixelState.
        if ((openRows_[std::size_t(y - y0_)] >> (x - x0_)) & 1u)
            return true;
        ++result_.behindOpaque;
        return false;
    };
    for (std::size_t begin = 0; begin < n; begin += kSegmentsPerStep) {
        if (openPixels_ == 0) {
            result_.segmentsSkipped += n - begin;
            break;
        }
        const std::size_t end = std::min(n, begin + kSegmentsPerStep);
        for (std::size_t j = begin; j < end; ++j) {
            // Ribbons are read in depth order, scattered over the tile's
            // array: fetch the next ones while this one is covered.
            if (j + kPrefetchAhead < n) {
                const ScreenRibbon* next = &s_.ribbons[s_.order[j + kPrefetchAhead]];
                prefetch(&next->s0);
                prefetch(&next->yMax);
            }
            const std::uint32_t local = s_.order[j];
            const ScreenRibbon& r = s_.ribbons[local];
            if (!anyOpenUnder(r)) {
                ++result_.segmentsSkipped;
                continue;
            }
            const RibbonLocator locator(r);
            raster::rasterizeRibbon(
                r, x0_, y0_, x1_, y1_, s_.coverageCells,
                [&](int x, int y, float coverage) {
                    Fragment f;
                    locator.locate(Vec2d(x + 0.5, y + 0.5), f.t, f.depth);
                    f.alpha = coverage;
                    f.local = local;
                    f.pixel = pixelIndex(x, y);
                    s_.pending.push_back(f);
                },
                open);
        }
        settle(end < n ? s_.zMin[s_.order[end]] : std::numeric_limits<float>::infinity());
    }
    settle(std::numeric_limits<float>::infinity());
}

void TileRenderer::settle(float z) {
    // Split without a branch: whether a pending fragment is final is a
    // coin toss to the branch predictor (on the head each is read 6.4
    // times, at every step until it settles), so each is written to both
    // arrays and the count of the one it belongs to advances.
    if (s_.settling.size() < s_.pending.size())
        s_.settling.resize(s_.pending.size());
    std::size_t kept = 0, settling = 0;
    for (const Fragment& f : s_.pending) {
        const bool settles = f.depth < z;
        s_.settling[settling] = f;
        s_.pending[kept] = f;
        settling += settles ? 1 : 0;
        kept += settles ? 0 : 1;
    }
    s_.pending.resize(kept);
    if (settling == 0)
        return;
    const std::span<const Fragment> settled(s_.settling.data(), settling);
    // Counting sort by pixel, then insertion sort per pixel by (depth,
    // segment; the head after hair at equal depth): a total order.
    s_.pixelStart.assign(area_ + 1, 0);
    for (const Fragment& f : settled)
        ++s_.pixelStart[f.pixel + 1];
    for (std::size_t p = 0; p < area_; ++p)
        s_.pixelStart[p + 1] += s_.pixelStart[p];
    s_.sorted.resize(settled.size());
    s_.cursor.assign(s_.pixelStart.begin(), s_.pixelStart.end() - 1);
    for (const Fragment& f : settled)
        s_.sorted[s_.cursor[f.pixel]++] = f;
    auto before = [](const Fragment& a, const Fragment& b) {
        return a.depth < b.depth || (a.depth == b.depth && a.local < b.local);
    };
    for (std::size_t p = 0; p < area_; ++p) {
        Fragment* first = s_.sorted.data() + s_.pixelStart[p];
        Fragment* last = s_.sorted.data() + s_.pixelStart[p + 1];
        if (first == last)
            continue;
        if (last - first > 32) {
            std::sort(first, last, before);
        } else {
            for (Fragment* i = first + 1; i < last; ++i) {
                const Fragment f = *i;
                Fragment* j = i;
                for (; j > first && before(f, *(j - 1)); --j)
                    *j = *(j - 1);
                *j = f;
            }
        }
        PixelState& st = s_.pixels[p];
        for (const Fragment* f = first; f != last; ++f)
            composite(st, *f);
    }
}

void TileRenderer::composite(PixelState& st, const Fragment& f) {
    const bool hair = f.local != kSurfaceFragment;
    if (st.closed) {
        result_.behindOpaque += hair ? 1u : 0u;
        return;
    }
    const std::uint32_t point = hair ? s_.pointOf[f.local] : kNoPoint;
    // Root-side points of one strand's segments are consecutive; across
    // strands they differ by at least 2 (a strand's tip starts nothing).
    if (hair && st.lastPoint != kNoPoint &&
        (point > st.lastPoint ? point - st.lastPoint : st.lastPoint - point) <= 1) {
        st.groupCoverage = std::min(st.groupCoverage + f.alpha, 1.0f);
    } else {
        st.groupT = st.T;
        st.groupCoverage = f.alpha;
    }
    const float T = st.groupT * (1.0f - st.groupCoverage);
    const float w = st.T - T; // this fragment's share: what it took from the transmittance
    st.T = T;
    st.lastPoint = point;
    st.depthSum += w * f.depth;
    if (hair) {
        // Seen through less than the tail transmittance: interpolated.
        (st.groupT < tailTransmittance_ ? s_.tail : s_.visible)
            .push_back({f.pixel, f.local, f.t, w});
        st.hairWeight += w;
        ++result_.composited;
    } else {
        st.surface += w * ctx_.surfaces.radiance[imageIndex(f.pixel)];
    }
    if (st.T <= ctx_.settings.opaqueTransmittance) {
        st.closed = true;
        --openPixels_;
        openRows_[f.pixel / std::uint32_t(width_)] &=
            ~(std::uint32_t(1) << (f.pixel % std::uint32_t(width_)));
    }
}

void TileRenderer::finishCoverage() {
    TileOutput alpha = output(ctx_.alphaLayer), hairAlpha = output(ctx_.hairAlphaLayer),
               depth = output(ctx_.depthLayer), surface = output(ctx_.surfaceLayer),
               background = output(ctx_.backgroundLayer), beauty = output(ctx_.beautyLayer);
    for (std::uint32_t p = 0; p < area_; ++p) {
        const PixelState& st = s_.pixels[p];
        const std::size_t i = tileIndex(p);
        alpha.set(i, 0, 1.0f - st.T);
        hairAlpha.set(i, 0, st.hairWeight);
        depth.set(i, 0, st.T < 1.0f ? st.depthSum / (1.0f - st.T) : 0.0f);
        // (A covered pixel's backdrop is not asked for: T·0 is the +0 that
        // T·backdrop was, the backdrop being finite.)
        const Rgb behind = ctx_.background.empty() ? ctx_.settings.background
                           : st.T > 0
                               ? ctx_.background.radiance(x0_ + int(p % std::uint32_t(width_)),
                                                          y0_ + int(p / std::uint32_t(width_)))
                               : Rgb(0.0f);
        const Rgb b = st.T * behind;
        for (int c = 0; c < 3; ++c) {
            const auto k = std::size_t(c);
            surface.set(i, k, st.surface[c]);
            background.set(i, k, b[c]);
            beauty.set(i, k, st.surface[c] + b[c]);
        }
    }
}

} // namespace hairvox::raster
