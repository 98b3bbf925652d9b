// hairvox film (internal): float → half conversion and range checks for the
// EXR writer, across SIMD lanes (Google Highway, dispatched at run time).
//
// The bits are those of Imath's half(float) — round to nearest, ties to even
// — on every CPU: targets with F16C (AVX2, AVX-512) convert in hardware,
// which rounds the same way; the others call Imath per value. Values beyond
// the largest half become ±Inf there as here (the writer stores such a
// channel as float instead: maxAbs()).
#pragma once

#include <cstddef>
#include <cstdint>

namespace hairvox::detail {

/// Largest |x| over the first `count` values of a channel whose values are
/// `stride` floats apart (1 or 3); NaN counts as larger than anything.
float maxAbs(const float* values, std::size_t stride, std::size_t count);

/// Half bits of `count` values `stride` floats apart (1 or 3) into `out`.
void toHalf(const float* values, std::size_t stride, std::size_t count, std::uint16_t* out);

} // namespace hairvox::detail
