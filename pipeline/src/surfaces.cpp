#include "surfaces.h"

#include <hairvox/core/math.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace hairvox::detail {

namespace {

constexpr int kSilhouetteSamples = 8; ///< per side, on the head's silhouette

/// The head seen from the camera: which pixels it covers, its depth and its
/// Lambertian radiance.
class HeadView {
public:
    HeadView(const Head& head, const Camera& camera, const std::vector<Light>& lights)
        : head_(head)
        , camera_(camera)
        , lights_(lights) {
        const Vec3f center = camera.directionToCamera(head.sphere.center - camera.position());
        axis_ = glm::normalize(center);
        // A pixel spans at most 1/f radians, so pixel centres farther than that
        // from the silhouette cone are wholly inside or outside it.
        const float psi = safeASin(head.sphere.radius / glm::length(center));
        const float pixel = 1.0f / camera.focalLength();
        cosInner_ = std::cos(std::max(psi - pixel, 0.0f));
        cosOuter_ = std::cos(std::min(psi + pixel, float(Pi)));
    }

    /// Coverage, mean depth and mean radiance of the head in pixel (x, y).
    bool cover(int x, int y, float& coverage, float& depth, Rgb& radiance) const {
        const Vec2f centre(float(x) + 0.5f, float(y) + 0.5f);
        const float cosPsi = glm::dot(camera_.rayDirection(centre), axis_);
        if (cosPsi <= cosOuter_)
            return false;
        if (cosPsi >= cosInner_) {
            coverage = 1.0f;
            return sample(centre, depth, radiance);
        }
        int hits = 0;
        double depthSum = 0;
        Rgb radianceSum(0.0f);
        for (int j = 0; j < kSilhouetteSamples; ++j)
            for (int i = 0; i < kSilhouetteSamples; ++i) {
                const Vec2f p(float(x) + (float(i) + 0.5f) / kSilhouetteSamples,
                              float(y) + (float(j) + 0.5f) / kSilhouetteSamples);
                float z;
                Rgb l;
                if (sample(p, z, l)) {
                    ++hits;
                    depthSum += double(z);
                    radianceSum += l;
                }
            }
        if (hits == 0)
            return false;
        coverage = float(hits) / float(kSilhouetteSamples * kSilhouetteSamples);
        depth = static_cast<float>(depthSum / hits);
        radiance = radianceSum / float(hits);
        return true;
    }

private:
    bool sample(const Vec2f& raster, float& depth, Rgb& radiance) const {
        const Vec3f dirCam = camera_.rayDirection(raster);
        const Vec3f dir = camera_.toWorldDirection(dirCam);
        const float t =
            head_.sphere.intersect(camera_.position(), dir, std::numeric_limits<float>::infinity());
        if (!(t > 0))
            return false; // missed, or the head is behind the camera
        depth = t * dirCam.z;
        const Vec3f x = camera_.position() + t * dir;
        const Vec3f normal = normalizeOr(x - head_.sphere.center, -dir);
        Rgb irradiance(0.0f);
        for (const Light& light : lights_) {
            const Light::Path path = light.pathFrom(x);
            const float cosTheta = glm::dot(normal, path.omega);
            if (cosTheta > 0)
                irradiance += cosTheta * light.irradiance(path.distance);
        }
        radiance = float(InvPi) * head_.albedo * irradiance;
        return true;
    }

    const Head& head_;
    const Camera& camera_;
    const std::vector<Light>& lights_;
    Vec3f axis_;
    float cosInner_, cosOuter_;
};

} // namespace

SurfaceLayer headSurfaceLayer(const Head& head, const Camera& camera,
                              const std::vector<Light>& lights) {
    const HeadView view(head, camera, lights);
    const std::size_t pixels = std::size_t(camera.width()) * std::size_t(camera.height());
    SurfaceLayer layer;
    layer.coverage.assign(pixels, 0.0f);
    layer.depth.assign(pixels, 0.0f);
    layer.radiance.assign(pixels, Rgb(0.0f));
    tbb::parallel_for(0, camera.height(), [&](int y) {
        for (int x = 0; x < camera.width(); ++x) {
            const std::size_t p = std::size_t(y) * std::size_t(camera.width()) + std::size_t(x);
            if (!view.cover(x, y, layer.coverage[p], layer.depth[p], layer.radiance[p]))
                layer.coverage[p] = 0.0f;
        }
    });
    return layer;
}

} // namespace hairvox::detail
