// hairvox voxelize: the fiber grid — strands splatted into a sparse grid of
// fiber length density and orientation (8³ blocks, values packed), and its
// .vdb file form (OpenVDB grids).
//
// The grid holds, per voxel, what the dual-scattering global term integrates
// along a shadow ray (DESIGN.md §5; Zinke et al. 2008, Sadeghi & Tamstorf 2010
// §2.1): the fiber length density λ and the distribution of fiber tangents u.
//
// Index space and reconstruction (vertex-centred; cf. OpenVDB doc/math.txt)
// -------------------------------------------------------------------------
//   Voxel (i,j,k) holds the value at world position (i,j,k)·h, h = voxelSize;
//   every grid's transform is Transform::createLinearTransform(h) (uniform
//   scale, no offset), so index space is world space divided by h.
//   A value between voxels is the trilinear interpolation of the 8 voxels
//   around it: openvdb::tools::BoxSampler in index space (GridSampler with
//   BoxSampler in world space).
//   Splatting is the adjoint of that reconstruction: a piece of fiber of
//   length ds at x gives each voxel v the share w_v(x)·ds, w_v the trilinear
//   (tent) weight of v at x, and the 8 weights sum to 1. Hence, exactly up to
//   rounding,
//       λ_v = (1/h³) ∫_fibers w_v(x(s)) ds        fiber length per unit volume (1/length²)
//       Σ_v λ_v h³ = total fiber length,  and  ∫ (trilinear λ) dV = total fiber length.
//   The integrals are exact: each segment is clipped to the cells it crosses
//   (3D DDA); inside one cell each weight is a cubic polynomial of the line
//   parameter, integrated in closed form (what Simpson's rule gives too).
//
// Orientation statistics (per voxel, weighted by the same w_v ds)
// ----------------------------------------------------------------
//   orientation  o_v = E_v[u] = ∫ w_v u ds / ∫ w_v ds, not normalised:
//                |o_v| ∈ [0, 1] is the coherence (1 where all fibers near v
//                are parallel). Sign: u points root → tip as the groom stores
//                it (DESIGN.md §2). Folding u into a hemisphere instead would
//                depend on an arbitrary reference direction and jump where
//                fibers are perpendicular to it; root → tip is the direction
//                a combed groom is coherent in. Consequence: antiparallel
//                fibers (a parting, strands folding back) cancel in o_v.
//   tensor       T_v = E_v[u uᵀ] (optional): symmetric, trace 1, positive
//                semidefinite and sign-free; E_v[(ω·u)²] = ωᵀ T_v ω exactly,
//                so E[sin²θ] and E[cos²θ] toward any direction ω are exact
//                where the mean tangent alone is biased (curls, crossings).
//                Stored as tensorDiag = (xx, yy, zz), tensorOffDiag = (xy, xz, yz).
//   Examples: one fiber of direction u: o = u, T = u uᵀ. Equal lengths of two
//   perpendicular fibers along x and y: o = (½, ½, 0) (|o| = 0.707),
//   T = diag(½, ½, 0). Equal lengths of antiparallel fibers: o = 0, T = u uᵀ.
//   o and T are means, so they read directly; the length-weighted
//   reconstruction of a per-fiber quantity g(u) at x is Σ_v w_v(x) λ_v E_v[g],
//   i.e. interpolate λ·o (or λ·T) rather than λ and o separately.
//
// Per-point diameters and fiber types (strands/groom.h)
// ------------------------------------------------------
//   A segment of mean diameter D̄ (its points' D_i, groom.thickness) is
//   splatted with weight D̄/D: λ counts fibers of the nominal diameter D, so
//   the optical depth stays λ·k·D·|ω×u| and the statistics above are weighted
//   by the cross-section a ray meets. A groom with several fiber types
//   (Groom::fiberType) also gets, per type t, the fraction of the voxel's
//   weighted length of that type, f_t = E_v[type = t] ∈ [0, 1], Σ_t f_t = 1
//   (grids "fiberType<t>", sharing the density's topology); the global term
//   mixes the types' rates with these weights.
//
// Voxels are active where λ is at least FLT_MIN; elsewhere every grid reads
// its background 0. The fiber scale (diameter D, density multiplier k;
// strands/fiber_scale.h) is recorded for the consumers (optical depth
// λ·k·D·|ω×u|); λ itself counts modeled strands only.
//
// Storage: OpenVDB for files, packed values in memory
// ----------------------------------------------------
//   In a .vdb the fiber grid is OpenVDB grids (one per quantity, sharing the
//   density's topology), for standard tools. In memory it is the same voxels
//   without OpenVDB's dense leaves: blocks of 8³ voxels (OpenVDB's leaf) that
//   list their active voxels by a 512-bit mask, and one packed array per
//   quantity with a value per active voxel. A strand that the voxels resolve
//   activates ~33 of a leaf's 512 voxels (Ratboy at 0.5 mm), so OpenVDB's
//   leaves held 264 bytes per active voxel where the packed form holds 16
//   (λ and E[u]) plus its block's 80: the splat's memory, and the kernel's
//   zeroing of fresh pages that was most of its time, grow with the active
//   voxels instead of with the leaves. toVdbGrids() builds the OpenVDB grids
//   (the .vdb writer's form); readFiberGrid() packs them again.
#pragma once

#include <hairvox/strands/fiber_scale.h>
#include <hairvox/strands/groom.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <ostream>
#include <span>
#include <string>
#include <vector>

namespace hairvox {

/// Grid names in .vdb files.
inline constexpr const char* kDensityGridName = "density";
inline constexpr const char* kOrientationGridName = "orientation";
inline constexpr const char* kTensorDiagGridName = "tensorDiag";
inline constexpr const char* kTensorOffDiagGridName = "tensorOffDiag";
/// "fiberType0", "fiberType1", ...: the fraction of fiber type t.
std::string typeFractionGridName(std::size_t type);

/// What a fiber grid was made from; stored as metadata on every grid of a .vdb
/// (names in fiber_grid_io.cpp: voxel_size, fiber_diameter, density_multiplier,
/// source_file, source_hash, strands, segments, total_length, hairvox_version).
struct FiberGridInfo {
    double voxelSize = 0;   ///< h, world units (metres for the procedural grooms)
    FiberScale fiberScale;  ///< D and k, for the consumers (λ does not depend on them)
    std::string sourceFile; ///< as given to splatStrands (the CLI passes the input path)
    std::string sourceHash; ///< hexDigest(contentHash(groom))
    std::uint64_t strands = 0, segments = 0;
    double totalLength = 0; ///< Σ segment lengths of the groom, world units
    std::string version;    ///< hairvox version that splatted the grid
};

std::ostream& operator<<(std::ostream& os, const FiberGridInfo& info);

/// One block of 8³ voxels (OpenVDB's leaf node) holding active voxels.
struct FiberBlock {
    openvdb::Coord origin;             ///< its first voxel, a multiple of 8 on each axis
    std::uint32_t first = 0;           ///< index of its first active voxel in the value arrays
    openvdb::util::NodeMask<3> active; ///< its active voxels by leaf offset, x·64 + y·8 + z

    /// OpenVDB's leaf, whose offsets (coordToOffset, offsetToLocalCoord) `active` uses.
    using Leaf = openvdb::FloatTree::LeafNodeType;
    static constexpr int kDim = int(Leaf::DIM);
    /// Index-space coordinates of the voxel at leaf offset `offset`.
    openvdb::Coord voxel(openvdb::Index offset) const {
        return origin + Leaf::offsetToLocalCoord(offset);
    }
};

/// The fiber grid in memory (see "Storage" above): its blocks in
/// lexicographic order of their origins, and per active voxel — block by
/// block, each block's in offset order — one value of each quantity.
struct FiberGrid {
    std::vector<FiberBlock> blocks;
    /// λ, fiber length per unit volume (1/length²).
    std::vector<float> density;
    /// E[u], length-weighted mean unit tangent (root → tip), |·| ∈ [0, 1].
    std::vector<openvdb::Vec3s> orientation;
    /// E[u uᵀ] as (xx, yy, zz) and (xy, xz, yz); filled when tensorStored.
    std::vector<openvdb::Vec3s> tensorDiag, tensorOffDiag;
    bool tensorStored = false; ///< SplatOptions::storeOrientationTensor, or the file had it
    /// f_t, the fraction of fiber type t, one array per type for a groom with
    /// more than one type (see above); empty otherwise.
    std::vector<std::vector<float>> typeFraction;
    FiberGridInfo info;
    /// Notes for the user from splatStrands (e.g. an empty groom); not stored in files.
    std::vector<std::string> warnings;

    /// What find() returns for a voxel that is not active.
    static constexpr std::size_t kInactive = SIZE_MAX;

    bool hasTensor() const { return tensorStored; }
    /// Fiber types the grid distinguishes (1 when it has no fractions).
    std::size_t fiberTypeCount() const { return std::max<std::size_t>(1, typeFraction.size()); }
    std::uint64_t activeVoxelCount() const { return density.size(); }
    /// In-memory size of the blocks and values, bytes.
    std::uint64_t memoryBytes() const;
    /// The value index of voxel `ijk` (index space), or kInactive. O(log blocks).
    std::size_t find(const openvdb::Coord& ijk) const;

    /// f(value index, ijk) for every active voxel of `block`, in offset order.
    template <typename F>
    static void forEachVoxelOf(const FiberBlock& block, const F& f) {
        std::size_t i = block.first;
        for (auto it = block.active.beginOn(); it; ++it)
            f(i++, block.voxel(it.pos()));
    }
    /// f(value index, ijk) for every active voxel, in the arrays' order.
    template <typename F>
    void forEachVoxel(const F& f) const {
        for (const FiberBlock& block : blocks)
            forEachVoxelOf(block, f);
    }
};

std::ostream& operator<<(std::ostream& os, const FiberGrid& grid);

/// The default voxel size is the longest side of the groom's bounding box
/// divided by this. Why a count across the box: it does not depend on the
/// units or the strand count, and it bounds work and memory (at most 256³
/// voxels; the 50,000-strand procedural head of data/scenes/head_1p4m.json
/// gets 2.2 mm voxels, 1.0M of them active, 15.5 MiB packed and 30 MiB as
/// OpenVDB grids) while resolving the hair volume:
/// ~10 voxels through a 2–3 cm layer of hair, the depth over which the
/// forward-scattered light decays. At the densest voxels of that head
/// λ·D ≈ 900 /m, i.e. about 2 fibers crossed per voxel. The transmittance
/// stage tunes this number against exact ray casting.
inline constexpr int kDefaultVoxelsAcross = 256;

/// Longest side of groom.bounds() / voxelsAcross. A groom without extent
/// (empty, or all points coincident) gets 1: there is nothing to resolve.
double defaultVoxelSize(const Groom& groom, int voxelsAcross = kDefaultVoxelsAcross);

struct SplatOptions {
    double voxelSize = 0;  ///< h > 0; 0 = defaultVoxelSize(groom)
    FiberScale fiberScale; ///< recorded in FiberGridInfo
    /// Also splat E[u uᵀ] (two more Vec3S grids, ~2.5× the memory); off until
    /// the transmittance stage measures that it pays.
    bool storeOrientationTensor = false;
    bool threaded = true; ///< false runs on the calling thread only (same result)
    /// splatStrands refuses, before allocating, a voxel size whose estimated
    /// memory exceeds this.
    std::uint64_t memoryBudgetBytes = 4ull << 30;
    /// The caller will write the grid as a .vdb (toVdbGrids): the estimate
    /// also counts the file's OpenVDB leaves (vdbBlockBytes() a block).
    bool forVdbFile = false;
    std::string sourceFile;    ///< recorded in FiberGridInfo
    bool showProgress = false; ///< progress bar on stderr
};

std::ostream& operator<<(std::ostream& os, const SplatOptions& options);

/// Splats every segment of the groom (see the conventions above). The result is
/// bit-identical for any thread count. An empty groom (or one without length)
/// gives empty grids and a warning. Throws InputError for invalid options, a
/// non-finite point, coordinates beyond OpenVDB's 32-bit index space at this
/// voxel size, or an estimated memory above the budget (the message states the
/// estimate). Polls throwIfInterrupted().
FiberGrid splatStrands(const Groom& groom, const SplatOptions& options);

/// The fiber grid as OpenVDB grids: the grids a .vdb file holds, with their
/// names, transforms, classes and metadata (FiberGridInfo, units, description).
struct FiberVdbGrids {
    openvdb::FloatGrid::Ptr density;
    openvdb::Vec3SGrid::Ptr orientation;
    openvdb::Vec3SGrid::Ptr tensorDiag, tensorOffDiag; ///< null without the tensor
    std::vector<openvdb::FloatGrid::Ptr> typeFraction;

    /// Every grid, in the file's order.
    openvdb::GridPtrVec all() const;
};

/// Builds the OpenVDB grids of `grid` (a leaf per block, in parallel; the
/// same grids for any thread count).
FiberVdbGrids toVdbGrids(const FiberGrid& grid);

/// Bytes toVdbGrids() allocates for one block: a dense 8³ OpenVDB leaf in
/// each grid (λ and E[u], the tensor's two, `typeFractions` fractions).
std::uint64_t vdbBlockBytes(bool tensor, std::size_t typeFractions);

/// Bytes toVdbGrids(grid) allocates: vdbBlockBytes() for each block.
std::uint64_t vdbMemoryBytes(const FiberGrid& grid);

/// Writes toVdbGrids(grid) as one .vdb file, atomically.
void writeFiberGrid(const std::filesystem::path& path, const FiberGrid& grid);

/// Writes OpenVDB grids as one .vdb file through writeFileAtomically() (every
/// .vdb hairvox writes goes through here); InputError naming the path on failure.
void writeVdbFile(const std::filesystem::path& path, const openvdb::GridPtrVec& grids);

/// Reads a .vdb written by writeFiberGrid. Throws InputError naming the file if
/// it is unreadable, lacks the density or orientation grid or the hairvox
/// metadata, has a transform other than the vertex-centred linear one, holds
/// non-finite or negative density values, or active tiles (a fiber grid's
/// voxels are leaf voxels). The other grids are read at the density's active
/// voxels.
FiberGrid readFiberGrid(const std::filesystem::path& path);

/// The grid as it is in memory — its blocks, value arrays and info — as
/// bytes, for the disk cache that a farm's render tasks share
/// (core/disk_cache.h; host byte order). Not a .vdb: a cache entry is read
/// by a task's first frame, and OpenVDB's trees cost that read more than the
/// splat it saves (fiber_grid_bytes.cpp has the figures).
std::vector<std::byte> fiberGridBytes(const FiberGrid& grid);
/// The grid of fiberGridBytes() (the same blocks, values and info), or
/// InputError naming `name` for bytes that are not one — blocks out of
/// order or off the 8³ lattice, counts that disagree with the masks, values
/// a fiber grid cannot hold (readFiberGrid's rules).
FiberGrid fiberGridFromBytes(std::span<const std::byte> bytes, const std::string& name);

} // namespace hairvox
