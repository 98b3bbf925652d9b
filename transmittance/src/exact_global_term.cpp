#include <hairvox/core/error.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/math.h>
#include <hairvox/core/rng.h>
#include <hairvox/transmittance/exact_global_term.h>

#include <glm/common.hpp>
#include <glm/vec3.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

namespace hairvox {

void ExactOptions::validate() const {
    if (rays < 1 || rays > 65536)
        throw InputError(strCat("exact mode: rays = ", rays, " should be in the range [1, 65536]"));
    if (!(radius >= 0 && radius < 1e3f))
        throw InputError(
            strCat("exact mode: radius = ", radius, " should be in the range [0, 1000)"));
}

namespace {

class ExactModel;

class ExactLightGlobalTerm final : public LightGlobalTerm {
public:
    ExactLightGlobalTerm(const ExactModel& model, const Light& light)
        : model_(model)
        , light_(light) {}
    GlobalTermStats evaluate(std::span<const GlobalTermQuery> queries,
                             std::span<GlobalTerm> out) const override;

private:
    GlobalTerm evaluateOne(const GlobalTermQuery& q, std::vector<FiberCrossing>& hits) const;

    const ExactModel& model_;
    Light light_;
};

class ExactModel final : public GlobalTermModel {
public:
    ExactModel(const Groom& groom, CrossingTables crossingTables,
               const GlobalTermSettings& globalSettings, const ExactOptions& exactOptions)
        : scene(groom, globalSettings.fiberScale)
        , fiberType(groom.fiberType)
        , crossings(std::move(crossingTables))
        , settings(globalSettings)
        , options(exactOptions) {}

    GlobalTermMode mode() const override { return GlobalTermMode::Exact; }
    using GlobalTermModel::forLight;
    std::unique_ptr<LightGlobalTerm> forLight(const Light& light,
                                              LightWorkspace* workspace) const override {
        if (workspace) // makeWorkspace() makes none: another model's
            throw std::invalid_argument("exact global term: a workspace of another model");
        return withSurfaces(std::make_unique<ExactLightGlobalTerm>(*this, light), settings.surfaces,
                            light);
    }

    RayScene scene;
    std::vector<std::uint8_t> fiberType; ///< the groom's (Groom::fiberType)
    CrossingTables crossings;            ///< per fiber type
    GlobalTermSettings settings;
    ExactOptions options;
};

/// Per-query seed: a function of the point (not of its position in a batch),
/// so results do not depend on batching or threads.
std::uint64_t querySeed(const GlobalTermQuery& q, std::uint64_t seed) {
    return Hasher().value(seed).value(q.position).digest();
}

GlobalTerm ExactLightGlobalTerm::evaluateOne(const GlobalTermQuery& q,
                                             std::vector<FiberCrossing>& hits) const {
    const Light::Path path = light_.pathFrom(q.position);
    if (!(path.distance > 0))
        return GlobalTerm::unoccluded();
    const ExactOptions& opt = model_.options;
    const std::optional<FiberPoint> own =
        q.onFiber ? model_.scene.locate(q.position, q.strand) : std::nullopt;
    const float ownSlack = 2.0f * (opt.radius + model_.scene.ribbonWidth());

    Vec3f e1, e2;
    coordinateSystem(path.omega, e1, e2);
    Pcg32 rng(querySeed(q, opt.seed));
    const float rotation = static_cast<float>(TwoPi) * rng.uniformFloat();
    constexpr float goldenAngle = 2.39996322972865332f;

    double nSum = 0, vSum = 0, crossedRays = 0;
    Rgbd pSum, beta2Sum;
    for (int ray = 0; ray < opt.rays; ++ray) {
        // Fibonacci spiral over the disk (uniform area density), randomly rotated.
        const float rho =
            opt.radius * std::sqrt((static_cast<float>(ray) + 0.5f) / static_cast<float>(opt.rays));
        const float phi = rotation + goldenAngle * static_cast<float>(ray);
        const Vec3f origin = q.position + rho * (std::cos(phi) * e1 + std::sin(phi) * e2);
        model_.scene.crossings(origin, path.omega, path.distance, hits);

        int m = 0;
        Rgb logP(0.0f), beta2(0.0f);
        for (const FiberCrossing& c : hits) {
            if (own && RayScene::isOwnFiber(c.strand, c.arcLength, *own,
                                            glm::distance(origin + c.t * path.omega, q.position),
                                            ownSlack))
                continue; // the point's own fiber, not a curl coming back
            const std::uint8_t type =
                fiberTypeAt(model_.fiberType, segmentStartPoint(c.strand, c.segment));
            const CrossingTable::Values v =
                model_.crossings[type].crossing(glm::dot(path.omega, c.tangent));
            logP += v.logABar_f;
            beta2 += v.beta2Bar_f;
            ++m;
        }
        nSum += m;
        vSum += m == 0 ? 1.0 : 0.0;
        pSum += Rgbd(exp(logP));
        if (m > 0) {
            beta2Sum += Rgbd(beta2);
            crossedRays += 1;
        }
    }
    const double invRays = 1.0 / opt.rays;
    GlobalTerm g;
    g.n = static_cast<float>(nSum * invRays);
    g.V = static_cast<float>(vSum * invRays);
    g.P = Rgb(pSum * invRays);
    g.T_s = model_.settings.dualScattering.d_f * max(g.P - Rgb(g.V), Rgb(0.0f));
    g.sigma2_f = crossedRays > 0 ? Rgb(beta2Sum / crossedRays) : Rgb(0.0f);
    return g;
}

GlobalTermStats ExactLightGlobalTerm::evaluate(std::span<const GlobalTermQuery> queries,
                                               std::span<GlobalTerm> out) const {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 16),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          std::vector<FiberCrossing> hits;
                          for (std::size_t i = range.begin(); i != range.end(); ++i)
                              out[i] = evaluateOne(queries[i], hits);
                      });
    GlobalTermStats stats;
    stats.queries = queries.size();
    stats.evaluated = queries.size();
    return stats;
}

} // namespace

std::unique_ptr<GlobalTermModel> makeExactModel(const Groom& groom, CrossingTables crossings,
                                                const GlobalTermSettings& settings,
                                                const ExactOptions& options) {
    settings.validate();
    options.validate();
    checkCrossingTables(crossings, fiberTypeCount(groom));
    return std::make_unique<ExactModel>(groom, std::move(crossings), settings, options);
}

} // namespace hairvox
