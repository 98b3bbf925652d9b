#include "environment_lights.h"

#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/core/thread_scratch.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

namespace hairvox::detail {

namespace {

/// The normal of table node (x, y).
Vec3f nodeNormal(int x, int y) {
    const double theta = Pi * y / (RegionIrradiance::kNormalsY - 1);
    const double phi = TwoPi * x / RegionIrradiance::kNormalsX;
    return {float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
            float(std::sin(theta) * std::sin(phi))};
}

} // namespace

RegionIrradiance::RegionIrradiance(const EnvironmentMap& map,
                                   std::span<const EnvironmentRegion> regions,
                                   std::size_t subdivisions)
    : regions_(regions.size())
    , table_(regions.size() * std::size_t(kNormalsX * kNormalsY)) {
    tbb::parallel_for(std::size_t(0), regions.size(), [&](std::size_t k) {
        const std::vector<EnvironmentRegion> parts =
            map.split(std::max<std::size_t>(subdivisions, 1), EnvironmentSplit::Energy, regions[k]);
        Node* nodes = table_.data() + k * std::size_t(kNormalsX * kNormalsY);
        for (int y = 0; y < kNormalsY; ++y)
            for (int x = 0; x < kNormalsX; ++x) {
                const Vec3f n = nodeNormal(x, y);
                Rgbd irradiance(0.0);
                Vec3d direction(0.0);
                for (const EnvironmentRegion& part : parts) {
                    const float cosine = glm::dot(n, part.direction);
                    if (!(cosine > 0))
                        continue;
                    irradiance += Rgbd(part.irradiance) * double(cosine);
                    direction +=
                        double(part.irradiance.luminance() * cosine) * Vec3d(part.direction);
                }
                nodes[y * kNormalsX + x] = {Rgb(irradiance), Vec3f(direction)};
            }
    });
}

RegionIrradiance::Value RegionIrradiance::at(std::size_t region, const Vec3f& n) const {
    const float theta = safeACos(std::clamp(n.y, -1.0f, 1.0f));
    float phi = std::atan2(n.z, n.x);
    if (phi < 0)
        phi += float(TwoPi);
    const float fx = phi * float(kNormalsX / TwoPi), fy = theta * float((kNormalsY - 1) / Pi);
    const int x0 = std::min(int(fx), kNormalsX - 1), y0 = std::min(int(fy), kNormalsY - 2);
    const int x1 = (x0 + 1) % kNormalsX, y1 = y0 + 1;
    const float tx = std::clamp(fx - float(x0), 0.0f, 1.0f),
                ty = std::clamp(fy - float(y0), 0.0f, 1.0f);
    const Node* nodes = table_.data() + region * std::size_t(kNormalsX * kNormalsY);
    const auto node = [&](int x, int y) -> const Node& {
        return nodes[y * kNormalsX + x];
    };
    const float w00 = (1 - tx) * (1 - ty), w10 = tx * (1 - ty), w01 = (1 - tx) * ty, w11 = tx * ty;
    Value v;
    v.irradiance = w00 * node(x0, y0).irradiance + w10 * node(x1, y0).irradiance +
                   w01 * node(x0, y1).irradiance + w11 * node(x1, y1).irradiance;
    v.direction = normalizeOr(w00 * node(x0, y0).direction + w10 * node(x1, y0).direction +
                                  w01 * node(x0, y1).direction + w11 * node(x1, y1).direction,
                              n);
    return v;
}

EnvironmentLighting environmentLighting(const EnvironmentMap& map, const std::string& name,
                                        std::size_t count, EnvironmentSplit by,
                                        std::size_t subdivisions, std::size_t shadowRays) {
    EnvironmentLighting out;
    out.regions = map.split(count, by);
    for (std::size_t k = 0; k < out.regions.size(); ++k) {
        const EnvironmentRegion& r = out.regions[k];
        Light light = Light::directional(r.direction);
        light.name = strCat(name, ".", k);
        light.color = r.irradiance;
        light.intensity = 1.0f;
        out.lights.push_back(light);
        out.spread2.push_back(r.spread2);
        out.shadowDirections.push_back(
            map.split(std::max<std::size_t>(shadowRays, 1), EnvironmentSplit::Energy, r));
    }
    out.surfaces = RegionIrradiance(map, out.regions, subdivisions);
    return out;
}

RegionSurfaceShadow::RegionSurfaceShadow(std::shared_ptr<const LightGlobalTerm> inner,
                                         std::shared_ptr<const SurfaceScene> surfaces,
                                         std::span<const EnvironmentRegion> directions)
    : inner_(std::move(inner))
    , surfaces_(surfaces && !surfaces->empty() ? std::move(surfaces) : nullptr) {
    double total = 0;
    for (const EnvironmentRegion& d : directions)
        total += double(d.irradiance.luminance());
    for (const EnvironmentRegion& d : directions) {
        directions_.push_back(d.direction);
        weights_.push_back(total > 0 ? float(double(d.irradiance.luminance()) / total)
                                     : 1.0f / float(directions.size()));
    }
}

GlobalTermStats RegionSurfaceShadow::evaluate(std::span<const GlobalTermQuery> queries,
                                              std::span<GlobalTerm> out) const {
    if (!surfaces_ || directions_.empty())
        return inner_->evaluate(queries, out);
    // One segment per query and direction, a direction's tested together;
    // `lit` sums the weights of the directions no surface blocks, `seen`
    // counts them (every element of these arrays is written before it is
    // read).
    struct Scratch {
        std::vector<Vec3f> origins, dirs;
        std::vector<float> tMax, lit;
        std::vector<std::uint8_t> blocked;
        std::vector<std::uint32_t> seen;
        std::vector<GlobalTermQuery> open;
        std::vector<std::size_t> openIndex;
        std::vector<GlobalTerm> openOut;
    };
    ThreadScratch<Scratch> scratch;
    auto& [origins, dirs, tMax, lit, blocked, seen, open, openIndex, openOut] = *scratch;
    const std::size_t n = queries.size();
    origins.resize(n);
    dirs.resize(n);
    blocked.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        origins[i] = queries[i].position;
    tMax.assign(n, std::numeric_limits<float>::infinity());
    lit.assign(n, 0.0f);
    seen.assign(n, 0);
    for (std::size_t d = 0; d < directions_.size(); ++d) {
        std::fill(dirs.begin(), dirs.end(), directions_[d]);
        surfaces_->occluded(origins, dirs, tMax, blocked, SurfaceScene::RayCoherence::Incoherent);
        for (std::size_t i = 0; i < n; ++i)
            if (!blocked[i]) {
                lit[i] += weights_[d];
                ++seen[i];
            }
    }
    const auto all = static_cast<std::uint32_t>(directions_.size());
    GlobalTermStats stats;
    std::uint64_t none = 0;
    if (std::all_of(seen.begin(), seen.end(), [&](std::uint32_t s) { return s == all; })) {
        // The common batch: nothing blocked, nothing to take out or scale.
        stats = inner_->evaluate(queries, out);
    } else {
        open.clear();
        openIndex.clear();
        for (std::size_t i = 0; i < n; ++i) {
            if (seen[i] > 0) {
                open.push_back(queries[i]);
                openIndex.push_back(i);
            } else {
                out[i] = GlobalTerm::blocked();
                ++none;
            }
        }
        openOut.resize(open.size());
        stats = inner_->evaluate(open, openOut);
        for (std::size_t k = 0; k < open.size(); ++k) {
            const std::size_t i = openIndex[k];
            GlobalTerm g = openOut[k];
            if (seen[i] < all) { // a mixture with GlobalTerm::blocked(): V, P, T_s scale
                const float f = std::min(lit[i], 1.0f);
                g.V *= f;
                g.P *= f;
                g.T_s *= f;
            }
            out[i] = g;
        }
    }
    stats.queries = n;
    stats.blockedBySurface += none;
    return stats;
}

BackgroundLayer backgroundLayer(const EnvironmentMap& map, const Camera& camera) {
    BackgroundLayer layer;
    layer.radiance = [&map, &camera](int x, int y) {
        Rgb sum(0.0f);
        for (int k = 0; k < 4; ++k) {
            const Vec2f raster(float(x) + 0.25f + 0.5f * float(k & 1),
                               float(y) + 0.25f + 0.5f * float(k >> 1));
            sum += map.backdrop(camera.toWorldDirection(camera.rayDirection(raster)));
        }
        return 0.25f * sum;
    };
    return layer;
}

} // namespace hairvox::detail
