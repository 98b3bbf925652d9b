#include "ribbon.h"

#include <hairvox/core/math.h>

namespace hairvox::raster {

namespace {

/// Raster-space image of a direction u at camera-space point p (the
/// derivative of Camera::toRaster along u, divided by the focal length).
Vec2d projectDirection(const Vec3d& p, const Vec3d& u) {
    return {(u.x * p.z - p.x * u.z) / (p.z * p.z), -(u.y * p.z - p.y * u.z) / (p.z * p.z)};
}

} // namespace

bool isConvexQuad(const Vec2d q[4]) {
    bool positive = false, negative = false;
    for (int k = 0; k < 4; ++k) {
        const Vec2d e0 = q[(k + 1) % 4] - q[k];
        const Vec2d e1 = q[(k + 2) % 4] - q[(k + 1) % 4];
        const double cross = e0.x * e1.y - e0.y * e1.x;
        positive |= cross > 0;
        negative |= cross < 0;
    }
    return !(positive && negative);
}

namespace {

/// The ribbon's half-width offset at a vertex: the projection of the radius
/// of the ray-facing ribbon — perpendicular to both the tangent and the line
/// of sight, what Embree's flat curves are (RayScene) — f · radius / z across
/// the projected tangent on the optical axis, up to 1/cos of the angle off it
/// (a pinhole stretches the image radially). A tangent pointing at the camera
/// takes the perpendicular of `fallback` instead.
Vec2d ribbonOffset(const Vec3f& pc, const Vec3f& uc, double focal, double radius,
                   const Vec2d& fallback) {
    const Vec3d p(pc), w = glm::cross(p, Vec3d(uc));
    const double lw = glm::length(w);
    Vec2d d = projectDirection(p, Vec3d(uc));
    if (lw > 1e-9 * glm::length(p) && glm::length(d) > 1e-9) {
        const Vec2d o = projectDirection(p, w) * (focal * radius / lw);
        return glm::dot(o, Vec2d(-d.y, d.x)) < 0 ? -o : o;
    }
    d = fallback;
    double len = glm::length(d);
    if (!(len > 1e-12)) {
        d = Vec2d(1.0, 0.0);
        len = 1.0;
    }
    return Vec2d(-d.y, d.x) * (focal * radius / (p.z * len));
}

void setBounds(ScreenRibbon& r) {
    const Vec2d q[4] = {r.s0 + r.o0, r.s1 + r.o1, r.s1 - r.o1, r.s0 - r.o0};
    r.xMin = r.xMax = q[0].x;
    r.yMin = r.yMax = q[0].y;
    for (int k = 1; k < 4; ++k) {
        r.xMin = std::min(r.xMin, q[k].x);
        r.xMax = std::max(r.xMax, q[k].x);
        r.yMin = std::min(r.yMin, q[k].y);
        r.yMax = std::max(r.yMax, q[k].y);
    }
}

} // namespace

void projectStrand(const Camera& camera, std::span<const Vec3f> points,
                   std::span<const Vec3f> tangents, std::span<const float> radii, float zNear,
                   std::span<ProjectedVertex> out) {
    const double focal = camera.focalLength();
    const std::size_t n = points.size();
    for (std::size_t k = 0; k < n; ++k) {
        const Vec3f pc = camera.toCamera(points[k]);
        out[k].invZ = pc.z >= zNear ? 1.0f / pc.z : 0.0f;
        out[k].raster = pc.z >= zNear ? Vec2d(camera.toRaster(pc)) : Vec2d(0.0);
    }
    for (std::size_t k = 0; k < n; ++k) {
        if (!out[k].valid())
            continue;
        // Fallback direction: toward a projected neighbour.
        Vec2d fallback(0.0);
        if (k + 1 < n && out[k + 1].valid())
            fallback = out[k + 1].raster - out[k].raster;
        else if (k > 0 && out[k - 1].valid())
            fallback = out[k].raster - out[k - 1].raster;
        out[k].offset =
            ribbonOffset(camera.toCamera(points[k]), camera.directionToCamera(tangents[k]), focal,
                         radii[k], fallback);
    }
    // Miter joins: at an inner vertex the offset runs along the bent strand's
    // bisector, so its projection onto each adjacent segment's normal — the
    // ribbon's width there — is shorter by the cosine of half the bend.
    // Lengthen it by that cosine's inverse (capped, like SVG's miter limit, at
    // 4: a bend sharper than 150° keeps a shorter spike) so the ribbon is 2·r_k
    // wide along both segments at vertex k and its area is its width's
    // integral along its length.
    constexpr double kMiterLimit = 4.0;
    for (std::size_t k = 1; k + 1 < n; ++k) {
        if (!out[k - 1].valid() || !out[k].valid() || !out[k + 1].valid())
            continue;
        const Vec2d o = out[k].offset;
        const double len = glm::length(o);
        const Vec2d a = out[k].raster - out[k - 1].raster, b = out[k + 1].raster - out[k].raster;
        const double la = glm::length(a), lb = glm::length(b);
        if (!(len > 0 && la > 1e-12 && lb > 1e-12))
            continue;
        // |o × d| / |o| is the cosine between the offset and the segment's normal.
        const double ca = std::abs(o.x * a.y - o.y * a.x) / (len * la);
        const double cb = std::abs(o.x * b.y - o.y * b.x) / (len * lb);
        out[k].offset *= std::min(2.0 / std::max(ca + cb, 1e-12), kMiterLimit);
    }
}

ScreenRibbon ribbonBetween(const ProjectedVertex& a, const ProjectedVertex& b) {
    ScreenRibbon r;
    r.s0 = a.raster;
    r.s1 = b.raster;
    r.o0 = a.offset;
    r.o1 = b.offset;
    r.invZ0 = a.invZ;
    r.invZ1 = b.invZ;
    r.t0 = 0.0f;
    r.t1 = 1.0f;
    setBounds(r);
    return r;
}

std::optional<ScreenRibbon> projectRibbon(const Camera& camera, const Vec3f& p0, const Vec3f& p1,
                                          const Vec3f& u0, const Vec3f& u1, float r0, float r1,
                                          float zNear) {
    Vec3f c0 = camera.toCamera(p0), c1 = camera.toCamera(p1);
    if (c0.z < zNear && c1.z < zNear)
        return std::nullopt;
    Vec3f v0 = camera.directionToCamera(u0), v1 = camera.directionToCamera(u1);
    ScreenRibbon r;
    r.t0 = 0.0f;
    r.t1 = 1.0f;
    if (c0.z < zNear || c1.z < zNear) {
        const float t = (zNear - c0.z) / (c1.z - c0.z);
        const Vec3f c = c0 + t * (c1 - c0);
        const Vec3f v = lerp(t, v0, v1); // only its projected direction matters
        const float rc = r0 + t * (r1 - r0);
        if (c0.z < zNear) {
            c0 = c;
            v0 = v;
            r0 = rc;
            r.t0 = t;
        } else {
            c1 = c;
            v1 = v;
            r1 = rc;
            r.t1 = t;
        }
        c0.z = std::max(c0.z, zNear);
        c1.z = std::max(c1.z, zNear);
    }
    const double focal = camera.focalLength();
    r.s0 = Vec2d(camera.toRaster(c0));
    r.s1 = Vec2d(camera.toRaster(c1));
    r.invZ0 = 1.0f / c0.z;
    r.invZ1 = 1.0f / c1.z;
    r.o0 = ribbonOffset(c0, v0, focal, r0, r.s1 - r.s0);
    r.o1 = ribbonOffset(c1, v1, focal, r1, r.s1 - r.s0);
    setBounds(r);
    return r;
}

} // namespace hairvox::raster
