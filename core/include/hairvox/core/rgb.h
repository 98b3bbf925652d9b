// hairvox core: RGB triples for spectral quantities (σ_a, attenuations, radiance).
//
// A distinct type from the geometric vectors so that a colour can never be
// passed where a direction is expected. Operations are per channel.
#pragma once

#include <hairvox/core/math.h>

#include <algorithm>
#include <cmath>
#include <concepts>
#include <ostream>

namespace hairvox {

template <std::floating_point T>
struct RgbT {
    T r = 0, g = 0, b = 0;

    constexpr RgbT() = default;
    constexpr explicit RgbT(T v) : r(v), g(v), b(v) {}
    constexpr RgbT(T r_, T g_, T b_) : r(r_), g(g_), b(b_) {}
    template <std::floating_point U>
    constexpr explicit RgbT(const RgbT<U>& o)
        : r(static_cast<T>(o.r)), g(static_cast<T>(o.g)), b(static_cast<T>(o.b)) {}

    static constexpr int size() { return 3; }
    constexpr T& operator[](int c) { return c == 0 ? r : (c == 1 ? g : b); }
    constexpr T operator[](int c) const { return c == 0 ? r : (c == 1 ? g : b); }

    constexpr RgbT& operator+=(const RgbT& o) { r += o.r; g += o.g; b += o.b; return *this; }
    constexpr RgbT& operator-=(const RgbT& o) { r -= o.r; g -= o.g; b -= o.b; return *this; }
    constexpr RgbT& operator*=(const RgbT& o) { r *= o.r; g *= o.g; b *= o.b; return *this; }
    constexpr RgbT& operator*=(T s) { r *= s; g *= s; b *= s; return *this; }
    constexpr RgbT& operator/=(T s) { r /= s; g /= s; b /= s; return *this; }

    constexpr T average() const { return (r + g + b) / T(3); }
    /// Relative luminance Y of linear Rec. 709 / sRGB primaries (ITU-R BT.709).
    constexpr T luminance() const { return T(0.2126) * r + T(0.7152) * g + T(0.0722) * b; }
    constexpr T maxComponent() const { return std::max({r, g, b}); }
    constexpr T minComponent() const { return std::min({r, g, b}); }
    bool isFinite() const { return std::isfinite(r) && std::isfinite(g) && std::isfinite(b); }
    constexpr bool isBlack() const { return r == 0 && g == 0 && b == 0; }

    friend constexpr bool operator==(const RgbT&, const RgbT&) = default;
};

using Rgb = RgbT<float>;
using Rgbd = RgbT<double>;

template <std::floating_point T>
constexpr RgbT<T> operator+(RgbT<T> a, const RgbT<T>& b) { return a += b; }
template <std::floating_point T>
constexpr RgbT<T> operator-(RgbT<T> a, const RgbT<T>& b) { return a -= b; }
template <std::floating_point T>
constexpr RgbT<T> operator-(const RgbT<T>& a) { return {-a.r, -a.g, -a.b}; }
template <std::floating_point T>
constexpr RgbT<T> operator*(RgbT<T> a, const RgbT<T>& b) { return a *= b; }
template <std::floating_point T>
constexpr RgbT<T> operator*(RgbT<T> a, T s) { return a *= s; }
template <std::floating_point T>
constexpr RgbT<T> operator*(T s, RgbT<T> a) { return a *= s; }
template <std::floating_point T>
constexpr RgbT<T> operator/(RgbT<T> a, T s) { return a /= s; }
template <std::floating_point T>
constexpr RgbT<T> operator/(const RgbT<T>& a, const RgbT<T>& b) {
    return {a.r / b.r, a.g / b.g, a.b / b.b};
}

/// Applies a scalar function to each channel.
template <std::floating_point T, typename F>
RgbT<T> mapChannels(const RgbT<T>& c, F&& f) {
    return {f(c.r), f(c.g), f(c.b)};
}

template <std::floating_point T>
RgbT<T> exp(const RgbT<T>& c) { return mapChannels(c, [](T x) { return std::exp(x); }); }
template <std::floating_point T>
RgbT<T> log(const RgbT<T>& c) { return mapChannels(c, [](T x) { return std::log(x); }); }
template <std::floating_point T>
RgbT<T> safeSqrt(const RgbT<T>& c) { return mapChannels(c, [](T x) { return safeSqrt(x); }); }
template <std::floating_point T>
RgbT<T> min(const RgbT<T>& a, const RgbT<T>& b) {
    return {std::min(a.r, b.r), std::min(a.g, b.g), std::min(a.b, b.b)};
}
template <std::floating_point T>
RgbT<T> max(const RgbT<T>& a, const RgbT<T>& b) {
    return {std::max(a.r, b.r), std::max(a.g, b.g), std::max(a.b, b.b)};
}
template <std::floating_point T>
RgbT<T> clamp(const RgbT<T>& c, T lo, T hi) {
    return mapChannels(c, [=](T x) { return std::clamp(x, lo, hi); });
}

template <std::floating_point T>
std::ostream& operator<<(std::ostream& os, const RgbT<T>& c) {
    return os << "Rgb(" << c.r << ", " << c.g << ", " << c.b << ")";
}

} // namespace hairvox
