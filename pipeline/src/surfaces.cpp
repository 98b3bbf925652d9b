#include "surfaces.h"

#include <hairvox/core/interrupt.h>
#include <hairvox/core/large_array.h>
#include <hairvox/core/math.h>
#include <hairvox/core/thread_scratch.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

namespace hairvox::detail {

namespace {

constexpr int kEdgeSamples = 8;          ///< per side, in a silhouette or depth-edge pixel
constexpr int kQuadrant = kEdgeSamples / 2;
constexpr float kSmoothDepthRatio = 1.02f; ///< corners this close in depth: one smooth surface
constexpr std::uint32_t kMiss = std::numeric_limits<std::uint32_t>::max();
/// Rows shaded together (a task of the layer's loop).
constexpr int kBandRows = 4;
/// Points whose global term is evaluated together (per light).
constexpr std::size_t kBatch = 1024;

/// Where the camera ray through a raster position meets the surfaces
/// (castView() sets every member).
struct ViewSample {
    std::uint32_t surface; ///< kMiss where the ray met nothing
    float depth;           ///< camera-space z
    Vec3f position;
    Vec3f normal;          ///< shading, facing the camera
    Vec3f geometricNormal;
};

ViewSample castView(const SurfaceScene& surfaces, const Camera& camera, const Vec2f& raster) {
    const Vec3f dirCam = camera.rayDirection(raster);
    const Vec3f dir = camera.toWorldDirection(dirCam);
    // Geometry nearer than the near plane is clipped, as for the hair.
    const float tNear = camera.nearClip() / dirCam.z;
    const Vec3f origin = camera.position() + tNear * dir;
    ViewSample s{kMiss, 0.0f, Vec3f(0.0f), Vec3f(0.0f), Vec3f(0.0f)};
    if (const std::optional<SurfaceHit> hit =
            surfaces.intersect(origin, dir, std::numeric_limits<float>::infinity())) {
        s.surface = hit->surface;
        s.depth = (tNear + hit->t) * dirCam.z;
        s.position = origin + hit->t * dir;
        s.normal = hit->normal;
        s.geometricNormal = hit->geometricNormal;
    }
    return s;
}

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

} // namespace

SurfaceLayer surfaceLayer(const SurfaceScene& surfaces, const std::vector<Rgb>& albedo,
                          const Camera& camera, const std::vector<Light>& lights,
                          const std::vector<const LightGlobalTerm*>& terms) {
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
        for (int x = 0; x <= width; ++x) {
            const ViewSample s = castView(surfaces, camera, Vec2f(float(x), float(y)));
            corners[std::size_t(y) * cornerRow + std::size_t(x)] = {s.surface, s.depth};
        }
    });
    throwIfInterrupted();

    // 2. A band of rows a task: coverage and depth per pixel, the points to
    // shade (in pixel order), and their Lambertian radiance lit through the
    // hair, light by light, added into their pixels. A band's points live in
    // its thread's arrays only: gathered for the whole image they were the
    // layer's largest memory (Ratboy at 1280²: ~0.7M points of 64 bytes,
    // held per row, copied into one array, with a radiance each), and on
    // this VM fresh memory is time (docs/DESIGN.md §7).
    const int bands = (height + kBandRows - 1) / kBandRows;
    tbb::parallel_for(0, bands, [&](int band) {
        throwIfInterrupted();
        struct Scratch {
            std::vector<ShadingSample> samples;
            std::vector<Rgb> radiance; ///< per sample
            std::vector<GlobalTermQuery> queries;
            std::vector<std::size_t> which; ///< per query: its sample
            std::vector<float> cosines;     ///< per query
            std::vector<GlobalTerm> terms;  ///< per query
        };
        ThreadScratch<Scratch> scratch;
        auto& [samples, radiance, queries, which, cosines, g] = *scratch;
        samples.clear();
        const int yEnd = std::min(height, (band + 1) * kBandRows);
        for (int y = band * kBandRows; y < yEnd; ++y) {
            std::uninitialized_fill_n(layer.radiance.begin() + std::size_t(y) * std::size_t(width),
                                      width, Rgb(0.0f));
            for (int x = 0; x < width; ++x) {
                const std::size_t p = std::size_t(y) * std::size_t(width) + std::size_t(x);
                const CornerHit* c[4] = {
                    &corners[std::size_t(y) * cornerRow + std::size_t(x)],
                    &corners[std::size_t(y) * cornerRow + std::size_t(x) + 1],
                    &corners[std::size_t(y + 1) * cornerRow + std::size_t(x)],
                    &corners[std::size_t(y + 1) * cornerRow + std::size_t(x) + 1]};
                int hits = 0;
                bool sameSurface = true;
                float zMin = std::numeric_limits<float>::infinity(), zMax = 0;
                for (const CornerHit* s : c) {
                    if (s->surface == kMiss)
                        continue;
                    ++hits;
                    sameSurface = sameSurface && s->surface == c[0]->surface;
                    zMin = std::min(zMin, s->depth);
                    zMax = std::max(zMax, s->depth);
                }
                layer.coverage[p] = 0.0f;
                layer.depth[p] = 0.0f;
                if (hits == 0)
                    continue;
                if (hits == 4 && sameSurface && zMax <= kSmoothDepthRatio * zMin) {
                    const ViewSample centre =
                        castView(surfaces, camera, Vec2f(float(x) + 0.5f, float(y) + 0.5f));
                    if (centre.surface == c[0]->surface) {
                        layer.coverage[p] = 1.0f;
                        layer.depth[p] = centre.depth;
                        samples.push_back({p, 1.0f, centre});
                        continue;
                    }
                }
                // A silhouette or a depth edge: 8×8 samples, one shaded per quadrant.
                int covered = 0;
                double depthSum = 0;
                const std::size_t firstShaded = samples.size();
                for (int qy = 0; qy < 2; ++qy)
                    for (int qx = 0; qx < 2; ++qx) {
                        int quadrantHits = 0;
                        ViewSample shaded{};
                        for (int j = qy * kQuadrant; j < (qy + 1) * kQuadrant; ++j)
                            for (int i = qx * kQuadrant; i < (qx + 1) * kQuadrant; ++i) {
                                const ViewSample s =
                                    castView(surfaces, camera,
                                             Vec2f(float(x) + (float(i) + 0.5f) / kEdgeSamples,
                                                   float(y) + (float(j) + 0.5f) / kEdgeSamples));
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
                    continue;
                layer.coverage[p] = float(covered) / float(kEdgeSamples * kEdgeSamples);
                layer.depth[p] = static_cast<float>(depthSum / covered);
                for (std::size_t k = firstShaded; k < samples.size(); ++k)
                    samples[k].weight /= float(covered);
            }
        }

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
                    radiance[i] += float(InvPi) * albedo[samples[i].view.surface] *
                                   light.irradiance(distance) * cosines[k] *
                                   (Rgb(g[k].V) + g[k].T_s);
                }
            }
        }
        for (std::size_t i = 0; i < samples.size(); ++i)
            layer.radiance[samples[i].pixel] += samples[i].weight * radiance[i];
    });
    throwIfInterrupted();
    return layer;
}

} // namespace hairvox::detail
