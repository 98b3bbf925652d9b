// hairvox core: piecewise-constant probability distributions on [0, 1) and
// [0, 1)², sampled by inversion of their cumulative distribution (pbrt-v4's
// PiecewiseConstant1D and PiecewiseConstant2D, "Sampling Algorithms" A.5).
//
// A distribution is built from n ≥ 1 non-negative, finite values f_i, one per
// interval [i/n, (i + 1)/n); its density is f_i / ∫f there (∫f = mean of the
// f_i). A function that is zero everywhere gives the uniform density (so that
// sampling never fails) and integral() = 0. The cumulative sums are kept in
// double: a value 10⁵ times the mean (a sun in an environment map) next to
// millions of small ones keeps every interval's width.
//
// The 2D distribution samples the row (v) from the marginal of the row sums,
// then the column (u) from that row's conditional: pdf(u, v) = f(u, v) / ∫f.
// Beside them, the weight of multiple importance sampling that combines two
// such strategies (Veach 1997, §9.2).
#pragma once

#include <cstddef>
#include <limits>
#include <span>
#include <vector>

namespace hairvox {

/// Veach's power heuristic (β = 2): the weight of a sample drawn with density
/// pdfChosen when another strategy could have drawn it with pdfOther;
/// powerHeuristic(a, b) + powerHeuristic(b, a) = 1 where either is positive.
/// An infinite pdfChosen (a delta) weighs 1; both zero weigh 0.
inline float powerHeuristic(float pdfChosen, float pdfOther) {
    if (!(pdfChosen < std::numeric_limits<float>::infinity()))
        return 1.0f;
    const double a = double(pdfChosen) * double(pdfChosen), b = double(pdfOther) * double(pdfOther);
    return a + b > 0 ? float(a / (a + b)) : 0.0f;
}

class PiecewiseConstant1D {
public:
    PiecewiseConstant1D() = default;
    /// std::invalid_argument for no values or a negative or non-finite one.
    explicit PiecewiseConstant1D(std::span<const float> f);

    struct Sample {
        float x = 0;           ///< in [0, 1)
        float pdf = 0;         ///< density at x (> 0)
        std::size_t index = 0; ///< the interval x lies in
    };
    /// The point of cumulative probability u ∈ [0, 1).
    Sample sample(float u) const;
    /// Density on interval i.
    float pdf(std::size_t i) const {
        return integral_ > 0 ? float(double(func_[i]) / integral_) : 1.0f;
    }
    /// ∫₀¹ f = the mean of the values (0 for a zero function).
    double integral() const { return integral_; }
    std::size_t size() const { return func_.size(); }
    std::size_t memoryBytes() const {
        return func_.capacity() * sizeof(float) + cdf_.capacity() * sizeof(double);
    }

private:
    std::vector<float> func_;
    std::vector<double> cdf_; ///< n + 1 values, cdf_[0] = 0, cdf_[n] = 1
    double integral_ = 0;
};

class PiecewiseConstant2D {
public:
    PiecewiseConstant2D() = default;
    /// `f` row-major: `height` rows of `width` values (std::invalid_argument
    /// as for the 1D distribution, or for a size that does not match).
    PiecewiseConstant2D(std::span<const float> f, std::size_t width, std::size_t height);

    struct Sample {
        float u = 0, v = 0; ///< in [0, 1)²: u along a row, v across the rows
        float pdf = 0;      ///< density at (u, v) (> 0)
        std::size_t column = 0, row = 0;
    };
    /// The point for two uniforms in [0, 1).
    Sample sample(float u0, float u1) const;
    /// Density of the cell (column, row).
    float pdf(std::size_t column, std::size_t row) const;
    /// ∫∫ f over the unit square.
    double integral() const { return marginal_.integral(); }
    std::size_t width() const { return width_; }
    std::size_t height() const { return conditional_.size(); }
    std::size_t memoryBytes() const;

private:
    std::size_t width_ = 0;
    std::vector<PiecewiseConstant1D> conditional_; ///< per row
    PiecewiseConstant1D marginal_;                 ///< of the row integrals
};

} // namespace hairvox
