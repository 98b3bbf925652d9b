#include <hairvox/core/distribution.h>
#include <hairvox/core/error.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/math.h>
#include <hairvox/core/parallel.h>
#include <hairvox/core/progress.h>
#include <hairvox/core/sampling.h>
#include <hairvox/core/sobol.h>
#include <hairvox/geometry/ray_scene.h>
#include <hairvox/pathtrace/path_tracer.h>
#include <hairvox/shading/marschner.h>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

namespace hairvox {

void PathTraceSettings::validate() const {
    if (spp < 1 || spp > 1'000'000)
        throw InputError(strCat("path tracing: spp = ", spp, ": expected an integer in [1, 1000000]"));
    if (!(timeLimit >= 0 && timeLimit <= 1e7))
        throw InputError(
            strCat("path tracing: time limit = ", timeLimit, " s: expected a number in [0, 1e7]"));
    if (maxDepth < 1 || maxDepth > 100'000)
        throw InputError(strCat("path tracing: max depth = ", maxDepth,
                                ": expected an integer in [1, 100000]"));
    if (rouletteDepth < 1 || rouletteDepth > 100'000)
        throw InputError(strCat("path tracing: roulette depth = ", rouletteDepth,
                                ": expected an integer in [1, 100000]"));
}

std::ostream& operator<<(std::ostream& os, const PathTraceSettings& s) {
    return os << "PathTraceSettings(spp=" << s.spp << ", timeLimit=" << s.timeLimit
              << " s, maxDepth=" << s.maxDepth << ", rouletteDepth=" << s.rouletteDepth
              << ", seed=" << s.seed << ")";
}

std::ostream& operator<<(std::ostream& os, const PathTraceStats& s) {
    return os << "PathTraceStats(" << s.spp << " spp (" << s.sppThisRun << " this run) in "
              << s.seconds << " s; " << s.paths << " paths, " << s.rays << " rays, "
              << s.shadowRays << " shadow rays, " << s.scatteringEvents
              << " scattering events, deepest " << s.deepestPath << ", " << s.pathsAtDepthCap
              << " at the depth cap" << (s.timeLimited ? ", time-limited" : "")
              << (s.interrupted ? ", interrupted" : "") << ")";
}

namespace {

using Clock = std::chrono::steady_clock;

// What one sample contributes, as floats: where each layer's channels are.
enum Slot : std::size_t {
    kBeauty = 0,      // RGB
    kAlpha = 3,       // 1
    kHairAlpha = 4,   // 1
    kDirectR = 5,     // RGB
    kDirectTT = 8,    // RGB
    kDirectTRT = 11,  // RGB
    kMultiple = 14,   // RGB
    kSurface = 17,    // RGB
    kBackground = 20, // RGB
    kSlots = 23,
};

/// Film layers of the accumulated slots, in film order.
struct LayerSlot {
    const char* name;
    std::size_t slot;
    int channels;
};
constexpr std::array<LayerSlot, 9> kLayers{{
    {"", kBeauty, 3},
    {"A", kAlpha, 1},
    {"hair.A", kHairAlpha, 1},
    {"direct_R", kDirectR, 3},
    {"direct_TT", kDirectTT, 3},
    {"direct_TRT", kDirectTRT, 3},
    {"multiple", kMultiple, 3},
    {"surface", kSurface, 3},
    {"background", kBackground, 3},
}};
constexpr const char* kHalfLayer = "half_a";
constexpr const char* kHairHalfLayer = "hair_half_a";

/// Per pixel: the sums of the slots over its samples, and over the samples of
/// half A the sums of the beauty and of the hair's radiance (direct + multiple).
struct PixelSums {
    std::array<double, kSlots> sum{};
    std::array<double, 3> beautyA{}, hairA{};
};

struct Sample {
    std::array<float, kSlots> v{};

    void add(std::size_t slot, const Rgb& c) {
        v[slot] += c.r;
        v[slot + 1] += c.g;
        v[slot + 2] += c.b;
    }
    Rgb rgb(std::size_t slot) const { return {v[slot], v[slot + 1], v[slot + 2]}; }
    Rgb hair() const {
        return rgb(kDirectR) + rgb(kDirectTT) + rgb(kDirectTRT) + rgb(kMultiple);
    }
};

struct Counters {
    std::uint64_t paths = 0, rays = 0, shadowRays = 0, events = 0, atCap = 0;
    std::uint64_t environmentShadowRays = 0, escaped = 0;
    std::uint32_t deepest = 0;
    double energyAtCap = 0;
};

class Tracer {
public:
    Tracer(const PathTraceScene& scene, const PathTraceSettings& settings)
        : scene_(scene), settings_(settings), camera_(scene.camera),
          bcsdfs_(scene.fibers.begin(), scene.fibers.end()),
          rays_(*scene.groom, scene.fiberScale, scene.surfaces),
          slack_(2.0f * maxRibbonWidth(*scene.groom, scene.fiberScale)) {
        for (const Light& l : scene.lights)
            if (!l.isDark())
                lights_.push_back(l);
        if (scene.environment && scene.environment->maxLuminance() > 0)
            env_ = scene.environment.get();
    }

    /// Sample `index` of pixel (x, y): samples 2j and 2j + 1 are the j-th of
    /// halves A and B, two independent randomizations of one sequence.
    Sample trace(int x, int y, std::uint32_t index, Counters& counters) const {
        const std::size_t pixel = std::size_t(y) * std::size_t(camera_.width()) + std::size_t(x);
        // Every uniform from a padded Owen-scrambled Sobol sampler (core/sobol.h):
        // sample j of a half is the j-th point of each pair of dimensions'
        // (0,2)-sequence, the pixel position first; the halves' randomizations
        // are independent.
        const std::uint32_t half = index & 1u;
        SobolSampler sampler(Hasher().value(settings_.seed).value(pixel).value(half).digest(),
                             index >> 1);
        Sample out;
        const Vec2f raster = Vec2f(float(x), float(y)) + sampler.next2D();
        const Vec3f dirCam = camera_.rayDirection(raster);
        Vec3f dir = camera_.toWorldDirection(dirCam);
        // Geometry nearer than the near plane is clipped, as in the rasterizer.
        Vec3f origin = camera_.position() + (camera_.nearClip() / dirCam.z) * dir;

        ++counters.paths;
        Rgb throughput(1.0f);
        bool firstOnHair = false;
        std::optional<RayOrigin> from;
        std::uint32_t events = 0;
        // Of the last continuation: the density it was drawn with and, at
        // depth 1 on a fiber, each lobe's share of its weight f_p·cos/pdf
        // (per channel: the throughput then carries roulette's factor too).
        float continuationPdf = 0;
        LobeValues firstShare;
        // The continuation escaped: the map's light, weighted against light
        // sampling's density of the same direction.
        const auto escaped = [&] {
            ++counters.escaped;
            const Rgb L = env_->radiance(dir) * powerHeuristic(continuationPdf, env_->pdf(dir));
            if (firstOnHair && events == 1) {
                out.add(kDirectR, throughput * L * firstShare.R);
                out.add(kDirectTT, throughput * L * firstShare.TT);
                out.add(kDirectTRT, throughput * L * firstShare.TRT);
            } else {
                out.add(firstOnHair ? kMultiple : kSurface, throughput * L);
            }
        };
        for (;;) {
            ++counters.rays;
            const std::optional<RayHit> hit = rays_.intersect(
                origin, dir, std::numeric_limits<float>::infinity(), from ? &*from : nullptr);
            if (!hit) {
                if (events == 0) {
                    out.add(kBackground, scene_.environment && scene_.environmentVisible
                                             ? scene_.environment->backdrop(dir)
                                             : scene_.background);
                } else if (env_) {
                    escaped();
                }
                break;
            }
            const Vec3f xHit = origin + hit->t * dir;
            const Vec3f wo = -dir;
            if (events == 0) {
                firstOnHair = hit->kind == RayHit::Kind::Fiber;
                out.v[kAlpha] = 1.0f;
                out.v[kHairAlpha] = firstOnHair ? 1.0f : 0.0f;
            }
            // Where this vertex's light goes: depth 1 on hair by lobe, deeper
            // paths on hair to `multiple`, paths that began on a surface to `surface`.
            const std::size_t deeper = firstOnHair ? kMultiple : kSurface;
            ++events;
            ++counters.events;
            if (hit->kind == RayHit::Kind::Fiber) {
                const Vec3f& u = hit->tangent;
                const RayOrigin here{hit->fiber, slack_};
                const MarschnerBcsdf& bcsdf = bcsdfs_[fiberTypeAt(
                    *scene_.groom, segmentStartPoint(hit->fiber.strand, hit->fiber.segment))];
                // Light e scattered toward the camera by lobes f: by lobe at depth 1.
                const auto addScattered = [&](const Rgb& e, const LobeValues& f) {
                    if (events == 1) {
                        out.add(kDirectR, e * f.R);
                        out.add(kDirectTT, e * f.TT);
                        out.add(kDirectTRT, e * f.TRT);
                    } else {
                        out.add(deeper, e * f.sum());
                    }
                };
                for (const Light& light : lights_) {
                    const Light::Path path = light.pathFrom(xHit);
                    if (!(path.distance > 0))
                        continue;
                    const FiberAngles a = FiberAngles::fromDirections(path.omega, wo, u);
                    if (!(a.cosTheta_i > 0))
                        continue;
                    ++counters.shadowRays;
                    if (rays_.occluded(xHit, path.omega, path.distance, &here))
                        continue;
                    addScattered(throughput * light.irradiance(path.distance) * a.cosTheta_i,
                                 bcsdf.eval(a));
                }
                if (env_) {
                    // A direction from the map, weighted against f_s sampling's density.
                    const Vec2f ue = sampler.next2D();
                    const EnvironmentSample es = env_->sample(ue.x, ue.y);
                    const FiberAngles a = FiberAngles::fromDirections(es.omega, wo, u);
                    if (es.pdf > 0 && !es.radiance.isBlack() && a.cosTheta_i > 0) {
                        ++counters.shadowRays;
                        ++counters.environmentShadowRays;
                        if (!rays_.occluded(xHit, es.omega, std::numeric_limits<float>::infinity(),
                                            &here)) {
                            const float w = powerHeuristic(es.pdf, bcsdf.pdf(a)) / es.pdf;
                            addScattered(throughput * es.radiance * (a.cosTheta_i * w),
                                         bcsdf.eval(a));
                        }
                    }
                }
                const Vec2f u01 = sampler.next2D(), u23 = sampler.next2D();
                const BcsdfSample s = bcsdf.sample(wo, u, {u01.x, u01.y, u23.x, u23.y});
                if (!s.valid())
                    break;
                continuationPdf = s.pdf;
                if (events == 1) {
                    const float cosTheta_i = cosFromSin(std::clamp(glm::dot(s.wi, u), -1.0f, 1.0f));
                    for (const Lobe p : kLobes)
                        for (int c = 0; c < 3; ++c)
                            firstShare[p][c] = s.weight[c] > 0
                                                   ? s.f[p][c] * (cosTheta_i / s.pdf) / s.weight[c]
                                                   : 0.0f;
                }
                throughput *= s.weight;
                origin = xHit;
                dir = s.wi;
                from = here;
            } else {
                // Two-sided: both normals face wo (SurfaceHit); light and
                // continuation stay on the geometric normal's side.
                const Rgb albedo = scene_.surfaceAlbedo[hit->surface];
                const Vec3f& n = hit->normal;
                const Vec3f& ng = hit->geometricNormal;
                const Vec3f xOff = xHit + surfaceOffset(xHit) * ng;
                const Rgb brdf = float(InvPi) * albedo;
                for (const Light& light : lights_) {
                    const Light::Path path = light.pathFrom(xOff);
                    const float cosTheta = glm::dot(n, path.omega);
                    if (!(cosTheta > 0) || !(glm::dot(ng, path.omega) > 0) || !(path.distance > 0))
                        continue;
                    ++counters.shadowRays;
                    if (rays_.occluded(xOff, path.omega, path.distance))
                        continue;
                    out.add(deeper, throughput * brdf * light.irradiance(path.distance) * cosTheta);
                }
                if (env_) {
                    // A direction from the map, weighted against cosine sampling's density.
                    const Vec2f ue = sampler.next2D();
                    const EnvironmentSample es = env_->sample(ue.x, ue.y);
                    const float cosTheta = glm::dot(n, es.omega);
                    if (es.pdf > 0 && !es.radiance.isBlack() && cosTheta > 0 &&
                        glm::dot(ng, es.omega) > 0) {
                        ++counters.shadowRays;
                        ++counters.environmentShadowRays;
                        if (!rays_.occluded(xOff, es.omega, std::numeric_limits<float>::infinity()))
                            out.add(deeper,
                                    throughput * brdf * es.radiance *
                                        (cosTheta *
                                         powerHeuristic(es.pdf, cosTheta * float(InvPi)) / es.pdf));
                    }
                }
                throughput *= albedo;
                origin = xOff;
                const Vec2f uc = sampler.next2D();
                dir = cosineHemisphere(n, uc.x, uc.y);
                if (!(glm::dot(dir, ng) > 0))
                    break; // below the surface: the shading normal's lobe dips under it
                continuationPdf = glm::dot(n, dir) * float(InvPi);
                from.reset();
            }
            if (throughput.isBlack())
                break;
            if (events >= settings_.maxDepth) {
                ++counters.atCap;
                counters.energyAtCap += double(throughput.average());
                // The environment seen by this last continuation is light of
                // this path's depth, the other half of its sample's MIS weight.
                if (env_) {
                    ++counters.rays;
                    if (!rays_.intersect(origin, dir, std::numeric_limits<float>::infinity(),
                                         from ? &*from : nullptr))
                        escaped();
                }
                break;
            }
            if (events >= settings_.rouletteDepth) {
                const float q = std::min(1.0f, throughput.maxComponent());
                if (sampler.next1D() >= q)
                    break;
                throughput /= q;
            }
        }
        counters.deepest = std::max(counters.deepest, events);
        const Rgb beauty = out.rgb(kBackground) + out.rgb(kSurface) + out.hair();
        out.add(kBeauty, beauty);
        return out;
    }

    const Camera& camera() const { return camera_; }

private:
    const PathTraceScene& scene_;
    const PathTraceSettings& settings_;
    Camera camera_;
    std::vector<MarschnerBcsdf> bcsdfs_; ///< per fiber type
    RayScene rays_;
    float slack_;
    std::vector<Light> lights_;
    const EnvironmentMap* env_ = nullptr; ///< null: no environment light
};

/// The sums a film of this function's layers held after `spp` samples (even:
/// half of them in half A).
void restoreSums(const Film& film, std::uint32_t spp, std::vector<PixelSums>& sums) {
    for (const LayerSlot& l : kLayers)
        if (!film.find(l.name))
            throw InputError(strCat("the path-traced image to continue has no layer '", l.name, "'"));
    for (const char* name : {kHalfLayer, kHairHalfLayer})
        if (!film.find(name))
            throw InputError(strCat("the path-traced image to continue has no layer '", name, "'"));
    const double n = spp, nA = spp / 2;
    const FilmLayer& half = film.layer(kHalfLayer);
    const FilmLayer& hairHalf = film.layer(kHairHalfLayer);
    for (std::size_t p = 0; p < sums.size(); ++p) {
        PixelSums& s = sums[p];
        for (const LayerSlot& l : kLayers) {
            const FilmLayer& layer = film.layer(l.name);
            for (int c = 0; c < l.channels; ++c)
                s.sum[l.slot + std::size_t(c)] = n * double(layer.value(p, c));
        }
        for (std::size_t c = 0; c < 3; ++c) {
            s.beautyA[c] = nA * double(half.value(p, int(c)));
            s.hairA[c] = nA * double(hairHalf.value(p, int(c)));
        }
    }
}

Film filmOf(int width, int height, const std::vector<PixelSums>& sums, std::uint32_t spp) {
    Film film(width, height);
    for (const LayerSlot& l : kLayers)
        film.addLayer(l.name, l.channels, /*fullPrecision=*/true);
    film.addLayer(kHalfLayer, 3, true);
    film.addLayer(kHairHalfLayer, 3, true);
    if (spp == 0)
        return film;
    const double n = spp, nA = spp / 2;
    std::vector<FilmLayer*> layers;
    for (const LayerSlot& l : kLayers)
        layers.push_back(&film.layer(l.name));
    FilmLayer& half = film.layer(kHalfLayer);
    FilmLayer& hairHalf = film.layer(kHairHalfLayer);
    for (std::size_t p = 0; p < sums.size(); ++p) {
        const PixelSums& s = sums[p];
        for (std::size_t i = 0; i < kLayers.size(); ++i) {
            const auto channels = static_cast<std::size_t>(kLayers[i].channels);
            for (std::size_t c = 0; c < channels; ++c)
                layers[i]->at(p, int(c)) = static_cast<float>(s.sum[kLayers[i].slot + c] / n);
        }
        for (std::size_t c = 0; c < 3; ++c) {
            half.at(p, int(c)) = static_cast<float>(s.beautyA[c] / nA);
            hairHalf.at(p, int(c)) = static_cast<float>(s.hairA[c] / nA);
        }
    }
    return film;
}

} // namespace

PathTraceOutput pathTrace(const PathTraceScene& scene, const PathTraceSettings& settings,
                          const Film* previous, std::uint32_t previousSpp) {
    const Clock::time_point start = Clock::now();
    settings.validate();
    if (!scene.groom)
        throw std::invalid_argument("pathTrace: no groom");
    if (scene.surfaceAlbedo.size() != (scene.surfaces ? scene.surfaces->surfaceCount() : 0))
        throw std::invalid_argument("pathTrace: one albedo per surface is needed");
    if (scene.fibers.size() < fiberTypeCount(*scene.groom))
        throw std::invalid_argument("pathTrace: one fiber per fiber type of the groom is needed");
    scene.fiberScale.validate();
    const ThreadLimit threadLimit(settings.threads);
    const Tracer tracer(scene, settings);
    const Camera& camera = tracer.camera();
    const int width = camera.width(), height = camera.height();
    const std::size_t pixels = std::size_t(width) * std::size_t(height);

    std::vector<PixelSums> sums(pixels);
    std::uint32_t spp = 0;
    if (previous && previousSpp > 0) {
        if (previousSpp % 2 != 0)
            throw InputError(strCat("the path-traced image to continue has ", previousSpp,
                                    " samples per pixel; runs take them in pairs"));
        if (previous->width() != width || previous->height() != height)
            throw InputError(strCat("the path-traced image to continue is ", previous->width(), " x ",
                                    previous->height(), ", the camera ", width, " x ", height));
        restoreSums(*previous, previousSpp, sums);
        spp = previousSpp;
    }

    PathTraceOutput out;
    PathTraceStats& st = out.stats;
    tbb::enumerable_thread_specific<Counters> counters;
    // Passes of two samples per pixel, one in each half.
    std::vector<std::array<Sample, 2>> pass(pixels);
    const std::uint32_t target = std::max(settings.spp + (settings.spp & 1u), spp);
    ProgressReporter progress("path trace", (target - spp) / 2, settings.progress);
    if (settings.timeLimit > 0)
        progress.limitTime(settings.timeLimit);
    constexpr int kRowsPerTask = 4;
    while (spp < target) {
        // The time limit ends the run between passes, after the first: an image
        // of no samples would be of no use.
        if (settings.timeLimit > 0 && st.sppThisRun > 0 &&
            std::chrono::duration<double>(Clock::now() - start).count() >= settings.timeLimit) {
            st.timeLimited = true;
            break;
        }
        try {
            tbb::parallel_for(
                tbb::blocked_range<int>(0, height, kRowsPerTask),
                [&](const tbb::blocked_range<int>& rows) {
                    throwIfInterrupted();
                    flushDenormalsToZero();
                    Counters& c = counters.local();
                    for (int y = rows.begin(); y != rows.end(); ++y)
                        for (int x = 0; x < width; ++x) {
                            auto& samples = pass[std::size_t(y) * std::size_t(width) + std::size_t(x)];
                            samples[0] = tracer.trace(x, y, spp, c);
                            samples[1] = tracer.trace(x, y, spp + 1, c);
                        }
                });
        } catch (const Interrupted&) {
            st.interrupted = true; // the pass is incomplete: dropped
            break;
        }
        tbb::parallel_for(std::size_t(0), pixels, [&](std::size_t p) {
            PixelSums& s = sums[p];
            for (const Sample& v : pass[p])
                for (std::size_t k = 0; k < kSlots; ++k)
                    s.sum[k] += double(v.v[k]);
            const Sample& a = pass[p][0];
            const Rgb beauty = a.rgb(kBeauty), hair = a.hair();
            for (int c = 0; c < 3; ++c) {
                s.beautyA[std::size_t(c)] += double(beauty[c]);
                s.hairA[std::size_t(c)] += double(hair[c]);
            }
        });
        spp += 2;
        st.sppThisRun += 2;
        progress.update();
    }
    progress.finish();

    st.spp = spp;
    for (const Counters& c : counters) {
        st.paths += c.paths;
        st.rays += c.rays;
        st.shadowRays += c.shadowRays;
        st.environmentShadowRays += c.environmentShadowRays;
        st.escapedRays += c.escaped;
        st.scatteringEvents += c.events;
        st.pathsAtDepthCap += c.atCap;
        st.energyAtDepthCap += c.energyAtCap;
        st.deepestPath = std::max(st.deepestPath, c.deepest);
    }
    if (st.paths > 0)
        st.energyAtDepthCap /= double(st.paths);
    out.film = filmOf(width, height, sums, spp);
    st.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return out;
}

} // namespace hairvox
