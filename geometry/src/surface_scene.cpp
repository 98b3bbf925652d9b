#include "embree_util.h"

#include <hairvox/core/error.h>
#include <hairvox/core/thread_scratch.h>
#include <hairvox/geometry/surface_scene.h>

#include <embree3/rtcore.h>

#include <cstring>
#include <limits>

namespace hairvox {

struct SurfaceScene::Embree {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;

    ~Embree() {
        if (scene)
            rtcReleaseScene(scene);
        if (device)
            rtcReleaseDevice(device);
    }
};

namespace {

/// Whether the segment o + t·d, t ∈ (0, tMax), can meet the box (slab test).
bool segmentMeetsBox(const Bounds3f& b, const Vec3f& o, const Vec3f& d, float tMax) {
    float t0 = 0, t1 = tMax;
    for (int a = 0; a < 3; ++a) {
        const float inv = 1.0f / d[a];
        float tNear = (b.min[a] - o[a]) * inv, tFar = (b.max[a] - o[a]) * inv;
        if (tNear > tFar)
            std::swap(tNear, tFar);
        // NaN (0·∞ for a ray in the slab's plane) keeps the interval as it is.
        t0 = tNear > t0 ? tNear : t0;
        t1 = tFar < t1 ? tFar : t1;
        if (t0 > t1 * (1.0f + 4e-7f))
            return false;
    }
    return true;
}

struct MeshHit {
    float t;
    std::uint32_t mesh, triangle;
    float u, v; ///< barycentric coordinates of corners 1 and 2
};

} // namespace

SurfaceScene::SurfaceScene(std::vector<Sphere> spheres, std::vector<TriangleMesh> meshes)
    : spheres_(std::move(spheres))
    , meshes_(std::move(meshes)) {
    for (const Sphere& s : spheres_) {
        if (!isFinite(s.center) || !(s.radius > 0) || !std::isfinite(s.radius))
            throw InputError("a surface sphere needs a finite centre and a radius > 0");
        bounds_.extend(Bounds3f{s.center - Vec3f(s.radius), s.center + Vec3f(s.radius)});
    }
    for (std::size_t m = 0; m < meshes_.size(); ++m) {
        const TriangleMesh& mesh = meshes_[m];
        for (const Vec3f& p : mesh.positions)
            if (!isFinite(p))
                throw InputError(strCat("mesh ", m, ": a vertex position is not finite"));
        for (const auto& t : mesh.triangles)
            for (const std::uint32_t v : t)
                if (v >= mesh.positions.size())
                    throw InputError(strCat("mesh ", m, ": a triangle names vertex ", v, " of ",
                                            mesh.positions.size()));
        if (!mesh.cornerNormals.empty() && mesh.cornerNormals.size() != 3 * mesh.triangles.size())
            throw InputError(strCat("mesh ", m, ": ", mesh.cornerNormals.size(),
                                    " corner normals for ", mesh.triangles.size(), " triangles"));
        bounds_.extend(mesh.bounds());
    }
    if (meshes_.empty())
        return;

    embree_ = std::make_unique<Embree>();
    Embree& e = *embree_;
    e.device = rtcNewDevice(nullptr);
    if (!e.device)
        throw std::runtime_error("cannot create an Embree device");
    e.scene = rtcNewScene(e.device);
    rtcSetSceneFlags(e.scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(e.scene, RTC_BUILD_QUALITY_HIGH);
    for (std::size_t m = 0; m < meshes_.size(); ++m) {
        const TriangleMesh& mesh = meshes_[m];
        RTCGeometry geometry = rtcNewGeometry(e.device, RTC_GEOMETRY_TYPE_TRIANGLE);
        // Embree-allocated buffers: they carry the padding its SIMD loads read.
        auto* vertices = static_cast<float*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                    3 * sizeof(float), mesh.positions.size()));
        auto* indices = static_cast<std::uint32_t*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                    3 * sizeof(std::uint32_t), mesh.triangles.size()));
        checkEmbree(e.device, "allocating a mesh");
        std::memcpy(vertices, mesh.positions.data(), mesh.positions.size() * sizeof(Vec3f));
        std::memcpy(indices, mesh.triangles.data(),
                    mesh.triangles.size() * 3 * sizeof(std::uint32_t));
        rtcCommitGeometry(geometry);
        rtcAttachGeometryByID(e.scene, geometry, static_cast<unsigned>(m));
        rtcReleaseGeometry(geometry);
    }
    rtcCommitScene(e.scene);
    checkEmbree(e.device, "building the surface scene");
}

SurfaceScene::~SurfaceScene() = default;

std::size_t SurfaceScene::triangleCount() const {
    std::size_t n = 0;
    for (const TriangleMesh& m : meshes_)
        n += m.triangleCount();
    return n;
}

namespace {

std::optional<MeshHit> nearestMeshHit(RTCScene scene, const Vec3f& origin, const Vec3f& dir,
                                      float tMax) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rayHit{};
    rayHit.ray = makeRay(origin, dir, tMax);
    rayHit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rayHit);
    if (rayHit.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return std::nullopt;
    return MeshHit{rayHit.ray.tfar, rayHit.hit.geomID, rayHit.hit.primID, rayHit.hit.u,
                   rayHit.hit.v};
}

/// The triangle's unit normal by its winding (counter-clockwise: outward).
Vec3f windingNormal(const TriangleMesh& mesh, std::uint32_t triangle) {
    const auto& t = mesh.triangles[triangle];
    const Vec3f& a = mesh.positions[t[0]];
    return normalizeOr(glm::cross(mesh.positions[t[1]] - a, mesh.positions[t[2]] - a),
                       Vec3f(0.0f, 1.0f, 0.0f));
}

} // namespace

namespace {

/// A context for a stream of coherent rays (Embree then traces them in
/// packets): camera rays through neighbouring pixels, shadow rays toward a light.
RTCIntersectContext coherentContext() {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    return context;
}

/// The nearest sphere on origin + t·dir before `nearest` (which it lowers to
/// the hit's t).
std::optional<SurfaceHit> nearestSphereHit(std::span<const Sphere> spheres, const Vec3f& origin,
                                           const Vec3f& dir, float& nearest) {
    std::optional<SurfaceHit> best;
    for (std::size_t i = 0; i < spheres.size(); ++i) {
        const float t = spheres[i].intersect(origin, dir, nearest);
        if (t > 0 && t < nearest) {
            nearest = t;
            const Vec3f n = normalizeOr(origin + t * dir - spheres[i].center, -dir);
            const Vec3f facing = glm::dot(n, dir) > 0 ? -n : n;
            best = SurfaceHit{t, static_cast<std::uint32_t>(i), facing, facing};
        }
    }
    return best;
}

/// The surface hit of a mesh hit on a ray along `dir`: its normals, facing the ray's origin.
SurfaceHit surfaceHit(std::span<const TriangleMesh> meshes, std::size_t sphereCount,
                      const MeshHit& h, const Vec3f& dir) {
    const TriangleMesh& mesh = meshes[h.mesh];
    Vec3f ng = windingNormal(mesh, h.triangle);
    if (glm::dot(ng, dir) > 0)
        ng = -ng;
    Vec3f ns = ng;
    if (!mesh.cornerNormals.empty()) {
        const Vec3f* n = &mesh.cornerNormals[3 * std::size_t(h.triangle)];
        ns = normalizeOr((1.0f - h.u - h.v) * n[0] + h.u * n[1] + h.v * n[2], ng);
        if (glm::dot(ns, ng) < 0)
            ns = -ns;
    }
    return SurfaceHit{h.t, static_cast<std::uint32_t>(sphereCount + h.mesh), ns, ng};
}

} // namespace

std::optional<SurfaceHit> SurfaceScene::intersect(const Vec3f& origin, const Vec3f& dir,
                                                  float tMax) const {
    if (empty() || !segmentMeetsBox(bounds_, origin, dir, tMax))
        return std::nullopt;
    float nearest = tMax;
    std::optional<SurfaceHit> best = nearestSphereHit(spheres_, origin, dir, nearest);
    if (embree_)
        if (const std::optional<MeshHit> h = nearestMeshHit(embree_->scene, origin, dir, nearest))
            best = surfaceHit(meshes_, spheres_.size(), *h, dir);
    return best;
}

void SurfaceScene::intersect(std::span<const Vec3f> origins, std::span<const Vec3f> dirs,
                             float tMax, std::span<std::optional<SurfaceHit>> hits) const {
    // Spheres and the bounding box per ray; the rest go to Embree together.
    struct Scratch {
        std::vector<RTCRayHit> rays;
        std::vector<std::uint32_t> rayOf;
    };
    ThreadScratch<Scratch> scratch;
    auto& [rays, rayOf] = *scratch;
    rays.clear();
    rayOf.clear();
    for (std::size_t i = 0; i < origins.size(); ++i) {
        hits[i].reset();
        if (empty() || !segmentMeetsBox(bounds_, origins[i], dirs[i], tMax))
            continue;
        float nearest = tMax;
        hits[i] = nearestSphereHit(spheres_, origins[i], dirs[i], nearest);
        if (!embree_)
            continue;
        RTCRayHit& ray = rays.emplace_back();
        ray.ray = makeRay(origins[i], dirs[i], nearest);
        ray.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rayOf.push_back(static_cast<std::uint32_t>(i));
    }
    if (rays.empty())
        return;
    RTCIntersectContext context = coherentContext();
    rtcIntersect1M(embree_->scene, &context, rays.data(), static_cast<unsigned>(rays.size()),
                   sizeof(RTCRayHit));
    for (std::size_t k = 0; k < rays.size(); ++k) {
        const RTCRayHit& r = rays[k];
        if (r.hit.geomID == RTC_INVALID_GEOMETRY_ID)
            continue;
        const std::uint32_t i = rayOf[k];
        hits[i] =
            surfaceHit(meshes_, spheres_.size(),
                       MeshHit{r.ray.tfar, r.hit.geomID, r.hit.primID, r.hit.u, r.hit.v}, dirs[i]);
    }
}

namespace {

/// A shadow segment's answer short of the meshes: Open (it misses the
/// surfaces' bounds, or there are no meshes left to ask), Blocked (by a
/// sphere), or AskMeshes.
enum class Occlusion { Open, Blocked, AskMeshes };

Occlusion occlusionBeforeMeshes(const Bounds3f& bounds, std::span<const Sphere> spheres,
                                bool meshes, const Vec3f& origin, const Vec3f& dir, float tMax) {
    if (!segmentMeetsBox(bounds, origin, dir, tMax))
        return Occlusion::Open;
    for (const Sphere& s : spheres)
        if (s.intersects(origin, dir, tMax))
            return Occlusion::Blocked;
    return meshes ? Occlusion::AskMeshes : Occlusion::Open;
}

} // namespace

bool SurfaceScene::occluded(const Vec3f& origin, const Vec3f& dir, float tMax) const {
    if (empty())
        return false;
    if (const Occlusion o =
            occlusionBeforeMeshes(bounds_, spheres_, embree_ != nullptr, origin, dir, tMax);
        o != Occlusion::AskMeshes)
        return o == Occlusion::Blocked;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray = makeRay(origin, dir, tMax);
    rtcOccluded1(embree_->scene, &context, &ray);
    return ray.tfar < 0; // Embree marks an occluded ray with tfar = −∞
}

void SurfaceScene::occluded(std::span<const Vec3f> origins, std::span<const Vec3f> dirs,
                            std::span<const float> tMax, std::span<std::uint8_t> blocked,
                            RayCoherence coherence) const {
    // Spheres and the bounding box per segment; the rest go to Embree together.
    struct Scratch {
        std::vector<RTCRay> rays;
        std::vector<std::uint32_t> rayOf;
    };
    ThreadScratch<Scratch> scratch;
    auto& [rays, rayOf] = *scratch;
    rays.clear();
    rayOf.clear();
    for (std::size_t i = 0; i < origins.size(); ++i) {
        const Occlusion o = empty() ? Occlusion::Open
                                    : occlusionBeforeMeshes(bounds_, spheres_, embree_ != nullptr,
                                                            origins[i], dirs[i], tMax[i]);
        blocked[i] = o == Occlusion::Blocked ? 1 : 0;
        if (o == Occlusion::AskMeshes) {
            rays.push_back(makeRay(origins[i], dirs[i], tMax[i]));
            rayOf.push_back(static_cast<std::uint32_t>(i));
        }
    }
    if (rays.empty())
        return;
    RTCIntersectContext context = coherentContext();
    if (coherence == RayCoherence::Incoherent)
        context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    rtcOccluded1M(embree_->scene, &context, rays.data(), static_cast<unsigned>(rays.size()),
                  sizeof(RTCRay));
    for (std::size_t k = 0; k < rays.size(); ++k)
        blocked[rayOf[k]] = rays[k].tfar < 0 ? 1 : 0; // Embree marks an occluded ray with tfar = −∞
}

bool SurfaceScene::contains(const Vec3f& p) const {
    for (const Sphere& s : spheres_)
        if (s.contains(p))
            return true;
    if (!embree_ || !isFinite(p))
        return false;
    static const Vec3f kDirections[3] = {glm::normalize(Vec3f(0.267f, 0.851f, 0.452f)),
                                         glm::normalize(Vec3f(-0.713f, -0.204f, 0.671f)),
                                         glm::normalize(Vec3f(0.388f, -0.559f, -0.733f))};
    int behind = 0;
    for (const Vec3f& d : kDirections)
        if (const std::optional<MeshHit> h =
                nearestMeshHit(embree_->scene, p, d, std::numeric_limits<float>::infinity()))
            behind += glm::dot(windingNormal(meshes_[h->mesh], h->triangle), d) > 0 ? 1 : 0;
    return behind >= 2;
}

} // namespace hairvox
