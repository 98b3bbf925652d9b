// hairvox transmittance: the global term toward one light at every active
// voxel of a fiber grid, as OpenVDB grids for inspection in any VDB viewer
// (`hairvox transmittance`). Each voxel is queried at its position with its
// mean fiber tangent (the global term depends on the fiber's own orientation
// only in approx mode).
//
// Grids (same transform and topology as the fiber grid's density):
//   n (float), V (float), T_s (vec3s, RGB), sigma2_f (vec3s, RGB, rad²),
// with metadata: light (its kind and direction or position), mode, voxel
// size, and the fiber grid's source hash.
#pragma once

#include <hairvox/transmittance/global_term_model.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <filesystem>
#include <map>
#include <string>

namespace hairvox {

struct LitGrid {
    openvdb::FloatGrid::Ptr n, V;
    openvdb::Vec3SGrid::Ptr T_s, sigma2_f;
    GlobalTermStats stats;
};

/// Evaluates `term` at every active voxel of `grid` (in parallel, deterministic).
LitGrid evaluateOnFiberGrid(const FiberGrid& grid, const LightGlobalTerm& term);

/// Writes the four grids, each with `metadata` as string metadata, atomically.
void writeLitGrid(const std::filesystem::path& path, const LitGrid& lit,
                  const std::map<std::string, std::string>& metadata);

} // namespace hairvox
