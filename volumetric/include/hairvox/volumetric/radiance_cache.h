// hairvox volumetric: the radiance cache — light that has scattered at least
// once, per cell of a coarse grid over the hair, as the fibers there receive
// it (spherical_harmonics.h); what the volumetric integrator's fragments read
// their multiple scattering from (docs/DESIGN.md §9).
//
// Cells. A cell is m × m × m voxels of the fiber grid (m = cellVoxels;
// cell_grid.h). The cache keeps the cells that hold fibers; values live at
// the cells' centres and are read trilinearly between them. (Spread
// instead to the cells around each voxel with trilinear weights — the
// lookup's adjoint — the estimate smooths over a cell's width; measured on
// the default scene: 0.073 / 0.061 rel L1 against 0.072 / 0.056 at 0.6M /
// 1.5M paths. The blur costs more than the noise it removes.)
//
// Basis. Each cell holds its incident radiance in real spherical harmonics
// to order L (`sh_order`) in the world frame (spherical_harmonics.h; Moon,
// Walter & Marschner 2008): one basis for every cell, so the eight cells
// around a point blend coefficient by coefficient, and a fiber of any
// tangent reads the field correctly. (Replaced: a frame per cell about its
// fibers' mean tangent, bins of s × azimuthal harmonics, and the scattering
// applied about that mean — on curly hair, where a cell holds fibers of every
// azimuth about a helix's axis, it over-counted by a third at depth 2;
// docs/DESIGN.md §9 has the measurements.)
//
// Incident radiance. A fragment lies on a fiber, so what it needs of a cell
// is the radiance averaged over the cell's fibers, L̄(ω) = ∫ λ L(x, ω) dV / Λ,
// Λ = ∫ λ dV = Σ_v λ_v h³ the cell's fiber length. deposit() adds one sample
// of Λ·L̄ (radiance × solid angle × fiber length: a flight's power times the
// fiber length it swept, Φ·∫λ dt, the track-length estimator of
// multiple_scattering.h) and divides by Λ: c_lm += sample·Y_lm(ω_i)/Λ. The
// fibers' average rather than the volume's: a cell half inside the head, or
// half beyond the hair's surface, would otherwise mix in the radiance of
// space no fiber sees.
//
// Noise. A cell's coefficients are sums over the flights that crossed it,
// c_lm = Σ_f w_f·Y_lm(ω_f) (w_f = sample/Λ), so each is noisy, and by the
// addition theorem Σ_m Y_lm(ω)² = (2l + 1)/4π the variance of band l is
// estimated by N_l = (2l + 1)/4π·Σ_f w_f² (the flights' counts Poisson), one
// second moment per cell and channel. A read shrinks each band l ≥ 1 of the
// blended coefficients toward zero by the positive-part James–Stein gain
// g_l = max(0, 1 − N_l/E_l), E_l = Σ_m ĉ_lm², with N_l of the blend
// (Σ_i a_i² N_l,i for blend weights a_i): it keeps a band where its energy
// stands above the noise and drops it where the flights could not resolve
// it. Band 0, the mean radiance, is kept as estimated. The hair's radiance
// against the path tracer (4×4 blocks, its noise removed; seeds 1–3), without
// and with (`RadianceCacheSettings::denoise`): the default look at 256²
// 0.058 / 0.064 / 0.058 → 0.055 / 0.061 / 0.055, the curly close-up at 80×60
// 0.085 / 0.082 / 0.084 → 0.081 / 0.078 / 0.079; the default look with 4×
// the paths, seed 1, 0.050 → 0.049. (Shrinking each cell's own bands
// instead, before the blend, needs its noise scaled by the blend's
// Σ a_i² ≈ (2/3)³ to do as well.)
//
// Gradients. A cell is 4–5 mm across and the light its fibers receive can
// change by a factor across it — at a lit layer's surface most of all, where
// the fibers the camera sees lie beyond the cell's fiber centroid. So each
// cell also fits how its mean radiance (band 0) changes with position: a
// deposit brings the λ-weighted mean position of its track in the cell
// (offset from the cell's centre, d), the cell sums m = Σ_f w_f·Y_00·d_f,
// and finish() solves the least-squares slope over the fibers' positions,
// β = Σ⁻¹(m − c_00·(x̄ − x_c)), x̄ and Σ the λ-weighted centroid and
// covariance of the cell's voxels (each voxel's box adding h²/12). A read
// scales cell i's coefficients by (c_00 + β·(x − x̄))/c_00 — the same
// directional shape, its level at x — kept within [½, 2] against a slope the
// flights resolved badly: the slope is the difference of two sums that agree
// to the noise of where the cell's ~100 tracks happened to pass, so it is
// the noisier estimate (a shrinkage by its own noise, as the bands have, is
// not done yet). Measured (the hair's radiance, 4×4 blocks, noise removed;
// with the reads denoised): the default look at 256² 0.055 / 0.061 / 0.055 →
// 0.051 / 0.057 / 0.052 (seeds 1–3; bias −2.4% → −1.4%), the curly close-up
// at 80×60 0.081 / 0.078 / 0.079 → 0.075 / 0.071 / 0.075; the `multiple`
// layer at depth 2 on key_back.json (128², 512 spp) −5.2% → −1.8%, rel L1
// 0.118 → 0.103 (`RadianceCacheSettings::gradients`).
//
// Outgoing radiance. outgoing() blends the coefficients of the 8 cells
// around x trilinearly (cells without fibers left out and the weights
// renormalised) and applies the fragment's own fiber type's scattering
// kernel about the fragment's own tangent (scattering_kernel.h): every lobe
// in the fiber's frame, exact for the order held. incidentInFrames() and
// outgoingInFrame() are its two halves, for a reader that rotates once for
// several fragments and rotates many frames at once (the pipeline's
// samples along the fibers).
#pragma once

#include <hairvox/core/large_array.h>
#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/volumetric/cell_grid.h>
#include <hairvox/volumetric/scattering_kernel.h>
#include <hairvox/volumetric/sh_rotation.h>

#include <glm/mat3x3.hpp>

#include <cstdint>
#include <ostream>
#include <span>
#include <vector>

namespace hairvox {

struct FiberGrid;

struct RadianceCacheSettings {
    int shOrder = 8;    ///< L: SH orders held, [1, 8]
    int cellVoxels = 2; ///< m: fiber-grid voxels per cell side, [1, 16]
    bool denoise = true;   ///< reads shrink each band by its noise (see above)
    bool gradients = true; ///< reads follow each cell's slope of mean radiance (see above)

    int coefficients() const { return (shOrder + 1) * (shOrder + 1); }

    void validate() const;
};

std::ostream& operator<<(std::ostream& os, const RadianceCacheSettings& s);

class RadianceCache {
public:
    /// The cells of `grid` (see above), each with zeroed coefficients. Throws InputError if the
    /// estimated memory exceeds `memoryBudget` bytes (the message states the estimate).
    RadianceCache(const FiberGrid& grid, const RadianceCacheSettings& settings,
                  std::uint64_t memoryBudget);

    /// Bytes the cache of `grid` would hold (coefficients, index, Λ).
    static std::uint64_t estimateBytes(const FiberGrid& grid,
                                       const RadianceCacheSettings& settings);

    const RadianceCacheSettings& settings() const { return settings_; }
    std::size_t cellCount() const { return cells_.size(); }
    float cellSize() const { return grid_.cellSize(); }
    /// The world-space box the cells cover.
    Bounds3f bounds() const;
    /// The box of cells the index spans: first cell and cells a side.
    const CellGrid& cells() const { return grid_; }
    std::uint64_t memoryBytes() const;

    /// Adds to the cell's incident radiance a sample of Λ·L̄ (radiance ×
    /// solid angle × fiber length) arriving from unit ω_i (pointing away from
    /// the cell, toward where the light comes from): sample/Λ in the basis,
    /// received at the cell's fiber centroid. Not thread-safe for one slot.
    void deposit(std::uint32_t slot, const Vec3f& omega_i, const Rgb& sample);
    /// The same with ω_i's basis values Y_lm(ω_i) given ((L + 1)² floats,
    /// SphericalHarmonics::evaluate; a flight deposits into several cells),
    /// received at `offset` from the cell's centre (world units: the
    /// λ-weighted mean of the track's points in the cell; see Gradients).
    void deposit(std::uint32_t slot, const float* y, const Rgb& sample, const Vec3f& offset);
    /// Asks for the cell's coefficients to be brought into the cache ahead of
    /// a deposit() to it (a hint: changes nothing else).
    void prefetch(std::uint32_t slot) const {
        const float* c = coefficients_.data() + std::size_t(slot) * floatsPerCell();
        for (std::size_t i = 0; i < floatsPerCell(); i += 16)
            __builtin_prefetch(c + i, 1);
    }

    /// Ends the deposits; `kernels[t]` is fiber type t's scattering kernel
    /// (of the cache's SH order).
    void finish(std::vector<ScatteringKernel> kernels);
    bool finished() const { return finished_; }

    /// The radiance a fiber of type `type` and unit tangent u at x sends
    /// toward unit ω_o from the cached light (see above); 0 outside the
    /// cells. Needs finish().
    Rgb outgoing(const Vec3f& x, const Vec3f& u, const Vec3f& omega_o, std::size_t type) const;
    /// outgoing() in two steps, for callers that read the cells once for
    /// several fragments of a fiber (pipeline: at samples along the fibers).
    /// First L̄ at x[k] in the frame of a fiber there, frames[k] (c' = C_F c
    /// of the cells' blend; sh_rotation.h), into out[k·3(L + 1)² …] (planar
    /// [channel][lm]; zeros outside the cells), ShFrameRotation::kLanes
    /// points at a time across the SIMD lanes. Needs no finish().
    void incidentInFrames(std::span<const Vec3f> x, std::span<const ShFrameRotation> frames,
                          float* out) const;
    /// Then the radiance toward ω_o of a fiber of type `type` whose incident
    /// coefficients in `frame` are `c` (incidentInFrames()). Needs finish().
    Rgb outgoingInFrame(const float* c, const ShFrameRotation& frame, const Vec3f& omega_o,
                        std::size_t type) const;
    /// The incident radiance L̄(x, ω_i) the fibers at x receive (trilinear
    /// between the cells' expansions): for tests and plots.
    Rgb incident(const Vec3f& x, const Vec3f& omega_i) const;

    /// The slot of the cell holding world point x, or -1.
    std::int64_t slotAt(const Vec3f& x) const { return grid_.slotAt(x); }
    /// The world position of a cell's centre.
    Vec3f cellCentre(std::size_t slot) const { return grid_.centre(cells_[slot]); }
    /// Λ, the cell's fiber length (world units).
    float fiberLength(std::size_t slot) const { return fiberLength_[slot]; }

private:
    std::size_t floatsPerCell() const { return 3 * std::size_t(settings_.coefficients()); }
    /// The coefficients blended trilinearly over the cells around x into
    /// `out` (floatsPerCell() floats), each cell at its level at x where
    /// settings().gradients and finish() has run, each band shrunk by its
    /// noise where settings().denoise; false where no cell is.
    bool blend(const Vec3f& x, float* out) const;

    RadianceCacheSettings settings_;
    CellGrid grid_;                  ///< the box of cells and the slots of those with fibers
    std::vector<glm::ivec3> cells_;  ///< per slot
    std::vector<float> fiberLength_; ///< per slot: Λ
    /// Per slot [channel][lm]: L̄'s SH coefficients.
    LargeVector<float> coefficients_;
    /// Per slot and channel: Σ_f w_f², the deposits' second moment (see above).
    std::vector<float> secondMoment_;
    /// Per slot: its fibers' centroid x̄ and the inverse Σ⁻¹ of their
    /// positions' covariance (see Gradients).
    struct CellShape {
        Vec3f centroid{0.0f};
        glm::mat3 covarianceInverse{0.0f};
    };
    std::vector<CellShape> shapes_;
    /// Per slot and channel: m = Σ_f w_f·Y_00·d_f while deposits come, the
    /// slope β of c_00 after finish() (see Gradients).
    std::vector<Vec3f> slopes_;
    std::vector<ScatteringKernel> kernels_; ///< per fiber type, after finish()
    bool finished_ = false;
};

std::ostream& operator<<(std::ostream& os, const RadianceCache& c);

} // namespace hairvox
