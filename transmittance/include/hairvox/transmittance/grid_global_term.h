// hairvox transmittance: the global term from the fiber grid (docs/DESIGN.md §5).
//
// For one light, every active voxel v of the fiber grid gets the rates at which
// a shadow ray accumulates the global term's optical depths (per unit length):
//   n      λ_v·k·D·E_v[cos θ]                  expected fibers crossed → V = e^{−n}
//   tauP   λ_v·k·D·E_v[cos θ·(1 − ā_f(θ))]     (Poisson estimate of E[P] = e^{−tauP})
//      or  λ_v·k·D·E_v[cos θ·(−ln ā_f(θ))]     (the paper's geometric form ā_f^n)
//   Σβ²    λ_v·k·D·E_v[cos θ·β̄_f²(θ)]          → σ_f² = Σβ² / (1 − V)
// with sin θ = ω·u over the fibers u in the voxel (the orientation model says
// how E_v is estimated from what voxelize stored). A grid of several fiber
// types mixes the types' rates (ā_f and β̄_f² of each type's fiber) with the
// voxel's type fractions f_t: rates = Σ_t f_t·rates_t. The rates are reconstructed
// between voxels with the fiber grid's own trilinear convention, and a shadow
// ray integrates them *exactly*: along a line the trilinear field is a cubic
// polynomial within each cell, so Simpson's rule per cell crossing has no step
// error. Empty space is skipped a brick (8³ voxels, an OpenVDB leaf) at a time,
// and the march stops once nothing more can change the result (V and every
// channel of P below 1e-7).
//
// Two ways to evaluate a light (both exact integrals of the same field):
//  - march: each query integrates from its point to the light. Cost per query
//    grows with the path length through hair, and a march is memory-bound
//    (random access to the volume): fine for probes, slow for a frame.
//  - cache (default): forLight() first integrates shadow lines through the
//    volume, once each and exactly — parallel to a directional light, or
//    radiating from a point light outside the volume — `cacheSpacing` voxels
//    apart, storing the running integral every voxel along each. A query
//    interpolates 4 lines (a point light inside the volume falls back to march).
//    Measured on the 1.4M-segment wavy groom against exact (K = 256): spacing
//    1 / 1.5 / 2 voxels gives MAE(V) 0.0087 / 0.0094 / 0.0102 for a build of
//    1.7 / 1.0 / 0.76 s per light (2 loaded cores): 1.5 is the default.
//
// Self-shadowing (docs/DESIGN.md §5, §8): the query point's own fiber — its
// ribbon of k hairs, which exact mode and the path tracer skip — is splatted
// into the voxels around it. Its expected optical depth along the shadow ray,
// k·D_i/(√(2π)·σ)·½·erfc(start·cos θ/(√2·σ)) crossings (σ the splat's and the
// cache's blur; ownFiberCrossings() derives it), is taken out of each query
// on a fiber: marched from the point on Ratboy and the bear at k = 4–12 this
// alone puts the visible single scattering within 0.3% of exact (0.93–0.96
// without it). Where the hair is a dense layer seen from outside (the
// default scene) the splat also smears the fibers under the point out in
// front of it, a bias that grows with the voxel (0.994, 0.952, 0.875 of exact
// at h = 1, 2.2, 4 mm): the integral starts `startOffset` voxels toward the
// light, 0.4 by default — chosen against exact mode over the project's scenes
// at k = 3–12 (pipeline/integrators_test).
//
// The `approx` mode (RenderMan report §2.1) uses the same march for n only and
// assumes every fiber in front shares the shading point's orientation θ_x
// (and its fiber type):
// P from n·(1 − ā_f(θ_x)) (or ā_f(θ_x)^n), Σβ² = n·β̄_f²(θ_x).
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/transmittance/global_term_model.h>

#include <memory>
#include <ostream>

namespace hairvox {

struct FiberGrid;

/// How E_v[w(θ)] is estimated from a voxel's stored orientation statistics.
enum class OrientationModel {
    MeanTangent,    ///< w at the normalised mean tangent o/|o| (DESIGN.md's simplest estimate)
    CoherenceBlend, ///< |o|·w(o/|o|) + (1 − |o|)·(isotropic average of w)
    Tensor, ///< w at |sin θ| = sqrt(ωᵀ E[uuᵀ] ω), symmetrised (needs the tensor grids)
};

/// The estimator of E[P] = E[∏ ā_f(θ_k)] under Poisson-distributed crossings.
enum class AttenuationEstimator {
    Poisson, ///< exp(−∫ λkD E[cos θ (1 − ā_f)] ds): the mean of ∏ā_f over crossings
    Geometric, ///< exp(∫ λkD E[cos θ ln ā_f] ds): the paper's ā_f^n (a geometric mean; biased low)
};

inline constexpr EnumNames<OrientationModel, 3> kOrientationModelNames{{{
    {OrientationModel::MeanTangent, "mean-tangent"},
    {OrientationModel::CoherenceBlend, "coherence-blend"},
    {OrientationModel::Tensor, "tensor"},
}}};
inline constexpr EnumNames<AttenuationEstimator, 2> kAttenuationEstimatorNames{{{
    {AttenuationEstimator::Poisson, "poisson"},
    {AttenuationEstimator::Geometric, "geometric"},
}}};
inline const char* toString(OrientationModel m) {
    return kOrientationModelNames.name(m);
}
inline const char* toString(AttenuationEstimator e) {
    return kAttenuationEstimatorNames.name(e);
}

/// How a LightGlobalTerm of the grid modes evaluates its queries.
enum class GridEvaluation {
    Cache, ///< per-light cache volume, one lookup per query
    March, ///< one exact march per query
};

inline constexpr EnumNames<GridEvaluation, 2> kGridEvaluationNames{{{
    {GridEvaluation::Cache, "cache"},
    {GridEvaluation::March, "march"},
}}};
inline const char* toString(GridEvaluation e) {
    return kGridEvaluationNames.name(e);
}

struct GridOptions {
    OrientationModel orientation = OrientationModel::CoherenceBlend;
    AttenuationEstimator estimator = AttenuationEstimator::Poisson;
    GridEvaluation evaluation = GridEvaluation::Cache;
    float startOffset = 0.4f;  ///< voxels toward the light before integrating, [0, 8]
    float cacheSpacing = 1.5f; ///< voxels between the cache's shadow lines, [0.5, 4]
    /// Voxels between the samples along a fiber that a query on it is
    /// interpolated from (alongFibers(); needs GlobalTermSettings::groom),
    /// 0: every query evaluated. [0, 4]
    float fiberSampleSpacing = 1.0f;

    void validate(const FiberGrid& grid) const;
    /// Every option (they all change what the grid modes compute).
    void hashInto(Hasher& hasher) const;
};

std::ostream& operator<<(std::ostream& os, const GridOptions& options);

/// The `grid` mode, with one crossing table per fiber type of the grid. The
/// model keeps a reference to `grid`, which must outlive it and every
/// LightGlobalTerm it returns.
std::unique_ptr<GlobalTermModel> makeGridModel(const FiberGrid& grid, CrossingTables crossings,
                                               const GlobalTermSettings& settings,
                                               const GridOptions& options);

/// The `approx` mode (same lifetime rule).
std::unique_ptr<GlobalTermModel> makeApproxModel(const FiberGrid& grid, CrossingTables crossings,
                                                 const GlobalTermSettings& settings,
                                                 const GridOptions& options);

} // namespace hairvox
