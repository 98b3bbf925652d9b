#include "dual_scattering_fragment_shader.h"

#include <hairvox/core/math.h>
#include <hairvox/core/thread_scratch.h>
#include <hairvox/strands/groom.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace hairvox::detail {

namespace {

std::int64_t nanosSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() -
                                                                start)
        .count();
}

/// Radiance layers: dual scattering's ShadeResult components in order, or
/// the three single-scattering lobes and the volumetric multiple scattering.
std::size_t radianceLayers(bool multipleScattering) {
    return multipleScattering ? 4 : 5;
}
/// Floats per light among the averages: V, n, and for dual scattering T_s
/// (3), σ_f (3).
std::size_t lightFloats(bool multipleScattering) {
    return multipleScattering ? 2 : 8;
}

void put(float* out, const Rgb& c) {
    out[0] = c.r;
    out[1] = c.g;
    out[2] = c.b;
}

} // namespace

DualScatteringFragmentShader::DualScatteringFragmentShader(
    std::vector<DualScatteringShader> shaders, std::span<const std::uint8_t> fiberType,
    std::vector<Light> lights, std::vector<std::shared_ptr<const LightGlobalTerm>> lightTerms,
    ShadedEnvironment environment, ShadedMultiple multiple)
    : shaders_(std::move(shaders))
    , fiberType_(fiberType)
    , lights_(std::move(lights))
    , terms_(std::move(lightTerms))
    , environment_(std::move(environment))
    , multiple_(multiple)
    , layout_(hairShaderLayout(lights_, multiple.cache != nullptr))
    , stats_(lights_.size()) {
    if (const Groom* groom = multiple_.groom) {
        pointTangents_.resize(groom->points.size());
        for (std::size_t s = 0; s < groom->strandCount(); ++s) {
            const std::span<const Vec3f> points = groom->strand(s);
            strandTangents(points, {pointTangents_.data() + groom->strandStart[s], points.size()});
        }
    }
}

ShaderLayout hairShaderLayout(std::span<const Light> lights, bool multipleScattering) {
    ShaderLayout layout;
    layout.radiance = {"direct_R", "direct_TT", "direct_TRT"};
    if (multipleScattering)
        layout.radiance.emplace_back("multiple");
    else
        layout.radiance.insert(layout.radiance.end(), {"back_direct", "scatter"});
    for (const Light& light : lights) {
        layout.averages.push_back({light.name + ".V", 1});
        layout.averages.push_back({light.name + ".n", 1});
        if (!multipleScattering) {
            layout.averages.push_back({light.name + ".T_s", 3});
            layout.averages.push_back({light.name + ".sigma_f", 3});
        }
    }
    return layout;
}

void DualScatteringFragmentShader::shade(std::span<const ShadingPoint> points,
                                         std::span<float> out) const {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t lightCount = lights_.size();
    const std::size_t stride = layout_.stride();
    const bool volumetric = multiple_.cache != nullptr;
    const std::size_t radianceFloats = 3 * radianceLayers(volumetric);
    const std::size_t perLight = lightFloats(volumetric);
    std::fill(out.begin(), out.end(), 0.0f);
    // This thread's arrays from the batches before (every element written
    // before it is read).
    struct Scratch {
        std::vector<GlobalTermQuery> queries;
        std::vector<GlobalTerm> terms;
        FiberSamplePlan plan;                ///< the environment's samples along the fibers
        std::vector<GlobalTerm> sampleTerms; ///< at them
        std::vector<ShadeBatch> batches;     ///< per fiber type
        std::vector<std::vector<std::uint32_t>> members; ///< per fiber type: its points
    };
    ThreadScratch<Scratch> scratch;
    // (References, not a structured binding: Clang 14 does not let the
    // lambda below capture one.)
    std::vector<GlobalTermQuery>& queries = scratch->queries;
    std::vector<GlobalTerm>& terms = scratch->terms;
    std::vector<ShadeBatch>& batches = scratch->batches;
    std::vector<std::vector<std::uint32_t>>& members = scratch->members;
    FiberSamplePlan& plan = scratch->plan;
    std::vector<GlobalTerm>& sampleTerms = scratch->sampleTerms;
    queries.resize(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
        queries[i] = {points[i].position,
                      points[i].tangent,
                      points[i].strand,
                      true,
                      fiberTypeAt(fiberType_, points[i].segment),
                      points[i].segment};
    terms.resize(points.size());
    std::int64_t globalTermNanos = 0;
    std::vector<GlobalTermStats> batchStats(lightCount);

    // The points of each fiber type, shaded together per light (one batch
    // and no index list when the groom has one type).
    const std::size_t types = shaders_.size();
    batches.resize(std::max(batches.size(), types));
    members.resize(std::max(members.size(), types));
    const auto pointOf = [&](std::size_t type, std::size_t k) {
        return types == 1 ? k : std::size_t(members[type][k]);
    };
    if (types > 1) {
        for (std::size_t t = 0; t < types; ++t)
            members[t].clear();
        for (std::size_t i = 0; i < points.size(); ++i)
            members[queries[i].fiberType].push_back(static_cast<std::uint32_t>(i));
    }
    for (std::size_t t = 0; t < types; ++t) {
        ShadeBatch& batch = batches[t];
        batch.reset(types == 1 ? points.size() : members[t].size());
        for (std::size_t k = 0; k < batch.size(); ++k) {
            const ShadingPoint& p = points[pointOf(t, k)];
            batch.setView(k, p.toCamera, p.tangent);
        }
    }

    // The scene's lights, then the environment's (no AOVs of their own).
    const std::size_t environmentCount = environment_.lights.size();
    GlobalTermStats environmentStats;
    const bool planned = environmentCount > 0 && environment_.groom && environment_.spacing > 0;
    if (planned) {
        const auto planStart = std::chrono::steady_clock::now();
        plan.plan(queries, *environment_.groom, environment_.spacing);
        sampleTerms.resize(plan.samples().size()); // every element written by evaluate
        globalTermNanos += nanosSince(planStart);
    }
    for (std::size_t l = 0; l < lightCount + environmentCount; ++l) {
        const bool ofEnvironment = l >= lightCount;
        const std::shared_ptr<const LightGlobalTerm>& term =
            ofEnvironment ? environment_.terms[l - lightCount] : terms_[l];
        // A region's terms at its samples, interpolated to each point as the
        // batch takes it: no array of them in between (the default scene's 8
        // regions wrote and read back 22M).
        const bool interpolated = ofEnvironment && planned && term;
        if (term) {
            const auto evalStart = std::chrono::steady_clock::now();
            if (interpolated) {
                GlobalTermStats stats = term->evaluate(plan.samples(), sampleTerms);
                stats.queries = points.size();
                environmentStats += stats;
            } else {
                (ofEnvironment ? environmentStats : batchStats[l]) +=
                    term->evaluate(queries, terms);
            }
            globalTermNanos += nanosSince(evalStart);
        } else {
            std::fill(terms.begin(), terms.end(), GlobalTerm::blocked());
        }
        if (!ofEnvironment)
            for (std::size_t i = 0; i < points.size(); ++i) {
                const GlobalTerm& g = terms[i];
                float* lightOut = out.data() + i * stride + radianceFloats + l * perLight;
                lightOut[0] = g.V;
                lightOut[1] = g.n;
                if (!volumetric) {
                    put(lightOut + 2, g.T_s);
                    put(lightOut + 5, safeSqrt(g.sigma2_f));
                }
            }
        if (!term)
            continue; // a skipped light contributes nothing
        const Light& light = ofEnvironment ? environment_.lights[l - lightCount] : lights_[l];
        const float spread2 = ofEnvironment ? environment_.spread2[l - lightCount] : 0.0f;
        for (std::size_t t = 0; t < types; ++t) {
            ShadeBatch& batch = batches[t];
            if (light.kind == Light::Kind::Directional) {
                const Light::Path path = light.pathFrom(Vec3f(0.0f));
                batch.setIncident(path.omega, light.irradiance(path.distance));
            } else {
                for (std::size_t k = 0; k < batch.size(); ++k) {
                    const Light::Path path = light.pathFrom(points[pointOf(t, k)].position);
                    batch.setIncident(k, path.omega, light.irradiance(path.distance));
                }
            }
            for (std::size_t k = 0; k < batch.size(); ++k) {
                GlobalTerm g =
                    interpolated ? plan.at(sampleTerms, pointOf(t, k)) : terms[pointOf(t, k)];
                if (volumetric)
                    g.T_s = Rgb(0.0f); // the forward-scattered light is the cache's
                batch.setGlobalTerm(k, g);
            }
            shaders_[t].shade(batch, spread2);
        }
    }
    for (std::size_t t = 0; t < types; ++t) {
        const ShadeBatch& batch = batches[t];
        for (std::size_t k = 0; k < batch.size(); ++k) {
            float* o = out.data() + pointOf(t, k) * stride;
            const ShadeResult r = batch.radiance(k);
            put(o, r.directR);
            put(o + 3, r.directTT);
            put(o + 6, r.directTRT);
            if (!volumetric) {
                put(o + 9, r.backDirect);
                put(o + 12, r.scatter);
            }
        }
    }
    if (volumetric)
        shadeMultiple(points, queries, out);
    globalTermNanos_ += globalTermNanos;
    shadeNanos_ += nanosSince(start);
    const std::lock_guard lock(statsMutex_);
    for (std::size_t l = 0; l < lightCount; ++l)
        stats_[l] += batchStats[l];
    environmentStats_ += environmentStats;
}

void DualScatteringFragmentShader::shadeMultiple(std::span<const ShadingPoint> points,
                                                 std::span<const GlobalTermQuery> queries,
                                                 std::span<float> out) const {
    const RadianceCache& cache = *multiple_.cache;
    const std::size_t stride = layout_.stride(),
                      n = 3 * std::size_t(cache.settings().coefficients());
    const int order = cache.settings().shOrder;
    struct Scratch {
        FiberSamplePlan plan;
        std::vector<ShFrameRotation> frames; ///< per sample
        std::vector<Vec3f> positions;        ///< per sample
        std::vector<float> incident;         ///< per sample: n floats in its frame
    };
    ThreadScratch<Scratch> scratch;
    FiberSamplePlan& plan = scratch->plan;
    std::vector<ShFrameRotation>& frames = scratch->frames;
    std::vector<Vec3f>& positions = scratch->positions;
    std::vector<float>& incident = scratch->incident;
    bool planned = multiple_.groom && multiple_.spacing > 0;
    if (planned) {
        plan.plan(queries, *multiple_.groom, multiple_.spacing);
        // Fragments far apart along their fibers (a groom seen from afar)
        // need more samples than points: each is then read where it is.
        planned = plan.samples().size() < points.size();
    }
    const std::span<const GlobalTermQuery> samples = planned ? plan.samples() : queries;
    frames.clear();
    positions.clear();
    for (const GlobalTermQuery& q : samples) {
        Vec3f u = q.tangent;
        if (planned && q.onFiber && q.segment != kUnknownSegment) {
            const Vec3f& p0 = multiple_.groom->points[q.segment];
            const Vec3f d = multiple_.groom->points[q.segment + 1] - p0;
            const float t = std::clamp(glm::dot(q.position - p0, d) / glm::dot(d, d), 0.0f, 1.0f);
            u = shadingTangent(pointTangents_[q.segment], pointTangents_[q.segment + 1],
                               std::isnan(t) ? 0.0f : t, q.tangent);
        }
        frames.emplace_back(u, order);
        positions.push_back(q.position);
    }
    incident.resize(samples.size() * n); // every element written by incidentInFrames
    cache.incidentInFrames(positions, frames, incident.data());
    for (std::size_t i = 0; i < points.size(); ++i) {
        const FiberSamplePlan::Where w =
            planned ? plan.where(i) : FiberSamplePlan::Where{static_cast<std::uint32_t>(i), 0.0f};
        const std::size_t t = queries[i].fiberType;
        const Vec3f& omega_o = points[i].toCamera;
        const float* c = incident.data() + std::size_t(w.sample) * n;
        Rgb L = cache.outgoingInFrame(c, frames[w.sample], omega_o, t);
        if (w.f > 0)
            L = lerp(w.f, L, cache.outgoingInFrame(c + n, frames[w.sample + 1], omega_o, t));
        put(out.data() + i * stride + 9, L);
    }
}

GlobalTermStats DualScatteringFragmentShader::environmentStats() const {
    const std::lock_guard lock(statsMutex_);
    return environmentStats_;
}

std::vector<GlobalTermStats> DualScatteringFragmentShader::stats() const {
    const std::lock_guard lock(statsMutex_);
    return stats_;
}

} // namespace hairvox::detail
