// Internal to hairvox transmittance: the per-light cache of the grid modes.
//
// Shadow lines run through the rate volume toward the light: parallel to it
// for a directional light (an orthographic lattice with the voxel spacing h),
// or radiating from a point light that lies outside the volume's bounds (a
// perspective lattice whose spacing is h at the volume's centre). Each line is
// integrated exactly once, from the light side, and the running integral is
// stored every h along it — only where it changes: a line keeps runs of
// samples around the hair it crosses, and between runs (the empty space
// inside a head or between strands), before its first (zero) and after its
// last or where it becomes opaque (unchanged), it stores nothing. Memory and
// build time therefore follow the hair's voxels, not the volume's: at 0.5 mm
// a line through a mohawk crosses ~1000 lattice steps but changes in ~20. A
// query interpolates its 4 surrounding lines bilinearly and each line
// linearly along its length. No value is interpolated twice, so there is no
// blur that grows with the path; the error is the lattice's interpolation,
// about a voxel, as in the rate volume itself.
#pragma once

#include "brick_volume.h"

#include <hairvox/core/large_array.h>
#include <hairvox/geometry/light.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace hairvox::detail {

class LightSpaceCache {
public:
    /// Empty for a point light inside (or too close to) the volume's bounds,
    /// where a perspective lattice cannot cover it: queries then march.
    /// `spacing` is the distance between lines in voxels (along them: one voxel).
    static std::optional<LightSpaceCache> build(const BrickVolume& rates, const Light& light,
                                                float opaqueDepth, float spacing);

    /// The integrals from each of `points` to the light (out: one per point).
    /// Each interpolates its 4 surrounding lines, and a line's read is three
    /// dependent loads (its runs' index, its run, two samples), each a likely
    /// cache miss in a cache of tens of MB: the points go in batches that take
    /// each step together, prefetching the next step's loads, so that the
    /// misses of different points overlap. A point's value does not depend on
    /// the others.
    void lookup(std::span<const Vec3f> points, std::span<OpticalDepths> out) const;

    /// The cache as bytes (host byte order, for a disk cache on machines of
    /// one architecture; light_space_cache_io.cpp), and back: nullopt for
    /// bytes that are not a cache this code wrote, or whose lines, runs and
    /// samples do not fit together (so that no lookup reads out of bounds).
    /// deserialize(serialize()) looks up the same values bit for bit.
    std::vector<std::byte> serialize() const;
    static std::optional<LightSpaceCache> deserialize(std::span<const std::byte> bytes);

    std::size_t lineCount() const { return std::size_t(ni_) * std::size_t(nj_); }
    /// Samples stored over every line.
    std::size_t sampleCount() const;
    std::size_t memoryBytes() const;

private:
    // toLattice, alongLine and value are defined inline in light_space_cache.cpp,
    // within lookup()'s loops (their small results stay in registers).

    /// Lattice coordinates of p: (u, v) across the lines, s along them (from the light).
    Vec3f toLattice(const Vec3f& p) const;
    /// A point of line (i, j) at lattice distance s.
    Vec3f lineOrigin(int i, int j, Vec3f& dir) const;
    /// Lines are stored in tiles of kTile × kTile (row-major within a tile,
    /// tiles row-major), the last row and column of tiles padded with lines
    /// that hold nothing. A brick of 8³ voxels is crossed by some 8 × 8
    /// neighbouring lines, which a tile integrates while the brick is in
    /// cache (in rows of the whole lattice its values were read again a row
    /// of lines later), and a query's 4 lines are mostly in one tile.
    static constexpr int kTile = 16;
    static constexpr std::size_t kLinesPerTile = std::size_t(kTile) * kTile;

    /// Samples k0 + 1, k0 + 2, ... of a line, stored from its tile's
    /// samples[begin] up to the next run's begin (at least one). Sample k0
    /// is not stored: the step before it changed nothing, so it is the last
    /// sample of the line's run before, or zero for its first run (17% of
    /// the samples on Ratboy at 0.7 mm, each 32 bytes of fresh pages).
    struct Run {
        std::int32_t k0;
        std::uint32_t begin;
    };
    /// What the lines of one tile store, each array allocated at its size
    /// once the tile is integrated (neither grown nor gathered into one
    /// array afterwards: at 0.5 mm voxels a light's cache is 150 MB, and
    /// every byte written twice was a page faulted twice): the runs of its
    /// lines one after another, and a sentinel whose begin is samples.size().
    /// Both empty where no line of the tile changes.
    struct Tile {
        std::vector<Run> runs;
        std::vector<Lanes> samples;
    };
    /// Where a line is stored: its tile and its place in the tile.
    struct LineAt {
        std::size_t tile;
        std::size_t line;
    };
    LineAt lineAt(int i, int j) const {
        const auto ti = static_cast<std::size_t>(i / kTile),
                   tj = static_cast<std::size_t>(j / kTile);
        return {tj * tilesPerRow_ + ti,
                static_cast<std::size_t>(j % kTile) * kTile + static_cast<std::size_t>(i % kTile)};
    }
    /// Where the stored integral of a line is read at a lattice distance:
    /// samples a and b (consecutive along the line) mixed by t, or sample a alone (b null),
    /// or zero (a null: before the line's first change).
    struct LineRead {
        const Lanes* a = nullptr;
        const Lanes* b = nullptr;
        float t = 0;
    };
    /// The read at lattice distance s of the line whose runs are tile.runs[r0, r1).
    static LineRead alongLine(const Tile& tile, std::uint32_t r0, std::uint32_t r1, float s);
    /// The value a read gives.
    static Lanes value(const LineRead& read);
    /// Sample k0 of a line's first run.
    static constexpr Lanes kZero{};

    bool perspective_ = false;
    Vec3f origin_{0.0f};                              ///< light position (perspective) or 0
    Vec3f e1_{1, 0, 0}, e2_{0, 1, 0}, axis_{0, 0, 1}; ///< axis points away from the light
    float du_ = 1;    ///< lattice spacing across lines (world, or per unit depth)
    float h_ = 1;     ///< spacing along lines (world)
    float sBase_ = 0; ///< world distance of lattice s = 0 from the light plane/point
    int i0_ = 0, j0_ = 0, ni_ = 0, nj_ = 0; ///< line lattice [i0, i0 + ni) × [j0, j0 + nj)
    std::size_t tilesPerRow_ = 0;          ///< ⌈ni / kTile⌉
    /// The runs of line l of tile t are tiles_[t].runs[r0, r1) with
    /// r0 = lineRuns_[t · (kLinesPerTile + 1) + l] and r1 the entry after it.
    LargeVector<std::uint32_t> lineRuns_;
    std::vector<Tile> tiles_;
};

} // namespace hairvox::detail
