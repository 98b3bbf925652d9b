// hairvox transmittance: the one interface behind which the three modes of
// the dual-scattering global term live (docs/DESIGN.md §5).
//
// A GlobalTermModel is built once per scene (Embree scene, fiber grid, tables);
// forLight() prepares everything that depends on one light (for the grid mode
// a cache volume of the global term) and returns a LightGlobalTerm that
// evaluates batches of shading points. Every consumer — renderer, probe,
// benchmark — switches modes only by building a different model. Several
// lights prepared one after another share a LightWorkspace: what a model
// builds for every light alike (the grid modes' rates volume: its layout is
// the fiber grid's, only its values depend on the light) is then built once.
#pragma once

#include <hairvox/core/vecmath.h>
#include <hairvox/geometry/light.h>
#include <hairvox/geometry/ray_scene.h>
#include <hairvox/geometry/surface_scene.h>
#include <hairvox/shading/fiber_params.h>
#include <hairvox/shading/global_term.h>
#include <hairvox/strands/groom.h>
#include <hairvox/transmittance/crossing_table.h>
#include <hairvox/transmittance/global_term_mode.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace hairvox {

class DiskCache;

inline constexpr std::uint32_t kUnknownSegment = std::numeric_limits<std::uint32_t>::max();

/// A point on a fiber and that fiber's unit tangent (root → tip). The strand
/// index, when the caller knows it, saves the exact mode a search for the
/// point's own fiber. A point on a surface (skin lit through the hair) is not
/// on a fiber: no own fiber is searched for, and approx mode gives the fibers
/// in front the orientation `tangent` (any unit vector ⟂ the light direction:
/// fibers across the light, the common case of hair over skin).
struct GlobalTermQuery {
    Vec3f position;
    Vec3f tangent;
    std::uint32_t strand = kUnknownStrand;
    bool onFiber = true;
    /// The query's fiber type (Groom::fiberType): approx mode assumes the
    /// fibers in front are of this type.
    std::uint8_t fiberType = 0;
    /// The segment the point lies on, by its root-side point (Groom::points),
    /// when known: lets a model sample the global term along the fiber
    /// (alongFibers()).
    std::uint32_t segment = kUnknownSegment;
};

/// What a per-light evaluation skipped (DESIGN.md §7).
struct GlobalTermStats {
    std::uint64_t queries = 0;
    std::uint64_t blockedBySurface = 0; ///< shadowed by an opaque surface: no march, no rays
    std::uint64_t emptyPaths = 0;       ///< of the points evaluated, nothing in front: n = 0
    /// Points the mode evaluated: the queries not blocked by a surface, or
    /// fewer — the samples along the fibers they were interpolated from (alongFibers()).
    std::uint64_t evaluated = 0;

    GlobalTermStats& operator+=(const GlobalTermStats& o) {
        queries += o.queries;
        blockedBySurface += o.blockedBySurface;
        emptyPaths += o.emptyPaths;
        evaluated += o.evaluated;
        return *this;
    }
};

/// The global term toward one light, ready to evaluate. Thread-safe.
class LightGlobalTerm {
public:
    virtual ~LightGlobalTerm() = default;
    /// out[i] is the global term at queries[i] (same size); deterministic for
    /// any thread count and any batching.
    virtual GlobalTermStats evaluate(std::span<const GlobalTermQuery> queries,
                                     std::span<GlobalTerm> out) const = 0;
    /// True when the light can reach no point at all (a point light inside an
    /// opaque surface): every query would be GlobalTerm::blocked(), so a renderer
    /// skips the light.
    virtual bool blocksEverything() const { return false; }
    /// Bytes held for this light's queries (the grid modes' light-space cache
    /// or rate volume; 0 for modes that hold nothing per light).
    virtual std::size_t memoryBytes() const { return 0; }
};

/// Inputs every mode shares.
struct GlobalTermSettings {
    FiberScale fiberScale; ///< D and k: optical depth λ·k·D·cos θ, ribbons k·D wide
    DualScatteringParams dualScattering;
    /// The opaque surfaces (head, meshes): they block light entirely. Null: none.
    std::shared_ptr<const SurfaceScene> surfaces;
    /// The strands the queries lie on, for the grid modes' sampling along
    /// the fibers (GridOptions::fiberSampleSpacing). Null: every query is
    /// evaluated. Must outlive the model.
    const Groom* groom = nullptr;
    /// Where the grid modes keep each light's prepared cache for other
    /// processes (the render tasks of a shot, on other machines) and look for
    /// it first, or null. Its entries are keyed by `diskCacheKey` — the
    /// caller's digest of everything besides the light that the preparation
    /// is made of: the fiber grid's and the crossing tables' contents, the
    /// fiber scale and the grid options — and the light. Must outlive the model.
    const DiskCache* diskCache = nullptr;
    std::uint64_t diskCacheKey = 0;
    /// The lights whose preparation is stored there (null: every light's);
    /// a light that moves from frame to frame is prepared for one frame only.
    std::function<bool(const Light&)> diskCacheStores;

    void validate() const;
};

/// What a model keeps from one light's preparation for the next: made by
/// GlobalTermModel::makeWorkspace(), passed to forLight() for each light in
/// turn (one call at a time), and dropped once the lights are prepared — it
/// holds memory no light keeps.
class LightWorkspace {
public:
    virtual ~LightWorkspace() = default;
};

class GlobalTermModel {
public:
    virtual ~GlobalTermModel() = default;
    virtual GlobalTermMode mode() const = 0;
    /// Prepares one light.
    std::unique_ptr<LightGlobalTerm> forLight(const Light& light) const {
        return forLight(light, nullptr);
    }
    /// The same, reusing `workspace` (this model's makeWorkspace(); null:
    /// none); the result does not depend on it. std::invalid_argument for
    /// another model's workspace.
    virtual std::unique_ptr<LightGlobalTerm> forLight(const Light& light,
                                                      LightWorkspace* workspace) const = 0;
    /// A workspace for forLight(), or null where the model has nothing to share.
    virtual std::unique_ptr<LightWorkspace> makeWorkspace() const { return nullptr; }
};

/// The global term from the expected optical depths along a shadow path under
/// a Poisson model of fiber crossings (DESIGN.md §5), shared by the grid-based
/// modes:
///   n           expected number of crossings          → V = e^{−n}
///   tauP        expected attenuation depth (per RGB)   → P = e^{−tauP}
///   sumBeta2    expected Σβ̄_f² over crossings          → σ_f² = sumBeta2 / (1 − V)
/// T_s = d_f·(P − V) ≥ 0, continuous as n → 0.
GlobalTerm globalTermFromDepths(float n, const Rgb& tauP, const Rgb& sumBeta2, float d_f);

/// The samples along the fibers that alongFibers() evaluates for a batch of
/// queries, and how each query is interpolated from them. Planned once, it
/// serves every light sampled with the same spacing (an environment's
/// regions: their planning was a tenth of such a render, once per region).
class FiberSamplePlan {
public:
    /// Plans `queries` as alongFibers() does (`spacing` in world units, > 0).
    /// With `shareVertices`, a strand vertex ending one run and starting the
    /// next (segments s and s + 1 of a strand, one after the other) is one
    /// sample: for evaluations that do not read a sample's tangent (grid
    /// mode), whose value at a vertex is then the same from either segment.
    void plan(std::span<const GlobalTermQuery> queries, const Groom& groom, float spacing,
              bool shareVertices = false);
    /// The points to evaluate.
    std::span<const GlobalTermQuery> samples() const { return samples_; }
    /// out[j], the global term at query j, from the samples' values
    /// (values.size() == samples().size(), out.size() == the queries').
    void interpolate(std::span<const GlobalTerm> values, std::span<GlobalTerm> out) const {
        for (std::size_t j = 0; j < where_.size(); ++j)
            out[j] = at(values, j);
    }
    /// The global term at query j alone (what interpolate() writes to out[j]):
    /// for a caller that consumes each query's term once, without an array of them.
    GlobalTerm at(std::span<const GlobalTerm> values, std::size_t j) const {
        const Where w = where_[j];
        if (!(w.f > 0))
            return values[w.sample];
        const GlobalTerm &a = values[w.sample], &b = values[w.sample + 1];
        const auto mix = [f = w.f](const auto& x, const auto& y) {
            return x + f * (y - x);
        };
        GlobalTerm g;
        g.n = mix(a.n, b.n);
        g.V = mix(a.V, b.V);
        g.P = mix(a.P, b.P);
        g.T_s = mix(a.T_s, b.T_s);
        g.sigma2_f = mix(a.sigma2_f, b.sigma2_f);
        return g;
    }

    /// How a query is read: the sample at or below it (an index into
    /// samples()) and the fraction toward the next one, a sample of the same
    /// segment with the same tangent (f = 0: that sample alone).
    struct Where {
        std::uint32_t sample;
        float f;
    };
    /// Query j's (for values other than GlobalTerm: interpolate() reads it so).
    Where where(std::size_t j) const { return where_[j]; }

private:
    std::vector<GlobalTermQuery> samples_;
    std::vector<Where> where_; ///< every element written before it is read
    std::vector<int> needed_;  ///< sample numbers along the current segment
};

/// Wraps a per-light evaluation so that a point on a fiber segment
/// (GlobalTermQuery::segment) gets the global term interpolated linearly
/// between samples along that segment, at t = k/m with m = ⌈length/spacing⌉
/// (world units; the samples at t = 0 and 1 are the strand's vertices
/// exactly): the global term varies on the scale of the grid's voxels, a
/// fragment every pixel. A batch evaluates each sample its queries need
/// once per run of consecutive queries on one segment (callers that order
/// their points by segment share the most), and with `shareVertices` once
/// for the two runs of consecutive segments of a strand that meet at it
/// (FiberSamplePlan::plan). A sample's position depends only on its segment,
/// so batches, tiles and thread counts agree; queries without a segment, or
/// not on a fiber, are evaluated as they are. The samples take the segment's
/// direction as their tangent (what approx mode reads: it must not share
/// vertices).
std::unique_ptr<LightGlobalTerm> alongFibers(std::unique_ptr<LightGlobalTerm> inner,
                                             const Groom& groom, float spacing,
                                             bool shareVertices = false);

/// Wraps a per-light evaluation so that points whose path to the light meets
/// an opaque surface get GlobalTerm::blocked() without being evaluated: one
/// shadow ray per point through the surfaces alone (SurfaceScene::occluded),
/// exact in every mode — the grid modes do not voxelise surfaces. Returns
/// `inner` unchanged when there are no surfaces.
std::unique_ptr<LightGlobalTerm> withSurfaces(std::unique_ptr<LightGlobalTerm> inner,
                                              std::shared_ptr<const SurfaceScene> surfaces,
                                              const Light& light);

} // namespace hairvox
