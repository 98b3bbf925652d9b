#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/geometry/camera.h>

#include <cmath>

namespace hairvox {

std::ostream& operator<<(std::ostream& os, const CameraParams& p) {
    return os << "Camera(position=" << p.position << ", look_at=" << p.lookAt << ", up=" << p.up
              << ", fov=" << p.fovY << "deg, " << p.width << "x" << p.height << ")";
}

Camera::Camera(const CameraParams& p) {
    if (!isFinite(p.position) || !isFinite(p.lookAt) || !isFinite(p.up))
        throw InputError("camera: position, look_at and up must be finite");
    if (!(p.fovY >= 0.1f && p.fovY <= 170.0f))
        throw InputError(strCat("camera: fov = ", p.fovY, " deg: expected a number in [0.1, 170]"));
    if (p.width < 1 || p.width > kMaxResolution || p.height < 1 || p.height > kMaxResolution ||
        std::uint64_t(p.width) * p.height > kMaxPixels)
        throw InputError(strCat("camera: resolution ", p.width, " x ", p.height, ": expected 1 to ",
                                kMaxResolution, " pixels a side and at most ", kMaxPixels,
                                " pixels"));
    const Vec3f view = p.lookAt - p.position;
    const float distance = glm::length(view);
    if (!(distance > 0))
        throw InputError("camera: position and look_at must differ");
    forward_ = view / distance;
    const Vec3f side = glm::cross(forward_, p.up);
    // Parallel within ~0.06°: the frame would be numerically meaningless.
    if (!(glm::length(side) > 1e-3f * glm::length(p.up)))
        throw InputError(
            strCat("camera: up ", p.up, " must not be parallel to the view direction ", forward_));
    right_ = glm::normalize(side);
    up_ = glm::cross(right_, forward_);
    position_ = p.position;
    width_ = static_cast<int>(p.width);
    height_ = static_cast<int>(p.height);
    near_ = 1e-3f * distance;
    focal_ = 0.5f * float(height_) / std::tan(0.5f * radians(p.fovY));
}

std::array<std::array<float, 4>, 4> Camera::worldToCameraMatrix() const {
    std::array<std::array<float, 4>, 4> m{};
    // OpenEXR (Imath) multiplies row vectors: p_cam = p_world · M, and its
    // cameras look down −z, so the third column is −forward.
    const Vec3f axes[3] = {right_, up_, -forward_};
    for (std::size_t row = 0; row < 3; ++row) {
        for (std::size_t col = 0; col < 3; ++col)
            m[row][col] = axes[col][static_cast<int>(row)];
        m[row][3] = 0.0f;
    }
    for (std::size_t col = 0; col < 3; ++col)
        m[3][col] = -glm::dot(axes[col], position_);
    m[3][3] = 1.0f;
    return m;
}

} // namespace hairvox
