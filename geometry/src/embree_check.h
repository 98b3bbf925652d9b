// Internal to hairvox geometry: Embree has no exceptions — check the device's
// error state after each call that can fail and turn it into one.
#pragma once

#include <hairvox/core/error.h>

#include <embree3/rtcore.h>

#include <stdexcept>

namespace hairvox {

inline void checkEmbree(RTCDevice device, const char* what) {
    const RTCError error = rtcGetDeviceError(device);
    if (error != RTC_ERROR_NONE)
        throw std::runtime_error(strCat("Embree error ", static_cast<int>(error), " in ", what));
}

} // namespace hairvox
