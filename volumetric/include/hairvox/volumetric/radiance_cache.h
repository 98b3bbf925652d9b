// hairvox volumetric: the radiance cache — light that has scattered at least
// once, per cell of a coarse grid over the hair, as the fibers there receive
// it (radiance_basis.h); what the volumetric integrator's fragments read
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
// Frames. Each cell has one frame (FiberFrame::about its fibers' mean
// tangent, the length-weighted Σ_v λ_v E_v[u], or the 3³ neighbourhood's
// where that cancels, or +y); incident radiance is expanded in it: bins of
// s = ω_i·axis and azimuthal harmonics about the axis (radiance_basis.h).
//
// Incident radiance. A fragment lies on a fiber, so what it needs of a cell
// is the radiance averaged over the cell's fibers, L̄(ω) = ∫ λ L(x, ω) dV / Λ,
// Λ = ∫ λ dV = Σ_v λ_v h³ the cell's fiber length. deposit() adds one sample
// of Λ·L̄ (radiance × solid angle × fiber length: a flight's power times the
// fiber length it swept, Φ·∫λ dt, the track-length estimator of
// multiple_scattering.h) and divides by Λ. The fibers' average rather than
// the volume's: a cell half inside the head, or half beyond the hair's
// surface, would otherwise mix in the radiance of space no fiber sees.
//
// Outgoing radiance: the lobes split by where their shape comes from.
// finish() applies each fiber type's two scattering kernels
// (scattering_kernel.h) to every cell's incident coefficients: its backward
// lobes (R and TRT) and its forward lobe (TT), into two tables per type.
// outgoing() reads them at a fragment of tangent u toward ω_o: trilinear
// between the 8 cell centres around x (cells without fibers left out and
// the weights renormalised), linearly between the tabulated s_o, the
// backward table in the fragment's own frame (FiberFrame::along(u, cell
// frame): s_o = ω_o·u) and the forward table in the cell's frame. R and TRT
// leave a fiber in a cone about its own tangent, a few degrees wide, so the
// fragment's inclination decides where they go; TT continues the light
// through the lock, which the cell's mean orientation describes better than
// one fiber does. Measured on the default scene against the path tracer
// (docs/DESIGN.md §9), per light: every lobe from the cell's frame read at
// the fragment's inclination put +5% into the back light's multiple
// scattering, read at the cell's own inclination −5%; each fragment's own
// f_s integrated against the cell's field, fixed in the world, +14% into
// the key light's. With the split, the multiple layer is −4% of the path
// tracer's and the hair's radiance −2%.
#pragma once

#include <hairvox/core/large_array.h>
#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/volumetric/cell_grid.h>
#include <hairvox/volumetric/radiance_basis.h>
#include <hairvox/volumetric/scattering_kernel.h>

#include <cstdint>
#include <ostream>
#include <vector>

namespace hairvox {

struct FiberGrid;

struct RadianceCacheSettings {
    RadianceBasis basis;
    int cellVoxels = 2; ///< m: fiber-grid voxels per cell side, [1, 16]

    void validate() const;
};

std::ostream& operator<<(std::ostream& os, const RadianceCacheSettings& s);

class RadianceCache {
public:
    /// The cells of `grid` (see above), each with its frame and zeroed
    /// coefficients. Throws InputError if the estimated memory exceeds
    /// `memoryBudget` bytes (the message states the estimate).
    RadianceCache(const FiberGrid& grid, const RadianceCacheSettings& settings,
                  std::uint64_t memoryBudget);

    /// Bytes the cache of `grid` would hold with `types` fiber types
    /// (incident and outgoing coefficients, index, frames).
    static std::uint64_t estimateBytes(const FiberGrid& grid, const RadianceCacheSettings& settings,
                                       std::size_t types);

    const RadianceCacheSettings& settings() const { return settings_; }
    std::size_t cellCount() const { return cells_.size(); }
    float cellSize() const { return grid_.cellSize(); }
    /// The world-space box the cells cover.
    Bounds3f bounds() const;
    /// The box of cells the index spans: first cell and cells a side.
    const CellGrid& cells() const { return grid_; }
    std::uint64_t memoryBytes() const;

    /// The slot of the cell holding voxel v (index space), or -1.
    std::int64_t slotOfVoxel(const glm::ivec3& v) const;

    /// Adds to the cell's incident radiance a sample of Λ·L̄ (radiance ×
    /// solid angle × fiber length) arriving from unit ω_i (pointing away from
    /// the cell, toward where the light comes from): sample/Λ in the basis,
    /// in the cell's frame. Not thread-safe for one slot.
    void deposit(std::uint32_t slot, const Vec3f& omega_i, const Rgb& sample);

    /// Turns every cell's incident radiance into outgoing radiance with the
    /// kernels of each fiber type t: kernels[2t] its backward lobes (R and
    /// TRT), kernels[2t + 1] its forward lobe (TT). In parallel.
    void finish(const std::vector<ScatteringKernel>& kernels);
    bool finished() const { return finished_; }

    /// The radiance a fiber of type `type` and unit tangent u at x sends
    /// toward unit ω_o from the cached light (see above); 0 outside the
    /// cells. Needs finish().
    Rgb outgoing(const Vec3f& x, const Vec3f& u, const Vec3f& omega_o, std::size_t type) const;
    /// The incident radiance L̄(x, ω_i) the fibers at x receive (trilinear
    /// between the cells' expansions), before finish():
    /// for tests and plots.
    Rgb incident(const Vec3f& x, const Vec3f& omega_i) const;

    /// The slot of the cell holding world point x, or -1.
    std::int64_t slotAt(const Vec3f& x) const { return grid_.slotAt(x); }
    /// The cell's reference frame: its fibers' mean tangent, and the origin
    /// of the azimuths.
    const FiberFrame& frame(std::size_t slot) const { return frames_[slot]; }
    /// The world position of a cell's centre.
    Vec3f cellCentre(std::size_t slot) const { return grid_.centre(cells_[slot]); }
    /// Λ, the cell's fiber length (world units).
    float fiberLength(std::size_t slot) const { return fiberLength_[slot]; }

private:
    std::size_t floatsPerCell() const { return 3 * std::size_t(settings_.basis.coefficients()); }

    RadianceCacheSettings settings_;
    std::size_t types_ = 1;
    CellGrid grid_;                  ///< the box of cells and the slots of those with fibers
    std::vector<glm::ivec3> cells_;  ///< per slot
    std::vector<FiberFrame> frames_;  ///< per slot
    std::vector<float> fiberLength_;  ///< per slot: Λ
    /// Outgoing table k (2·type + 0 backward, + 1 forward), per slot.
    float* table(std::size_t k) { return k == 0 ? coefficients_.data() : outgoing_[k - 1].data(); }
    const float* table(std::size_t k) const {
        return k == 0 ? coefficients_.data() : outgoing_[k - 1].data();
    }

    /// Per slot [channel][bin][coefficient]: incident radiance until finish(),
    /// then table 0 (type 0's backward lobes); tables 1.. in `outgoing_`.
    LargeVector<float> coefficients_;
    std::vector<LargeVector<float>> outgoing_;
    bool finished_ = false;
};

std::ostream& operator<<(std::ostream& os, const RadianceCache& c);

} // namespace hairvox
