// The light-space cache as bytes (light_space_cache.h), for the disk cache
// that render tasks share (core/disk_cache.h, pipeline's asset cache):
//   magic "HVXLSC02", the lattice (perspective, origin, e1, e2, axis, du, h,
//   sBase, i0, j0, ni, nj), tilesPerRow, the line → runs index, then per
//   tile its run count, runs (k0, begin), sample count and samples (8 floats).
// The disk cache checks its entries' integrity; deserialize() checks that the
// lattice, the index, the runs and the samples fit together, so that even
// bytes from another build cannot make a lookup read out of bounds.
#include "light_space_cache.h"

#include <hairvox/core/byte_stream.h>

#include <cmath>
#include <cstring>

namespace hairvox::detail {

namespace {

/// 02: a run's first sample is not stored (light_space_cache.h, Run).
constexpr char kMagic[8] = {'H', 'V', 'X', 'L', 'S', 'C', '0', '2'};

bool finite(const Vec3f& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

} // namespace

std::vector<std::byte> LightSpaceCache::serialize() const {
    ByteWriter w;
    w.bytes(kMagic, sizeof(kMagic));
    w.put(static_cast<std::uint8_t>(perspective_ ? 1 : 0));
    w.put(origin_);
    w.put(e1_);
    w.put(e2_);
    w.put(axis_);
    w.put(du_);
    w.put(h_);
    w.put(sBase_);
    w.put(i0_);
    w.put(j0_);
    w.put(ni_);
    w.put(nj_);
    w.put(std::uint64_t{tilesPerRow_});
    w.array(std::span<const std::uint32_t>(lineRuns_.data(), lineRuns_.size()));
    w.put(std::uint64_t{tiles_.size()});
    for (const Tile& tile : tiles_) {
        w.array(std::span<const Run>(tile.runs));
        w.array(std::span<const Lanes>(tile.samples));
    }
    return std::move(w.out);
}

std::optional<LightSpaceCache> LightSpaceCache::deserialize(std::span<const std::byte> bytes) {
    ByteReader r(bytes);
    char magic[sizeof(kMagic)] = {};
    LightSpaceCache c;
    std::uint8_t perspective = 0;
    std::uint64_t tilesPerRow = 0, tileCount = 0;
    if (!r.bytes(magic, sizeof(magic)) || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0 ||
        !r.get(perspective) || perspective > 1 || !r.get(c.origin_) || !r.get(c.e1_) ||
        !r.get(c.e2_) || !r.get(c.axis_) || !r.get(c.du_) || !r.get(c.h_) || !r.get(c.sBase_) ||
        !r.get(c.i0_) || !r.get(c.j0_) || !r.get(c.ni_) || !r.get(c.nj_) || !r.get(tilesPerRow))
        return std::nullopt;
    c.perspective_ = perspective == 1;
    if (!finite(c.origin_) || !finite(c.e1_) || !finite(c.e2_) || !finite(c.axis_) ||
        !(c.du_ > 0) || !std::isfinite(c.du_) || !(c.h_ > 0) || !std::isfinite(c.h_) ||
        !std::isfinite(c.sBase_) || c.ni_ < 0 || c.nj_ < 0)
        return std::nullopt;
    // The tiles the lattice needs, each with kLinesPerTile + 1 index entries.
    const auto tilesOf = [](int n) {
        return (static_cast<std::uint64_t>(n) + kTile - 1) / kTile;
    };
    const std::uint64_t tiles = tilesOf(c.ni_) * tilesOf(c.nj_);
    if (tilesPerRow != tilesOf(c.ni_))
        return std::nullopt;
    c.tilesPerRow_ = tilesPerRow;
    std::vector<std::uint32_t> lineRuns;
    if (!r.array(lineRuns) || lineRuns.size() != tiles * (kLinesPerTile + 1) || !r.get(tileCount) ||
        tileCount != tiles)
        return std::nullopt;
    c.lineRuns_.resize(lineRuns.size());
    std::copy(lineRuns.begin(), lineRuns.end(), c.lineRuns_.data());
    c.tiles_.resize(tiles);
    for (std::size_t t = 0; t < c.tiles_.size(); ++t) {
        Tile& tile = c.tiles_[t];
        if (!r.array(tile.runs) || !r.array(tile.samples))
            return std::nullopt;
        // The index: each line's runs [r0, r1) within the tile's runs, in order;
        // a tile without runs has none (and no samples).
        const std::uint32_t* index = lineRuns.data() + t * (kLinesPerTile + 1);
        const std::size_t runCount = tile.runs.empty() ? 0 : tile.runs.size() - 1;
        if (index[0] != 0 || index[kLinesPerTile] != runCount ||
            (tile.runs.empty() && !tile.samples.empty()))
            return std::nullopt;
        for (std::size_t l = 0; l < kLinesPerTile; ++l)
            if (index[l] > index[l + 1])
                return std::nullopt;
        // Every run holds at least one sample; the sentinel ends the samples.
        for (std::size_t k = 0; k < runCount; ++k)
            if (tile.runs[k].begin >= tile.runs[k + 1].begin)
                return std::nullopt;
        if (!tile.runs.empty() &&
            (tile.runs.front().begin != 0 || tile.runs.back().begin != tile.samples.size()))
            return std::nullopt;
        for (const Lanes& s : tile.samples)
            for (float v : s.v)
                if (!std::isfinite(v))
                    return std::nullopt;
    }
    if (!r.atEnd())
        return std::nullopt;
    return c;
}

} // namespace hairvox::detail
