// Internal to hairvox geometry: what the strand and surface scenes share about
// Embree — its errors (Embree has no exceptions: check the device's error state
// after each call that can fail and turn it into one) and its rays.
#pragma once

#include <hairvox/core/error.h>
#include <hairvox/core/vecmath.h>

#include <embree3/rtcore.h>

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace hairvox {

inline void checkEmbree(RTCDevice device, const char* what) {
    const RTCError error = rtcGetDeviceError(device);
    if (error != RTC_ERROR_NONE)
        throw std::runtime_error(strCat("Embree error ", static_cast<int>(error), " in ", what));
}

/// The segment origin + t·dir, t ∈ [0, tMax], as an Embree ray (all masks).
inline RTCRay makeRay(const Vec3f& origin, const Vec3f& dir, float tMax) {
    RTCRay ray{};
    ray.org_x = origin.x;
    ray.org_y = origin.y;
    ray.org_z = origin.z;
    ray.dir_x = dir.x;
    ray.dir_y = dir.y;
    ray.dir_z = dir.z;
    ray.tnear = 0.0f;
    ray.tfar = std::min(tMax, std::numeric_limits<float>::max());
    ray.mask = ~0u;
    return ray;
}

} // namespace hairvox
