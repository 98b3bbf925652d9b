#include <hairvox/core/gauss_legendre.h>

#include <hairvox/core/math.h>

#include <cmath>
#include <stdexcept>
#include <utility>

namespace hairvox::quadrature {

GaussLegendre::GaussLegendre(int order) {
    if (order < 1)
        throw std::invalid_argument("GaussLegendre: order must be >= 1");
    const auto n = static_cast<std::size_t>(order);
    x_.resize(n);
    w_.resize(n);
    // P_n(x) and P_n'(x) by the three-term recurrence.
    const auto legendre = [n](double x) {
        double p0 = 1, p1 = 0;
        for (std::size_t j = 1; j <= n; ++j) {
            const double p2 = p1;
            const auto jd = static_cast<double>(j);
            p1 = p0;
            p0 = ((2 * jd - 1) * x * p1 - (jd - 1) * p2) / jd;
        }
        return std::pair{p0, static_cast<double>(n) * (x * p0 - p1) / (x * x - 1)};
    };
    // Roots by Newton from Tricomi's initial guess; the rule is symmetric, so
    // compute the positive half and mirror it.
    for (std::size_t i = 0; i < (n + 1) / 2; ++i) {
        double x = std::cos(Pi * (static_cast<double>(i) + 0.75) / (static_cast<double>(n) + 0.5));
        for (int iter = 0; iter < 100; ++iter) {
            const auto [p, dp] = legendre(x);
            const double dx = p / dp;
            x -= dx;
            if (std::abs(dx) < 1e-15)
                break;
        }
        const double dp = legendre(x).second;
        x_[i] = -x;
        x_[n - 1 - i] = x;
        w_[i] = w_[n - 1 - i] = 2 / ((1 - x * x) * dp * dp);
    }
}

} // namespace hairvox::quadrature
