#include <hairvox/core/distribution.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hairvox {

PiecewiseConstant1D::PiecewiseConstant1D(std::span<const float> f)
    : func_(f.begin(), f.end()) {
    if (func_.empty())
        throw std::invalid_argument("PiecewiseConstant1D: no values");
    const std::size_t n = func_.size();
    cdf_.resize(n + 1);
    cdf_[0] = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (!(func_[i] >= 0) || !std::isfinite(func_[i]))
            throw std::invalid_argument("PiecewiseConstant1D: negative or non-finite value");
        cdf_[i + 1] = cdf_[i] + double(func_[i]) / double(n);
    }
    integral_ = cdf_[n];
    for (std::size_t i = 1; i <= n; ++i)
        cdf_[i] = integral_ > 0 ? cdf_[i] / integral_ : double(i) / double(n);
    // 1 from the end of the last interval of any weight on: the sum rounds
    // to just below 1 as often as to 1, and a u above it would otherwise land
    // in a trailing interval of weight 0 (a sample of density 0).
    std::size_t last = n;
    while (integral_ > 0 && last > 0 && func_[last - 1] == 0)
        --last;
    std::fill(cdf_.begin() + std::ptrdiff_t(last), cdf_.end(), 1.0);
}

PiecewiseConstant1D::Sample PiecewiseConstant1D::sample(float u) const {
    // The interval i with cdf[i] ≤ u < cdf[i + 1]: never one of zero width.
    const double x = std::clamp(double(u), 0.0, std::nextafter(1.0, 0.0));
    const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), x);
    const std::size_t i = std::min(std::size_t(it - cdf_.begin()) - 1, func_.size() - 1);
    const double width = cdf_[i + 1] - cdf_[i];
    const double du = width > 0 ? (x - cdf_[i]) / width : 0.5;
    const double n = double(func_.size());
    Sample s;
    s.index = i;
    // In its own interval: (i + du)/n can round up to the next one's start.
    s.x = std::min(float((double(i) + du) / n),
                   std::nextafter(float((double(i) + 1.0) / n), 0.0f));
    s.pdf = pdf(i);
    return s;
}

PiecewiseConstant2D::PiecewiseConstant2D(std::span<const float> f, std::size_t width,
                                         std::size_t height)
    : width_(width) {
    if (width == 0 || height == 0 || f.size() != width * height)
        throw std::invalid_argument("PiecewiseConstant2D: values do not match the size");
    conditional_.reserve(height);
    std::vector<float> rows(height);
    for (std::size_t y = 0; y < height; ++y) {
        conditional_.emplace_back(f.subspan(y * width, width));
        rows[y] = float(conditional_.back().integral());
    }
    marginal_ = PiecewiseConstant1D(rows);
}

PiecewiseConstant2D::Sample PiecewiseConstant2D::sample(float u0, float u1) const {
    const PiecewiseConstant1D::Sample v = marginal_.sample(u1);
    const PiecewiseConstant1D::Sample u = conditional_[v.index].sample(u0);
    return {u.x, v.x, u.pdf * v.pdf, u.index, v.index};
}

float PiecewiseConstant2D::pdf(std::size_t column, std::size_t row) const {
    return marginal_.pdf(row) * conditional_[row].pdf(column);
}

std::size_t PiecewiseConstant2D::memoryBytes() const {
    std::size_t bytes = marginal_.memoryBytes();
    for (const PiecewiseConstant1D& c : conditional_)
        bytes += c.memoryBytes() + sizeof(c);
    return bytes;
}

} // namespace hairvox
