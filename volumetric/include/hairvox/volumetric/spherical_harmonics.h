// hairvox volumetric: real spherical harmonics Y_lm(ω), l ≤ L, in the world
// frame — the rotatable basis of a cache cell's incident radiance (Moon,
// Walter & Marschner 2008 keep their voxels' scattered radiance in it;
// docs/DESIGN.md §9).
//
// The orthonormal real basis (∫ Y_lm Y_l'm' dω = δ_ll' δ_mm'):
//     Y_l0 = K_l0 P_l^0(z),
//     Y_lm = √2 K_lm cos(mφ) P_l^m(z),   Y_l,−m = √2 K_lm sin(mφ) P_l^m(z)   (m > 0),
//     K_lm = √((2l + 1)/(4π) · (l − m)!/(l + m)!),
// P_l^m the associated Legendre functions without the Condon–Shortley phase.
// With z = ω_z and P_l^m(z) = (1 − z²)^{m/2} Q_l^m(z), the products
// (1 − z²)^{m/2}·(cos mφ, sin mφ) are Re and Im of (ω_x + iω_y)^m, so no
// trigonometric function is called; Q follows the usual recurrences
//     Q_m^m = (2m − 1)!!,  Q_{m+1}^m = (2m + 1) z Q_m^m,
//     Q_l^m = ((2l − 1) z Q_{l−1}^m − (l + m − 1) Q_{l−2}^m)/(l − m).
// Coefficient index l² + l + m (m ∈ [−l, l]).
#pragma once

#include <hairvox/core/math.h>
#include <hairvox/core/vecmath.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <utility>

namespace hairvox {

struct SphericalHarmonics {
    static constexpr int kMaxOrder = 8;
    static constexpr int kMaxCoefficients = (kMaxOrder + 1) * (kMaxOrder + 1);

    static constexpr int coefficients(int order) { return (order + 1) * (order + 1); }
    static constexpr int index(int l, int m) { return l * l + l + m; }

    /// Y_lm(ω) for l ≤ order into y[index(l, m)] (unit ω).
    static void evaluate(const Vec3f& omega, int order, float* y) {
        // kMaxOrder (the cache's default) with its loops unrolled at compile
        // time: the same operations, a third of the instructions (callgrind:
        // a flight's basis and record ~1,800 → ~600).
        if (order == kMaxOrder)
            evaluateTo(omega, std::integral_constant<int, kMaxOrder>{}, y);
        else
            evaluateTo(omega, order, y);
    }

    /// K_lm.
    static double normalisation(int l, int m) {
        double ratio = 1; // (l − m)!/(l + m)!
        for (int i = l - m + 1; i <= l + m; ++i)
            ratio /= double(i);
        return std::sqrt(double(2 * l + 1) / (4.0 * Pi) * ratio);
    }

private:
    /// evaluate() to `order`, an int or a std::integral_constant (then every
    /// loop is unrolled and every index a constant).
    template <typename Order>
    static void evaluateTo(const Vec3f& omega, Order order, float* y) {
        const float x = omega.x, yy = omega.y, z = omega.z;
        // Re, Im of (x + iy)^m, and Q_m^m = (2m − 1)!!, from m = 0 up.
        float re = 1, im = 0, qmm = 1;
        forEach(std::integral_constant<int, 0>{}, order, [&](auto m) {
            if (m > 0) {
                const float r = re * x - im * yy;
                im = re * yy + im * x;
                re = r;
                qmm *= float(2 * m - 1);
            }
            float q2 = 0, q1 = qmm; // Q_{l−2}^m, Q_{l−1}^m, starting at l = m
            forEach(m, order, [&](auto l) {
                float q;
                if (l == m)
                    q = qmm;
                else if (l == m + 1)
                    q = float(2 * m + 1) * z * qmm;
                else
                    q = kRecurrence[std::size_t(index(l, m))][0] * z * q1 -
                        kRecurrence[std::size_t(index(l, m))][1] * q2;
                if (l > m) {
                    q2 = q1;
                    q1 = q;
                }
                const float k = kNormalisation[std::size_t(index(l, m))];
                if (m == 0) {
                    y[index(l, 0)] = k * q;
                } else {
                    y[index(l, m)] = k * q * re;
                    y[index(l, -m)] = k * q * im;
                }
            });
        });
    }
    /// f(i) for i = first … last: a loop, or, for compile-time bounds, f of
    /// each std::integral_constant in turn.
    template <typename F>
    static void forEach(int first, int last, F&& f) {
        for (int i = first; i <= last; ++i)
            f(i);
    }
    template <int First, int Last, typename F>
    static void forEach(std::integral_constant<int, First>, std::integral_constant<int, Last>,
                        F&& f) {
        [&]<int... I>(std::integer_sequence<int, I...>) {
            (f(std::integral_constant<int, First + I>{}), ...);
        }
        (std::make_integer_sequence<int, Last - First + 1>{});
    }

    /// K_l0, and √2·K_lm for m > 0, at index(l, m).
    static inline const std::array<float, kMaxCoefficients> kNormalisation = [] {
        std::array<float, kMaxCoefficients> k{};
        for (int l = 0; l <= kMaxOrder; ++l)
            for (int m = 0; m <= l; ++m)
                k[std::size_t(index(l, m))] =
                    float((m == 0 ? 1.0 : std::sqrt(2.0)) * normalisation(l, m));
        return k;
    }();
    /// (2l − 1)/(l − m) and (l + m − 1)/(l − m) at index(l, m), l ≥ m + 2: Q's
    /// recurrence without a division per term.
    static inline const std::array<std::array<float, 2>, kMaxCoefficients> kRecurrence = [] {
        std::array<std::array<float, 2>, kMaxCoefficients> r{};
        for (int l = 2; l <= kMaxOrder; ++l)
            for (int m = 0; m <= l - 2; ++m)
                r[std::size_t(index(l, m))] = {float(2 * l - 1) / float(l - m),
                                               float(l + m - 1) / float(l - m)};
        return r;
    }();
};

} // namespace hairvox
