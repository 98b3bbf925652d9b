// hairvox core: Gauss–Legendre quadrature for the table integrals of shading/ and volumetric/
// (Tungsten's precomputeAzimuthalDistributions uses the same rule over h).
//
// An n-point rule integrates polynomials of degree 2n − 1 exactly; for the
// smooth, peak-split integrands of the dual-scattering tables it converges
// spectrally (tests/shading/dual_scattering_tables_test.cpp measures it).
#pragma once

#include <vector>

namespace hairvox::quadrature {

class GaussLegendre {
public:
    /// Nodes and weights on [−1, 1] for `order` ≥ 1 points (Newton on P_n, double precision).
    explicit GaussLegendre(int order);

    int order() const { return static_cast<int>(x_.size()); }
    /// Node k ∈ [0, order) on [−1, 1] (ascending) and its weight.
    double node(int k) const { return x_[static_cast<std::size_t>(k)]; }
    double weight(int k) const { return w_[static_cast<std::size_t>(k)]; }

    /// ∫_a^b f(x) dx.
    template <typename T, typename F>
    T integrate(double a, double b, F&& f) const {
        const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
        T sum{};
        for (std::size_t k = 0; k < x_.size(); ++k)
            sum += (w_[k] * half) * f(mid + half * x_[k]);
        return sum;
    }

private:
    std::vector<double> x_, w_;
};

} // namespace hairvox::quadrature
