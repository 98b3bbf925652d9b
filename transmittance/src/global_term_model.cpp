#include <hairvox/core/error.h>
#include <hairvox/core/thread_scratch.h>
#include <hairvox/transmittance/global_term_model.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hairvox {

void GlobalTermSettings::validate() const {
    fiberScale.validate();
    dualScattering.validate();
}

GlobalTerm globalTermFromDepths(float n, const Rgb& tauP, const Rgb& sumBeta2, float d_f) {
    GlobalTerm g;
    g.n = n;
    g.V = std::exp(-n);
    g.P = exp(-tauP);
    g.T_s = d_f * max(g.P - Rgb(g.V), Rgb(0.0f));
    // σ_f² conditioned on at least one crossing: E[Σβ̄²] / P(m ≥ 1). As n → 0,
    // 1 − e^{−n} → n and the ratio tends to the mean β̄² of the fibers in front.
    // 1 − e^{−n} is 1 − V where that is well conditioned (relative error
    // < 1e-6 for n ≥ 1/16) and its series below (error < n⁴/120 < 2e-7):
    // expm1f cost 3% of a 1080p render's CPU time.
    const float crossed =
        n >= 0.0625f ? 1.0f - g.V : n * (1.0f - n * (0.5f - n * (1.0f / 6.0f - n / 24.0f)));
    g.sigma2_f = crossed > 0 ? sumBeta2 / crossed : Rgb(0.0f);
    return g;
}

namespace {

class SurfaceShadowedGlobalTerm final : public LightGlobalTerm {
public:
    SurfaceShadowedGlobalTerm(std::unique_ptr<LightGlobalTerm> inner,
                              std::shared_ptr<const SurfaceScene> surfaces, const Light& light)
        : inner_(std::move(inner))
        , surfaces_(std::move(surfaces))
        , light_(light) {}

    std::size_t memoryBytes() const override { return inner_->memoryBytes(); }

    GlobalTermStats evaluate(std::span<const GlobalTermQuery> queries,
                             std::span<GlobalTerm> out) const override {
        // One shadow segment per query, tested together (every element of
        // these arrays is written before it is read).
        struct Scratch {
            std::vector<Vec3f> origins, dirs;
            std::vector<float> tMax;
            std::vector<std::uint8_t> occluded;
            std::vector<GlobalTermQuery> open;
            std::vector<std::size_t> openIndex;
            std::vector<GlobalTerm> openOut;
        };
        ThreadScratch<Scratch> scratch;
        auto& [origins, dirs, tMax, occluded, open, openIndex, openOut] = *scratch;
        origins.resize(queries.size());
        dirs.resize(queries.size());
        tMax.resize(queries.size());
        occluded.resize(queries.size());
        for (std::size_t i = 0; i < queries.size(); ++i) {
            const Light::Path path = light_.pathFrom(queries[i].position);
            origins[i] = queries[i].position;
            dirs[i] = path.omega;
            tMax[i] = path.distance;
        }
        surfaces_->occluded(origins, dirs, tMax, occluded);
        const auto blocked =
            static_cast<std::size_t>(std::count(occluded.begin(), occluded.end(), std::uint8_t(1)));
        GlobalTermStats stats;
        if (blocked == 0) {
            // The common batch: nothing to take out, nothing to copy.
            stats = inner_->evaluate(queries, out);
        } else {
            open.clear();
            openIndex.clear();
            for (std::size_t i = 0; i < queries.size(); ++i) {
                if (occluded[i]) {
                    out[i] = GlobalTerm::blocked();
                } else {
                    open.push_back(queries[i]);
                    openIndex.push_back(i);
                }
            }
            openOut.resize(open.size());
            stats = inner_->evaluate(open, openOut);
            for (std::size_t k = 0; k < open.size(); ++k)
                out[openIndex[k]] = openOut[k];
        }
        stats.queries = queries.size();
        stats.blockedBySurface += blocked;
        return stats;
    }

    bool blocksEverything() const override {
        return (light_.kind == Light::Kind::Point && surfaces_->contains(light_.position)) ||
               inner_->blocksEverything();
    }

private:
    std::unique_ptr<LightGlobalTerm> inner_;
    std::shared_ptr<const SurfaceScene> surfaces_;
    Light light_;
};

} // namespace

std::unique_ptr<LightGlobalTerm> withSurfaces(std::unique_ptr<LightGlobalTerm> inner,
                                              std::shared_ptr<const SurfaceScene> surfaces,
                                              const Light& light) {
    if (!surfaces || surfaces->empty())
        return inner;
    return std::make_unique<SurfaceShadowedGlobalTerm>(std::move(inner), std::move(surfaces),
                                                       light);
}

} // namespace hairvox
