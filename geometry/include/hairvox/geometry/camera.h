// hairvox geometry: the pinhole camera, shared by the rasterizer and the path
// tracer so that their images match pixel for pixel.
//
// Conventions (pbrt-v4's raster space, a right-handed camera frame):
//  - camera space: x right, y up, z forward along the view direction; the
//    depth of a point is its camera-space z (> 0 in front of the camera);
//  - raster space: x right, y down, in pixels; pixel (i, j) covers
//    [i, i+1) × [j, j+1) and its centre is (i + ½, j + ½); row 0 is the top
//    row of the image (and of the film, the EXR and the PNG).
// The vertical field of view spans the image height; pixels are square.
#pragma once

#include <hairvox/core/vecmath.h>

#include <array>
#include <cstdint>
#include <ostream>

namespace hairvox {

inline constexpr std::uint32_t kMaxResolution = 16384;         ///< pixels a side
inline constexpr std::uint64_t kMaxPixels = 8192ull * 8192ull; ///< width · height

/// What a scene file says about the camera (angles in degrees).
struct CameraParams {
    Vec3f position{0.0f, 0.0f, 1.0f};
    Vec3f lookAt{0.0f};
    Vec3f up{0.0f, 1.0f, 0.0f};
    float fovY = 30.0f;          ///< vertical field of view, degrees, [0.1, 170]
    std::uint32_t width = 1024;  ///< pixels, [1, 16384]
    std::uint32_t height = 1024; ///< pixels, [1, 16384]; width·height ≤ 8192²
};

std::ostream& operator<<(std::ostream& os, const CameraParams& p);

class Camera {
public:
    /// Throws InputError if the position equals look_at, up is parallel to
    /// the view direction, a vector is not finite, or the field of view or
    /// resolution is outside the range given in CameraParams.
    explicit Camera(const CameraParams& params);

    int width() const { return width_; }
    int height() const { return height_; }
    const Vec3f& position() const { return position_; }
    /// Focal length in pixels: a unit of length at depth z spans f/z pixels.
    float focalLength() const { return focal_; }
    /// Geometry nearer than this depth is clipped: 1/1000 of the look-at distance.
    float nearClip() const { return near_; }

    /// World → camera space (see the file comment).
    Vec3f toCamera(const Vec3f& world) const {
        const Vec3f d = world - position_;
        return {glm::dot(d, right_), glm::dot(d, up_), glm::dot(d, forward_)};
    }
    /// World direction → camera space.
    Vec3f directionToCamera(const Vec3f& d) const {
        return {glm::dot(d, right_), glm::dot(d, up_), glm::dot(d, forward_)};
    }
    /// Camera space (z > 0) → raster position.
    Vec2f toRaster(const Vec3f& cam) const {
        return {0.5f * float(width_) + focal_ * cam.x / cam.z,
                0.5f * float(height_) - focal_ * cam.y / cam.z};
    }
    /// Unit camera-space direction of the ray through a raster position.
    Vec3f rayDirection(const Vec2f& raster) const {
        return glm::normalize(
            Vec3f(raster.x - 0.5f * float(width_), 0.5f * float(height_) - raster.y, focal_));
    }
    /// Camera-space direction → world space.
    Vec3f toWorldDirection(const Vec3f& cam) const {
        return cam.x * right_ + cam.y * up_ + cam.z * forward_;
    }

    /// Row-major 4×4 world-to-camera matrix in OpenEXR's convention (row
    /// vectors, camera looking down −z): the EXR `worldToCamera` attribute.
    std::array<std::array<float, 4>, 4> worldToCameraMatrix() const;

private:
    Vec3f position_, right_, up_, forward_;
    float focal_, near_;
    int width_, height_;
};

} // namespace hairvox
