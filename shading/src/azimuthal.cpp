#include <hairvox/core/math.h>
#include <hairvox/shading/azimuthal.h>

#include <algorithm>
#include <cmath>

namespace hairvox::azimuthal {

namespace {

/// Below this cos θ_d the fiber is seen exactly end-on; η' is capped instead
/// of dividing by zero (the result is then the η' → ∞ limit to ~1e-12).
constexpr double kMinCosTheta_d = 1e-12;

/// Φ(p, γ) − pπ = 2γ − 2p·γ_t: odd in γ and, for η' ≥ 1, within [−π, π].
double reducedExitAzimuth(int p, double gamma, double etaPrime) {
    return 2 * gamma - 2 * p * safeASin(std::sin(gamma) / etaPrime);
}

/// The root of f(γ) = target on [a, b], where f − target changes sign (or
/// vanishes at an end). Newton steps that leave the bracket become bisections.
double solveBracketed(int p, double etaPrime, double target, double a, double b, double fa,
                      double fb) {
    if (fa == 0)
        return a;
    if (fb == 0)
        return b;
    double lo = a, hi = b;      // invariant: f(lo) − target has the sign of fa
    double x = a + (b - a) * fa / (fa - fb); // secant start
    for (int iter = 0; iter < 200; ++iter) {
        const double fx = reducedExitAzimuth(p, x, etaPrime) - target;
        if (fx == 0)
            return x;
        if ((fx < 0) == (fa < 0))
            lo = x;
        else
            hi = x;
        double next = x - fx / exitAzimuthDerivative(p, x, etaPrime);
        if (!(next > std::min(lo, hi) && next < std::max(lo, hi)))
            next = 0.5 * (lo + hi);
        if (std::abs(next - x) <= 1e-15 || std::abs(hi - lo) <= 1e-15)
            return next;
        x = next;
    }
    return x;
}

/// |Φ''(h)| for TRT: 2h/(1 − h²)^{3/2} − 4h/(η'³(1 − h²/η'²)^{3/2}) (Khungurn §1.5.1).
double trtCurvature(double h, double etaPrime) {
    const double a = std::max(1 - h * h, 1e-300);
    const double b = std::max(1 - h * h / (etaPrime * etaPrime), 1e-300);
    return std::abs(2 * h / (a * std::sqrt(a)) -
                    4 * h / (etaPrime * etaPrime * etaPrime * b * std::sqrt(b)));
}

} // namespace

Geometry Geometry::make(double eta, double theta_d) {
    const double cosTheta_d = std::max(std::cos(theta_d), kMinCosTheta_d);
    Geometry g;
    g.eta = eta;
    // η² − sin²θ_d written as (η² − 1) + cos²θ_d: exact for η = 1 end-on, and
    // consistent with the capped cos θ_d so that η' ≥ 1 always.
    const double root = std::sqrt(std::max(eta * eta - 1, 0.0) + cosTheta_d * cosTheta_d);
    g.etaPrime = root / cosTheta_d;
    g.etaDoublePrime = eta * eta / g.etaPrime;
    g.cosTheta_t = root / eta;
    return g;
}

double eccentricEta(double eta, double eccentricity, double cos2Phi_h) {
    if (eccentricity == 1)
        return eta;
    const double a2 = eccentricity * eccentricity;
    const double eta1 = 2 * (eta - 1) * a2 - eta + 2;
    const double eta2 = 2 * (eta - 1) / a2 - eta + 2;
    return std::max(0.5 * ((eta1 + eta2) + cos2Phi_h * (eta1 - eta2)), 1.0);
}

double exitAzimuth(int p, double h, double etaPrime) {
    return 2 * safeASin(h) - 2 * p * safeASin(h / etaPrime) + p * Pi;
}

double exitAzimuthDerivative(int p, double gamma_i, double etaPrime) {
    // cos γ_i / sqrt(η'² − sin²γ_i) = cos γ_i / sqrt((η'² − 1) + cos²γ_i), which is 1 in the
    // η' = 1, |γ_i| = π/2 corner where both vanish.
    const double c = std::cos(gamma_i);
    const double den = std::sqrt(std::max(etaPrime * etaPrime - 1, 0.0) + c * c);
    return 2 - 2 * p * (den > 0 ? c / den : 1.0);
}

Roots solveExitAzimuth(int p, double phi, double etaPrime) {
    Roots roots;
    if (p == 0) {
        roots.gamma_i[0] = 0.5 * wrapAngle(phi);
        roots.count = 1;
        return roots;
    }
    // Monotonic branches of f(γ) = Φ − pπ over γ ∈ [−π/2, π/2]. TT is
    // increasing (η' > 1). TRT with η' < 2 decreases between the caustics at
    // ±γ_c, where dΦ/dγ = 0 ⟺ cos²γ = (η'² − 1)/3.
    std::array<double, 4> ends{-PiOver2, PiOver2, 0, 0};
    int endCount = 2;
    if (p == 2 && etaPrime < 2) {
        const double gamma_c = safeACos(std::sqrt((etaPrime * etaPrime - 1) / 3));
        ends = {-PiOver2, -gamma_c, gamma_c, PiOver2};
        endCount = 4;
    }
    // |f| ≤ π, so the root set of Φ ≡ φ (mod 2π) is that of f = wrap(φ − pπ).
    const double target = wrapAngle(phi - p * Pi);
    double fa = reducedExitAzimuth(p, ends[0], etaPrime) - target;
    for (int k = 0; k + 1 < endCount; ++k) {
        const double a = ends[static_cast<std::size_t>(k)];
        const double b = ends[static_cast<std::size_t>(k + 1)];
        const double fb = reducedExitAzimuth(p, b, etaPrime) - target;
        if ((fa <= 0 && fb >= 0) || (fa >= 0 && fb <= 0)) {
            const double gamma = solveBracketed(p, etaPrime, target, a, b, fa, fb);
            // A root exactly on a shared branch end (a caustic) is found twice.
            if (roots.count == 0 ||
                gamma - roots.gamma_i[static_cast<std::size_t>(roots.count - 1)] > 1e-12)
                roots.gamma_i[static_cast<std::size_t>(roots.count++)] = gamma;
        }
        fa = fb;
    }
    return roots;
}

double fresnel(const Geometry& geo, double gamma_i) {
    const double cosGamma_i = std::cos(gamma_i);
    const double sinGamma_t = std::sin(gamma_i) / geo.etaPrime;
    const double cosGamma_t = cosFromSin(sinGamma_t);
    const double sDen = cosGamma_i + geo.etaPrime * cosGamma_t;
    const double pDen = geo.etaDoublePrime * cosGamma_i + cosGamma_t;
    // Both vanish only for η' = 1 at |h| = 1: grazing incidence reflects everything.
    if (!(sDen > 0) || !(pDen > 0))
        return 1;
    const double rs = (cosGamma_i - geo.etaPrime * cosGamma_t) / sDen;
    const double rp = (geo.etaDoublePrime * cosGamma_i - cosGamma_t) / pDen;
    return std::min(0.5 * (rs * rs + rp * rp), 1.0);
}

Rgbd attenuation(int p, const Geometry& geo, double gamma_i, const Rgb& sigma_a) {
    const double f = fresnel(geo, gamma_i);
    if (p == 0)
        return Rgbd(f);
    const double cosGamma_t = cosFromSin(std::sin(gamma_i) / geo.etaPrime);
    // One exponential for the p passes (optical depths add).
    const double pathLength = 2 * p * cosGamma_t / geo.cosTheta_t;
    double scale = (1 - f) * (1 - f);
    for (int k = 1; k < p; ++k)
        scale *= f;
    return mapChannels(Rgbd(sigma_a), [&](double s) { return scale * std::exp(-s * pathLength); });
}

TrtCaustic trtCaustic(const Geometry& geo, const FiberParams& params) {
    TrtCaustic c;
    c.width = params.causticWidth;
    const double etaPrime = geo.etaPrime;
    if (etaPrime < 2) {
        c.t = 1;
        c.h_c = std::sqrt((4 - etaPrime * etaPrime) / 3);
        c.phi_c = exitAzimuth(2, c.h_c, etaPrime) - 2 * Pi;
        const double curvature = trtCurvature(c.h_c, etaPrime);
        c.deltaH = params.causticMaxWidth;
        if (curvature > 0)
            c.deltaH = std::min(c.deltaH, 2 * std::sqrt(2 * double(params.causticWidth) / curvature));
    } else {
        // The caustics have merged at φ = 0 (h_c = 0); fade the lobe out.
        c.t = 1 - smoothStep(2.0, 2.0 + double(params.causticFade), etaPrime);
        c.deltaH = params.causticMaxWidth;
    }
    if (c.t > 0)
        c.amplitude = (c.t * double(params.causticGain) * c.deltaH) *
                      attenuation(2, geo, safeASin(c.h_c), params.sigma_a);
    return c;
}

double trtFade(const TrtCaustic& caustic, double phi) {
    if (caustic.t == 0)
        return 1;
    // 1 − t·e(x) = (1 − t) − t·expm1(−x²/2w²): exact near the lobe centres.
    const auto one = [&](double x) {
        const double d = wrapAngle(x);
        return (1 - caustic.t) - caustic.t * std::expm1(-d * d / (2 * caustic.width * caustic.width));
    };
    return one(phi - caustic.phi_c) * one(phi + caustic.phi_c);
}

Rgbd trtCausticLobes(const TrtCaustic& caustic, double phi) {
    if (caustic.t == 0)
        return Rgbd(0.0);
    const double g = gaussian(wrapAngle(phi - caustic.phi_c), caustic.width) +
                     gaussian(wrapAngle(phi + caustic.phi_c), caustic.width);
    return g * caustic.amplitude;
}

Rgbd N(int p, const FiberParams& params, double theta_d, double phi, double cos2Phi_h) {
    const double eta =
        p == 2 ? eccentricEta(params.eta, params.eccentricity, cos2Phi_h) : double(params.eta);
    const Geometry geo = Geometry::make(eta, theta_d);
    TrtCaustic caustic;
    double weight = 1;
    if (p == 2) {
        caustic = trtCaustic(geo, params);
        weight = trtFade(caustic, phi);
    }
    Rgbd sum(0.0);
    if (weight > 0) {
        const Roots roots = solveExitAzimuth(p, phi, geo.etaPrime);
        for (int k = 0; k < roots.count; ++k) {
            const double gamma = roots.gamma_i[static_cast<std::size_t>(k)];
            // |dΦ/dh|⁻¹ = cos γ / |dΦ/dγ|. At a caustic dΦ/dγ → 0, but there the
            // fade vanishes faster (quadratically in φ − φ_c); the floor only
            // keeps 0·∞ out of rounding.
            const double dPhi = std::max(std::abs(exitAzimuthDerivative(p, gamma, geo.etaPrime)), 1e-12);
            sum += (weight * std::cos(gamma) / (2 * dPhi)) *
                   attenuation(p, geo, gamma, params.sigma_a);
        }
    }
    if (p == 2)
        sum += trtCausticLobes(caustic, phi);
    return sum;
}

} // namespace hairvox::azimuthal
