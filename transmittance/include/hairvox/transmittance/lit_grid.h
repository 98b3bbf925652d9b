// hairvox transmittance: the global term toward one light at every active
// voxel of a fiber grid, as OpenVDB grids for inspection in any VDB viewer
// (`hairvox transmittance`). Each voxel is queried at its position with its
// mean fiber tangent (the global term depends on the fiber's own orientation
// only in approx mode).
//
// Grids (same transform and topology as the fiber grid's density), each
// GRID_UNKNOWN (none is a [0, 1] density with background 0, what
// GRID_FOG_VOLUME promises) with string metadata `units` and `description`,
// and for vectors `component_order`:
//   n        (float) expected fibers crossed toward the light; background 0
//   V        (float) direct visibility e^{-n}; background 1 (outside the
//            hair nothing blocks the light)
//   T_s      (vec3s, R,G,B) forward transmittance d_f·(P − V); background 0
//   sigma2_f (vec3s, R,G,B, rad²) accumulated forward variance; background 0
// and, on every grid, the numeric metadata of litGridMetadata().
#pragma once

#include <hairvox/geometry/light.h>
#include <hairvox/shading/fiber_params.h>
#include <hairvox/transmittance/global_term_mode.h>
#include <hairvox/transmittance/global_term_model.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <filesystem>
#include <vector>

namespace hairvox {

struct LitGrid {
    openvdb::FloatGrid::Ptr n, V;
    openvdb::Vec3SGrid::Ptr T_s, sigma2_f;
    GlobalTermStats stats;
};

/// The global term at every active voxel of a fiber grid, in the grid's
/// value order (FiberGrid::forEachVoxel): what the lit grids hold, packed
/// (the Python module's numpy arrays view it).
struct VoxelGlobalTerms {
    std::vector<GlobalTerm> terms;
    GlobalTermStats stats;
};

/// Evaluates `term` at every active voxel of `grid` (in parallel, deterministic).
VoxelGlobalTerms evaluateAtActiveVoxels(const FiberGrid& grid, const LightGlobalTerm& term);
/// The four grids of `values` (evaluateAtActiveVoxels of `grid`).
LitGrid toLitGrid(const FiberGrid& grid, const VoxelGlobalTerms& values);
/// Both: toLitGrid(grid, evaluateAtActiveVoxels(grid, term)).
LitGrid evaluateOnFiberGrid(const FiberGrid& grid, const LightGlobalTerm& term);

/// What a lit grid was computed from, as typed metadata: light_type (string
/// "directional" | "point"), light_direction (vec3s, toward the light) or
/// light_position (vec3s), light_color (vec3s), light_intensity (float);
/// mode (string); voxel_size (double, scene units); fiber_diameter,
/// density_multiplier, eta, eccentricity, alpha_R_deg, beta_R_deg,
/// caustic_width_deg, caustic_gain, d_f, d_b (float), sigma_a (vec3s, per
/// unit fiber radius); source_file, source_hash, hairvox_version (string).
openvdb::MetaMap litGridMetadata(const Light& light, GlobalTermMode mode, const FiberGridInfo& grid,
                                 const FiberParams& fiber,
                                 const DualScatteringParams& dualScattering);

/// Writes the four grids, each with `metadata` added, atomically.
void writeLitGrid(const std::filesystem::path& path, const LitGrid& lit,
                  const openvdb::MetaMap& metadata);

} // namespace hairvox
