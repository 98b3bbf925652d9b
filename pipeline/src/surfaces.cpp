#include "surfaces.h"

#include <hairvox/core/interrupt.h>
#include <hairvox/core/large_array.h>
#include <hairvox/core/math.h>
#include <hairvox/core/thread_scratch.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>

namespace hairvox::detail {

namespace {

constexpr int kEdgeSamples = 8; ///< per side, in a silhouette or depth-edge pixel
constexpr int kQuadrant = kEdgeSamples / 2;
constexpr auto kQuadrantSamples = std::size_t(kQuadrant * kQuadrant);
constexpr float kSmoothDepthRatio = 1.02f; ///< corners this close in depth: one smooth surface
constexpr std::uint32_t kMiss = std::numeric_limits<std::uint32_t>::max();
/// Rows shaded together (a task of the layer's loop).
constexpr int kBandRows = 4;
/// Points whose global term is evaluated together (per light).
constexpr std::size_t kBatch = 1024;

/// Where the camera ray through a raster position meets the surfaces
/// (castViews() sets every member).
struct ViewSample {
    std::uint32_t surface; ///< kMiss where the ray met nothing
    float depth;           ///< camera-space z
    Vec3f position;
    Vec3f normal; ///< shading, facing the camera
    Vec3f geometricNormal;
};

/// The camera rays through `rasters`, traced together (SurfaceScene's stream
/// of coherent rays: a row of pixels, a pixel's sub-samples), into `out`.
void castViews(const SurfaceScene& surfaces, const Camera& camera, std::span<const Vec2f> rasters,
               std::span<ViewSample> out) {
    struct Scratch {
        std::vector<Vec3f> origins, dirs;
        std::vector<float> tNear, dirZ; ///< from the camera to the origin; dir's camera-space z
        std::vector<std::optional<SurfaceHit>> hits;
    };
    ThreadScratch<Scratch> scratch;
    auto& [origins, dirs, tNear, dirZ, hits] = *scratch;
    const std::size_t n = rasters.size();
    origins.resize(n); // every element of these written below
    dirs.resize(n);
    tNear.resize(n);
    dirZ.resize(n);
    hits.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3f dirCam = camera.rayDirection(rasters[i]);
        dirs[i] = camera.toWorldDirection(dirCam);
        // Geometry nearer than the near plane is clipped, as for the hair.
        tNear[i] = camera.nearClip() / dirCam.z;
        dirZ[i] = dirCam.z;
        origins[i] = camera.position() + tNear[i] * dirs[i];
    }
    surfaces.intersect(origins, dirs, std::numeric_limits<float>::infinity(), hits);
    for (std::size_t i = 0; i < n; ++i) {
        ViewSample& s = out[i];
        s = {kMiss, 0.0f, Vec3f(0.0f), Vec3f(0.0f), Vec3f(0.0f)};
        if (const std::optional<SurfaceHit>& hit = hits[i]) {
            s.surface = hit->surface;
            s.depth = (tNear[i] + hit->t) * dirZ[i];
            s.position = origins[i] + hit->t * dirs[i];
            s.normal = hit->normal;
            s.geometricNormal = hit->geometricNormal;
        }
    }
}

/// Raster positions and what the camera rays through them meet: a
/// function's per-thread storage for one stream of rays.
struct ViewRays {
    std::vector<Vec2f> rasters;
    std::vector<ViewSample> views; ///< per raster position, once cast

    /// The rays through `rasters`, traced as one stream, into `views`.
    void cast(const SurfaceScene& surfaces, const Camera& camera) {
        views.resize(rasters.size());
        castViews(surfaces, camera, rasters, views);
    }
};

/// What a pixel-corner ray met (8 bytes: one per pixel of the image). No
/// member initialisers: a LargeVector of them is left unwritten until
/// the rays fill it.
struct CornerHit {
    std::uint32_t surface;
    float depth;
};

/// A point to shade and the share of its pixel's surface radiance it stands for.
struct ShadingSample {
    std::size_t pixel;
    float weight;
    ViewSample view;
};

/// What a row's coverage reads: the surfaces, the camera, and the rays
/// through the pixel corners (row y's corner x at corners[y · cornerRow + x]).
struct ViewCorners {
    const SurfaceScene& surfaces;
    const Camera& camera;
    const LargeVector<CornerHit>& corners;
    std::size_t cornerRow;

    /// Pixel (x, y)'s corners: top left, top right, bottom left, bottom right.
    std::array<const CornerHit*, 4> of(int x, int y) const {
        const std::size_t c = std::size_t(y) * cornerRow + std::size_t(x);
        return {&corners[c], &corners[c + 1], &corners[c + cornerRow], &corners[c + cornerRow + 1]};
    }
};

/// A silhouette or depth-edge pixel p = (x, y): 8×8 samples (one stream),
/// one shaded per 4×4 quadrant and weighted by its share of the pixel's hits;
/// its coverage and mean depth into `layer` (left 0 where no sample hits).
void coverEdgePixel(const ViewCorners& view, int x, int y, std::size_t p, SurfaceLayer& layer,
                    std::vector<ShadingSample>& samples) {
    ThreadScratch<ViewRays> scratch;
    auto& [rasters, views] = *scratch;
    rasters.clear();
    for (int qy = 0; qy < 2; ++qy)
        for (int qx = 0; qx < 2; ++qx)
            for (int j = qy * kQuadrant; j < (qy + 1) * kQuadrant; ++j)
                for (int i = qx * kQuadrant; i < (qx + 1) * kQuadrant; ++i)
                    rasters.emplace_back(float(x) + (float(i) + 0.5f) / kEdgeSamples,
                                         float(y) + (float(j) + 0.5f) / kEdgeSamples);
    scratch->cast(view.surfaces, view.camera);
    int covered = 0;
    double depthSum = 0;
    const std::size_t firstShaded = samples.size();
    for (std::size_t q = 0; q < 4; ++q) {
        int quadrantHits = 0;
        ViewSample shaded{};
        for (std::size_t k = 0; k < kQuadrantSamples; ++k) {
            const ViewSample& s = views[q * kQuadrantSamples + k];
            if (s.surface == kMiss)
                continue;
            if (quadrantHits++ == 0)
                shaded = s;
            depthSum += double(s.depth);
        }
        covered += quadrantHits;
        if (quadrantHits > 0)
            samples.push_back({p, float(quadrantHits), shaded});
    }
    if (covered == 0)
        return;
    layer.coverage[p] = float(covered) / float(kEdgeSamples * kEdgeSamples);
    layer.depth[p] = static_cast<float>(depthSum / covered);
    for (std::size_t k = firstShaded; k < samples.size(); ++k)
        samples[k].weight /= float(covered);
}

/// Row y's coverage and depth per pixel into `layer`, and its points to
/// shade appended to `samples` in pixel order. A pixel whose four corners
/// meet one surface at about one depth, and whose centre does too, is
/// covered and shaded at its centre (the row's centres cast as one stream);
/// one with any corner on a surface otherwise is an edge pixel.
void coverRow(const ViewCorners& view, int y, SurfaceLayer& layer,
              std::vector<ShadingSample>& samples) {
    // (Its own type: this storage is in use while coverEdgePixel() takes
    // a ViewRays of the thread's.)
    struct Scratch {
        std::vector<std::uint8_t> smooth; ///< per pixel: its centre is cast
        ViewRays centres;
    };
    ThreadScratch<Scratch> scratch;
    auto& [smooth, centres] = *scratch;
    std::vector<Vec2f>& rasters = centres.rasters;
    const int width = view.camera.width();
    smooth.assign(std::size_t(width), 0);
    rasters.clear();
    for (int x = 0; x < width; ++x) {
        const auto c = view.of(x, y);
        bool oneSurface = c[0]->surface != kMiss;
        float zMin = std::numeric_limits<float>::infinity(), zMax = 0;
        for (const CornerHit* h : c) {
            oneSurface = oneSurface && h->surface == c[0]->surface;
            zMin = std::min(zMin, h->depth);
            zMax = std::max(zMax, h->depth);
        }
        if (oneSurface && zMax <= kSmoothDepthRatio * zMin) {
            smooth[std::size_t(x)] = 1;
            rasters.emplace_back(float(x) + 0.5f, float(y) + 0.5f);
        }
    }
    centres.cast(view.surfaces, view.camera);
    std::size_t centre = 0;
    for (int x = 0; x < width; ++x) {
        const std::size_t p = std::size_t(y) * std::size_t(width) + std::size_t(x);
        const auto c = view.of(x, y);
        layer.coverage[p] = 0.0f;
        layer.depth[p] = 0.0f;
        if (smooth[std::size_t(x)]) {
            const ViewSample& v = centres.views[centre++];
            if (v.surface == c[0]->surface) {
                layer.coverage[p] = 1.0f;
                layer.depth[p] = v.depth;
                samples.push_back({p, 1.0f, v});
                continue;
            }
        } else if (std::none_of(c.begin(), c.end(),
                                [](const CornerHit* h) { return h->surface != kMiss; })) {
            continue;
        }
        coverEdgePixel(view, x, y, p, layer, samples);
    }
}

/// Each sample's Lambertian radiance lit through the hair (surfaces.h),
/// summed over the lights in order, into `radiance`; the global term is
/// evaluated kBatch samples at a time per light.
void lightSamples(const SurfaceScene& surfaces, std::span<const ShadingSample> samples,
                  const std::vector<Rgb>& albedo, const std::vector<Light>& lights,
                  const std::vector<const LightGlobalTerm*>& terms,
                  const SurfaceEnvironment* environment, const SurfaceIrradiance* scattered,
                  std::vector<Rgb>& radiance) {
    struct Scratch {
        std::vector<GlobalTermQuery> queries;
        std::vector<std::size_t> which; ///< per query: its sample
        std::vector<float> cosines;     ///< per query
        std::vector<GlobalTerm> terms;  ///< per query
        // The environment's: per query its region's light and the surfaces' shadow ray.
        std::vector<RegionIrradiance::Value> light;
        std::vector<Vec3f> origins, dirs;
        std::vector<float> tMax;
        std::vector<std::uint8_t> blocked;
    };
    ThreadScratch<Scratch> scratch;
    auto& [queries, which, cosines, g, regionLight, origins, dirs, tMax, blocked] = *scratch;
    radiance.assign(samples.size(), Rgb(0.0f));
    for (std::size_t l = 0; l < lights.size(); ++l) {
        if (!terms[l])
            continue;
        const Light& light = lights[l];
        for (std::size_t begin = 0; begin < samples.size(); begin += kBatch) {
            const std::size_t end = std::min(samples.size(), begin + kBatch);
            queries.clear();
            which.clear();
            cosines.clear();
            for (std::size_t i = begin; i != end; ++i) {
                const ViewSample& v = samples[i].view;
                const Vec3f x = v.position + surfaceOffset(v.position) * v.geometricNormal;
                const Light::Path path = light.pathFrom(x);
                const float cosTheta = glm::dot(v.normal, path.omega);
                if (!(cosTheta > 0) || !(glm::dot(v.geometricNormal, path.omega) > 0))
                    continue;
                Vec3f across, unused;
                coordinateSystem(path.omega, across, unused);
                GlobalTermQuery q{x, across};
                q.onFiber = false;
                queries.push_back(q);
                which.push_back(i);
                cosines.push_back(cosTheta);
            }
            g.resize(queries.size()); // every element written by evaluate
            terms[l]->evaluate(queries, g);
            for (std::size_t k = 0; k < queries.size(); ++k) {
                const std::size_t i = which[k];
                const float distance = light.pathFrom(queries[k].position).distance;
                const Rgb through = scattered ? Rgb(g[k].V) : Rgb(g[k].V) + g[k].T_s;
                radiance[i] += float(InvPi) * albedo[samples[i].view.surface] *
                               light.irradiance(distance) * cosines[k] * through;
            }
        }
    }
    if (scattered)
        for (std::size_t i = 0; i < samples.size(); ++i) {
            const ViewSample& v = samples[i].view;
            radiance[i] += float(InvPi) * albedo[v.surface] * scattered->irradiance(v.position);
        }
    if (!environment)
        return;
    for (std::size_t r = 0; r < environment->terms.size(); ++r) {
        if (!environment->terms[r])
            continue;
        Vec3f across, unused;
        coordinateSystem(environment->lights[r].direction, across, unused);
        for (std::size_t begin = 0; begin < samples.size(); begin += kBatch) {
            const std::size_t end = std::min(samples.size(), begin + kBatch);
            queries.clear();
            which.clear();
            regionLight.clear();
            origins.clear();
            dirs.clear();
            for (std::size_t i = begin; i != end; ++i) {
                const ViewSample& v = samples[i].view;
                const RegionIrradiance::Value e = environment->irradiance->at(r, v.normal);
                if (e.irradiance.isBlack() || !(glm::dot(v.geometricNormal, e.direction) > 0))
                    continue;
                const Vec3f x = v.position + surfaceOffset(v.position) * v.geometricNormal;
                GlobalTermQuery q{x, across};
                q.onFiber = false;
                queries.push_back(q);
                which.push_back(i);
                regionLight.push_back(e);
                origins.push_back(x);
                dirs.push_back(e.direction);
            }
            g.resize(queries.size()); // every element written by evaluate
            environment->terms[r]->evaluate(queries, g);
            tMax.assign(queries.size(), std::numeric_limits<float>::infinity());
            blocked.resize(queries.size()); // every element written by occluded
            surfaces.occluded(origins, dirs, tMax, blocked, SurfaceScene::RayCoherence::Incoherent);
            for (std::size_t k = 0; k < queries.size(); ++k)
                if (!blocked[k])
                    radiance[which[k]] += float(InvPi) * albedo[samples[which[k]].view.surface] *
                                          regionLight[k].irradiance *
                                          (scattered ? Rgb(g[k].V) : Rgb(g[k].V) + g[k].T_s);
        }
    }
}

} // namespace

SurfaceLayer surfaceLayer(const SurfaceScene& surfaces, const std::vector<Rgb>& albedo,
                          const Camera& camera, const std::vector<Light>& lights,
                          const std::vector<const LightGlobalTerm*>& terms,
                          const SurfaceEnvironment* environment,
                          const SurfaceIrradiance* scattered) {
    const int width = camera.width(), height = camera.height();
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    SurfaceLayer layer;
    if (surfaces.empty()) {
        layer.coverage.assign(pixels, 0.0f);
        layer.depth.assign(pixels, 0.0f);
        layer.radiance = LargeBuffer<Rgb>(pixels, Rgb(0.0f));
        return layer;
    }
    // Every pixel is written by the parallel loops below (so that their
    // threads touch the pages first, core/large_array.h).
    layer.coverage.resize(pixels);
    layer.depth.resize(pixels);
    layer.radiance = LargeBuffer<Rgb>(pixels); // zeroed row by row below

    // 1. Visibility at the pixel corners.
    const std::size_t cornerRow = std::size_t(width) + 1;
    LargeVector<CornerHit> corners(cornerRow * (std::size_t(height) + 1));
    tbb::parallel_for(0, height + 1, [&](int y) {
        ThreadScratch<ViewRays> scratch;
        auto& [rasters, views] = *scratch;
        rasters.clear();
        for (int x = 0; x <= width; ++x)
            rasters.emplace_back(float(x), float(y));
        scratch->cast(surfaces, camera);
        for (int x = 0; x <= width; ++x)
            corners[std::size_t(y) * cornerRow + std::size_t(x)] = {views[std::size_t(x)].surface,
                                                                    views[std::size_t(x)].depth};
    });
    throwIfInterrupted();

    // 2. A band of rows a task: coverage and depth per pixel, the points to
    // shade (in pixel order), and their Lambertian radiance lit through the
    // hair, added into their pixels. A band's points live in its thread's
    // arrays only: gathered for the whole image (per row, copied into one
    // array, with a radiance each) they were the layer's largest memory, and
    // on this VM fresh memory is time (docs/DESIGN.md §7).
    const ViewCorners view{surfaces, camera, corners, cornerRow};
    const int bands = (height + kBandRows - 1) / kBandRows;
    tbb::parallel_for(0, bands, [&](int band) {
        throwIfInterrupted();
        struct Scratch {
            std::vector<ShadingSample> samples;
            std::vector<Rgb> radiance; ///< per sample
        };
        ThreadScratch<Scratch> scratch;
        auto& [samples, radiance] = *scratch;
        samples.clear();
        const int yEnd = std::min(height, (band + 1) * kBandRows);
        for (int y = band * kBandRows; y < yEnd; ++y) {
            std::uninitialized_fill_n(layer.radiance.begin() + std::size_t(y) * std::size_t(width),
                                      width, Rgb(0.0f));
            coverRow(view, y, layer, samples);
        }
        lightSamples(surfaces, samples, albedo, lights, terms, environment, scattered, radiance);
        for (std::size_t i = 0; i < samples.size(); ++i)
            layer.radiance[samples[i].pixel] += samples[i].weight * radiance[i];
    });
    throwIfInterrupted();
    return layer;
}

} // namespace hairvox::detail
