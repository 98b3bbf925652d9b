#include "light_space_cache.h"

#include <hairvox/core/thread_scratch.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hairvox::detail {

namespace {

std::array<Vec3f, 8> corners(const Bounds3f& b) {
    std::array<Vec3f, 8> c;
    for (int k = 0; k < 8; ++k)
        c[static_cast<std::size_t>(k)] = Vec3f(
            (k & 4) ? b.max.x : b.min.x, (k & 2) ? b.max.y : b.min.y, (k & 1) ? b.max.z : b.min.z);
    return c;
}

} // namespace

std::optional<LightSpaceCache> LightSpaceCache::build(const BrickVolume& rates, const Light& light,
                                                      float opaqueDepth, float spacing) {
    LightSpaceCache cache;
    cache.h_ = static_cast<float>(rates.voxelSize());
    const Bounds3f bounds = rates.bounds();
    if (bounds.empty()) {
        return cache;
    }
    const auto boxCorners = corners(bounds);

    float sMaxWorld = 0; // farthest lattice distance the volume reaches, world units
    if (light.kind == Light::Kind::Directional) {
        cache.axis_ = -light.direction;
        coordinateSystem(cache.axis_, cache.e1_, cache.e2_);
        cache.du_ = spacing * cache.h_;
        float sMin = std::numeric_limits<float>::infinity();
        sMaxWorld = -sMin;
        for (const Vec3f& c : boxCorners) {
            sMin = std::min(sMin, glm::dot(c, cache.axis_));
            sMaxWorld = std::max(sMaxWorld, glm::dot(c, cache.axis_));
        }
        cache.sBase_ = sMin - cache.h_;
    } else {
        // A perspective lattice needs the whole volume in front of the light,
        // within a cone of half-angle < 60° (so that the lattice stays regular).
        cache.perspective_ = true;
        cache.origin_ = light.position;
        const Vec3f toCentre = bounds.center() - light.position;
        const float centreDistance = glm::length(toCentre);
        if (!(centreDistance > 0))
            return std::nullopt;
        cache.axis_ = toCentre / centreDistance;
        coordinateSystem(cache.axis_, cache.e1_, cache.e2_);
        float sMin = std::numeric_limits<float>::infinity();
        for (const Vec3f& c : boxCorners) {
            const Vec3f d = c - light.position;
            const float w = glm::dot(d, cache.axis_);
            if (!(w > 0.5f * glm::length(d)))
                return std::nullopt; // the light is inside or beside the volume
            sMaxWorld = std::max(sMaxWorld, glm::length(d));
        }
        const Vec3f nearest = glm::clamp(light.position, bounds.min, bounds.max);
        sMin = glm::distance(nearest, light.position);
        cache.du_ = spacing * cache.h_ / glm::dot(toCentre, cache.axis_);
        cache.sBase_ = std::max(sMin - cache.h_, 0.0f);
    }

    // The line lattice covering the volume's projection, with a margin of one line.
    float uMin = std::numeric_limits<float>::infinity(), uMax = -uMin, vMin = uMin, vMax = uMax;
    for (const Vec3f& c : boxCorners) {
        const Vec3f l = cache.toLattice(c);
        uMin = std::min(uMin, l.x);
        uMax = std::max(uMax, l.x);
        vMin = std::min(vMin, l.y);
        vMax = std::max(vMax, l.y);
    }
    cache.i0_ = static_cast<int>(std::floor(uMin)) - 1;
    cache.j0_ = static_cast<int>(std::floor(vMin)) - 1;
    cache.ni_ = static_cast<int>(std::ceil(uMax)) + 2 - cache.i0_;
    cache.nj_ = static_cast<int>(std::ceil(vMax)) + 2 - cache.j0_;
    // (toLattice() used i0 = j0 = 0 above; lattice coordinates are now relative.)
    const auto samplesPerLine =
        static_cast<std::size_t>(std::ceil((sMaxWorld - cache.sBase_) / cache.h_)) + 2;

    // The lines each brick's values can reach: the lattice rectangle of its
    // value box's corners, widened by a quarter of a line against rounding
    // (the box is exact: its cells hold every value). Binned by tile of
    // lines, then by line within a tile's task, so that a line visits the
    // bricks whose values it may meet and no other: walking the lattice line
    // through every brick it passes cost a test per brick, and at fine
    // voxels the lines (∝ 1/h² over the hair's projection) pass bricks
    // (∝ 1/h each) far faster than the hair's voxels grow (∝ 1/h).
    cache.tilesPerRow_ = static_cast<std::size_t>((cache.ni_ + kTile - 1) / kTile);
    const std::size_t tileRows = static_cast<std::size_t>((cache.nj_ + kTile - 1) / kTile);
    const std::size_t tileCount = cache.tilesPerRow_ * tileRows;
    struct LineRect {
        int i0 = 0, i1 = -1, j0 = 0, j1 = -1; ///< lines [i0, i1] × [j0, j1]; empty if i0 > i1
    };
    if (rates.brickCount() > std::numeric_limits<std::uint32_t>::max())
        throw std::length_error("light-space cache: more than 2^32 bricks");
    std::vector<LineRect> reach(rates.brickCount());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, reach.size()), [&](const auto& range) {
        // A quarter of a line, more where the lattice's coordinates are so
        // large that their rounding is (toLattice subtracts i0, j0).
        const float offset = static_cast<float>(std::max(std::abs(cache.i0_), std::abs(cache.j0_)));
        for (std::size_t brick = range.begin(); brick != range.end(); ++brick) {
            const Bounds3f box = rates.valueBounds(brick);
            if (box.empty())
                continue;
            float u0 = std::numeric_limits<float>::infinity(), u1 = -u0, v0 = u0, v1 = u1;
            for (const Vec3f& c : corners(box)) {
                const Vec3f l = cache.toLattice(c);
                u0 = std::min(u0, l.x);
                u1 = std::max(u1, l.x);
                v0 = std::min(v0, l.y);
                v1 = std::max(v1, l.y);
            }
            const float margin =
                0.25f +
                64.0f * std::numeric_limits<float>::epsilon() *
                    (offset + std::max({std::abs(u0), std::abs(u1), std::abs(v0), std::abs(v1)}));
            LineRect& r = reach[brick];
            r.i0 = std::max(static_cast<int>(std::ceil(u0 - margin)), 0);
            r.i1 = std::min(static_cast<int>(std::floor(u1 + margin)), cache.ni_ - 1);
            r.j0 = std::max(static_cast<int>(std::ceil(v0 - margin)), 0);
            r.j1 = std::min(static_cast<int>(std::floor(v1 + margin)), cache.nj_ - 1);
            if (r.j0 > r.j1)
                r.i1 = r.i0 - 1;
        }
    });
    // Each tile's bricks, in brick order (a counting sort: deterministic).
    std::vector<std::size_t> tileStart(tileCount + 1, 0);
    const auto forEachTileOf = [&](const LineRect& r, auto&& f) {
        if (r.i0 > r.i1)
            return;
        for (int tj = r.j0 / kTile; tj <= r.j1 / kTile; ++tj)
            for (int ti = r.i0 / kTile; ti <= r.i1 / kTile; ++ti)
                f(static_cast<std::size_t>(tj) * cache.tilesPerRow_ + static_cast<std::size_t>(ti));
    };
    for (const LineRect& r : reach)
        forEachTileOf(r, [&](std::size_t tile) { ++tileStart[tile + 1]; });
    for (std::size_t t = 0; t < tileCount; ++t)
        tileStart[t + 1] += tileStart[t];
    std::vector<std::uint32_t> tileBricks(tileStart[tileCount]);
    {
        std::vector<std::size_t> cursor(tileStart.begin(), tileStart.end() - 1);
        for (std::size_t brick = 0; brick < reach.size(); ++brick)
            forEachTileOf(reach[brick], [&](std::size_t tile) {
                tileBricks[cursor[tile]++] = static_cast<std::uint32_t>(brick);
            });
    }

    // Lines are integrated a tile a task. A task gathers a tile's runs and
    // samples in its own arrays (reused from tile to tile, so they stay in
    // cache) and stores them at their size.
    cache.lineRuns_.resize(tileCount * (kLinesPerTile + 1)); // every entry written below
    cache.tiles_.resize(tileCount);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tileCount), [&](const auto& range) {
        struct Scratch {
            std::vector<std::size_t> lineStart;    ///< per line of the tile, where its bricks start
            std::vector<std::uint32_t> lineBricks; ///< the bricks of the tile's lines, line by line
            std::vector<BrickVolume::BrickCrossing> crossings;
            std::vector<BrickVolume::CumulativeSample> recorded;
            std::vector<Run> runs;
            std::vector<Lanes> samples;
        };
        ThreadScratch<Scratch> scratch;
        // (References, not a structured binding: Clang 14 does not let the
        // lambda below capture one.)
        std::vector<std::size_t>& lineStart = scratch->lineStart;
        std::vector<std::uint32_t>& lineBricks = scratch->lineBricks;
        std::vector<BrickVolume::BrickCrossing>& crossings = scratch->crossings;
        std::vector<BrickVolume::CumulativeSample>& recorded = scratch->recorded;
        std::vector<Run>& runs = scratch->runs;
        std::vector<Lanes>& samples = scratch->samples;
        for (std::size_t ti = range.begin(); ti != range.end(); ++ti) {
            runs.clear();
            samples.clear();
            std::uint32_t* lineRuns = cache.lineRuns_.data() + ti * (kLinesPerTile + 1);
            const int tileI = static_cast<int>(ti % cache.tilesPerRow_) * kTile;
            const int tileJ = static_cast<int>(ti / cache.tilesPerRow_) * kTile;
            // The tile's bricks by line (a counting sort over the lines they reach).
            const std::span<const std::uint32_t> bricks(tileBricks.data() + tileStart[ti],
                                                        tileStart[ti + 1] - tileStart[ti]);
            const auto forEachLineOf = [&](std::uint32_t brick, auto&& f) {
                const LineRect& r = reach[brick];
                for (int j = std::max(r.j0, tileJ); j <= std::min(r.j1, tileJ + kTile - 1); ++j)
                    for (int i = std::max(r.i0, tileI); i <= std::min(r.i1, tileI + kTile - 1); ++i)
                        f(static_cast<std::size_t>(j - tileJ) * kTile +
                          static_cast<std::size_t>(i - tileI));
            };
            lineStart.assign(kLinesPerTile + 1, 0);
            for (const std::uint32_t brick : bricks)
                forEachLineOf(brick, [&](std::size_t l) { ++lineStart[l + 1]; });
            for (std::size_t l = 0; l < kLinesPerTile; ++l)
                lineStart[l + 1] += lineStart[l];
            lineBricks.resize(lineStart[kLinesPerTile]);
            for (const std::uint32_t brick : bricks)
                forEachLineOf(brick, [&](std::size_t l) { lineBricks[lineStart[l]++] = brick; });
            // (Each lineStart[l] now holds line l's end, the start of line l + 1.)
            for (std::size_t l = 0; l < kLinesPerTile; ++l) {
                lineRuns[l] = static_cast<std::uint32_t>(runs.size());
                const std::size_t begin = l == 0 ? 0 : lineStart[l - 1], end = lineStart[l];
                if (begin == end)
                    continue; // no value reaches the line (or padding): it stores nothing
                const int li = tileI + static_cast<int>(l % kTile);
                const int lj = tileJ + static_cast<int>(l / kTile);
                Vec3f dir;
                const Vec3f origin = cache.lineOrigin(li, lj, dir);
                rates.integrateCumulative(origin, dir, 0.0f, cache.h_, samplesPerLine, opaqueDepth,
                                          std::span(lineBricks.data() + begin, end - begin),
                                          crossings, recorded);
                // Keep the samples at either end of a step where the value changes
                // (consecutive k); every other sample equals the one kept before it.
                const auto changes = [&](std::size_t i) {
                    return recorded[i + 1].k == recorded[i].k + 1 &&
                           !std::equal(std::begin(recorded[i].value.v),
                                       std::end(recorded[i].value.v),
                                       std::begin(recorded[i + 1].value.v));
                };
                // A run's first sample is not stored: nothing changed in the
                // step before it, so it holds the value of the line's run
                // before (its last sample) or zero (Run).
                bool keptPrevious = false;
                bool changedBefore = false; // changes(i - 1)
                for (std::size_t i = 0; i < recorded.size(); ++i) {
                    const bool changedAfter = i + 1 < recorded.size() && changes(i);
                    const bool keep = changedBefore || changedAfter;
                    changedBefore = changedAfter;
                    if (!keep) {
                        keptPrevious = false;
                        continue;
                    }
                    const bool first = !keptPrevious || recorded[i].k != recorded[i - 1].k + 1;
                    keptPrevious = true;
                    if (first) {
                        assert(std::equal(std::begin(recorded[i].value.v),
                                          std::end(recorded[i].value.v),
                                          runs.size() > lineRuns[l] ? std::begin(samples.back().v)
                                                                    : std::begin(kZero.v)));
                        runs.push_back({static_cast<std::int32_t>(recorded[i].k),
                                        static_cast<std::uint32_t>(samples.size())});
                        continue;
                    }
                    samples.push_back(recorded[i].value);
                }
                // A tile's samples are at most its lines' lattice steps
                // (samplesPerLine each), far below 2^32 for any volume that
                // fits in memory; say so rather than wrap.
                if (samples.size() > std::numeric_limits<std::uint32_t>::max() - 1)
                    throw std::length_error("light-space cache: a tile of 16 x 16 shadow lines "
                                            "holds more than 2^32 samples");
            }
            lineRuns[kLinesPerTile] = static_cast<std::uint32_t>(runs.size());
            if (runs.empty())
                continue; // no line of the tile changes: nothing stored
            runs.push_back({0, static_cast<std::uint32_t>(samples.size())}); // the sentinel
            Tile& tile = cache.tiles_[ti];
            tile.runs.assign(runs.begin(), runs.end());
            tile.samples.assign(samples.begin(), samples.end());
        }
    });
    return cache;
}

std::size_t LightSpaceCache::sampleCount() const {
    std::size_t count = 0;
    for (const Tile& tile : tiles_)
        count += tile.samples.size();
    return count;
}

std::size_t LightSpaceCache::memoryBytes() const {
    std::size_t bytes =
        lineRuns_.capacity() * sizeof(std::uint32_t) + tiles_.capacity() * sizeof(Tile);
    for (const Tile& tile : tiles_)
        bytes += tile.runs.capacity() * sizeof(Run) + tile.samples.capacity() * sizeof(Lanes);
    return bytes;
}

inline Vec3f LightSpaceCache::toLattice(const Vec3f& p) const {
    if (!perspective_)
        return {glm::dot(p, e1_) / du_ - float(i0_), glm::dot(p, e2_) / du_ - float(j0_),
                (glm::dot(p, axis_) - sBase_) / h_};
    const Vec3f d = p - origin_;
    const float w = std::max(glm::dot(d, axis_), 1e-30f);
    return {glm::dot(d, e1_) / (w * du_) - float(i0_), glm::dot(d, e2_) / (w * du_) - float(j0_),
            (glm::length(d) - sBase_) / h_};
}

Vec3f LightSpaceCache::lineOrigin(int i, int j, Vec3f& dir) const {
    const float u = float(i + i0_) * du_, v = float(j + j0_) * du_;
    if (!perspective_) {
        dir = axis_;
        return u * e1_ + v * e2_ + sBase_ * axis_;
    }
    dir = glm::normalize(axis_ + u * e1_ + v * e2_);
    return origin_ + sBase_ * dir;
}

inline LightSpaceCache::LineRead LightSpaceCache::alongLine(const Tile& tile, std::uint32_t r0,
                                                            std::uint32_t r1, float s) {
    const Run* runs = tile.runs.data();
    if (r0 == r1 || s < float(runs[r0].k0))
        return {}; // before the line's first change: zero
    // The last run starting at or before s (a line has a few).
    std::uint32_t r = r0;
    while (r + 1 < r1 && float(runs[r + 1].k0) <= s)
        ++r;
    const Run& run = runs[r];
    const std::size_t count = runs[r + 1].begin - run.begin; // samples k0 + 1 .. k0 + count
    const float local = s - float(run.k0);
    const auto k = static_cast<std::size_t>(local);
    const Lanes* samples = tile.samples.data() + run.begin;
    if (k >= count)
        return {samples + (count - 1), nullptr, 0.0f}; // unchanged until the next run (or for good)
    if (k == 0) // from sample k0: the line's run before ends with its value, or it is zero
        return {r == r0 ? &kZero : samples - 1, samples, local};
    return {samples + (k - 1), samples + k, local - float(k)};
}

inline Lanes LightSpaceCache::value(const LineRead& read) {
    if (!read.a)
        return {};
    if (!read.b)
        return *read.a;
    Lanes result;
    for (int lane = 0; lane < 8; ++lane)
        result.v[lane] = read.a->v[lane] + read.t * (read.b->v[lane] - read.a->v[lane]);
    return result;
}

void LightSpaceCache::lookup(std::span<const Vec3f> points, std::span<OpticalDepths> out) const {
    if (lineCount() == 0) {
        std::fill(out.begin(), out.end(), OpticalDepths{});
        return;
    }
    // 16 points × 4 lines a step (batches of 8 and 32 measured the same,
    // transmittance_bench GridLookup: 51-65 ns a query; one by one, 166 ns).
    constexpr std::size_t kBatch = 16;
    struct Corner {
        bool inside = false;
        float w = 0;
        std::size_t line = 0; ///< into lineRuns_
        const Tile* tile = nullptr;
        std::uint32_t r0 = 0, r1 = 0; ///< its runs in its tile
        LineRead read;
    };
    std::array<std::array<Corner, 4>, kBatch> corners;
    std::array<float, kBatch> s;
    for (std::size_t b = 0; b < points.size(); b += kBatch) {
        const std::size_t n = std::min(kBatch, points.size() - b);
        // 1. The 4 lines around each point (bilinear weights); their runs' index.
        for (std::size_t q = 0; q < n; ++q) {
            const Vec3f l = toLattice(points[b + q]);
            const float fi = std::floor(l.x), fj = std::floor(l.y);
            const int i = static_cast<int>(fi), j = static_cast<int>(fj);
            const float tx = l.x - fi, ty = l.y - fj;
            s[q] = l.z;
            for (int k = 0; k < 4; ++k) {
                Corner& c = corners[q][std::size_t(k)];
                const int ii = i + (k & 1), jj = j + (k >> 1);
                c.inside = ii >= 0 && jj >= 0 && ii < ni_ && jj < nj_;
                if (!c.inside)
                    continue;
                c.w = ((k & 1) ? tx : 1.0f - tx) * ((k >> 1) ? ty : 1.0f - ty);
                const LineAt at = lineAt(ii, jj);
                c.line = at.tile * (kLinesPerTile + 1) + at.line;
                c.tile = &tiles_[at.tile];
                __builtin_prefetch(&lineRuns_[c.line]);
                __builtin_prefetch(c.tile);
            }
        }
        // 2. Each line's runs.
        for (std::size_t q = 0; q < n; ++q)
            for (Corner& c : corners[q])
                if (c.inside) {
                    c.r0 = lineRuns_[c.line];
                    c.r1 = lineRuns_[c.line + 1];
                    __builtin_prefetch(c.tile->runs.data() + c.r0);
                }
        // 3. The run at s, and where its samples are.
        for (std::size_t q = 0; q < n; ++q)
            for (Corner& c : corners[q])
                if (c.inside) {
                    c.read = alongLine(*c.tile, c.r0, c.r1, s[q]);
                    if (c.read.a)
                        __builtin_prefetch(c.read.a);
                    if (c.read.b)
                        __builtin_prefetch(c.read.b);
                }
        // 4. The values, summed in the corners' order.
        for (std::size_t q = 0; q < n; ++q) {
            Lanes r;
            for (const Corner& c : corners[q]) {
                if (!c.inside)
                    continue;
                const Lanes v = value(c.read);
                for (int lane = 0; lane < 8; ++lane)
                    r.v[lane] += c.w * v.v[lane];
            }
            out[b + q] = r.depths();
        }
    }
}

} // namespace hairvox::detail
