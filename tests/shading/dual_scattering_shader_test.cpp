// Tests of the dual-scattering shader: its limits (unshadowed, blocked, n → 0),
// the normalisation of f_back, the widening of the scattered terms, and its
// contract with the tables.
#include "shading_test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/core/rng.h>
#include <hairvox/shading/dual_scattering_shader.h>

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <stdexcept>

namespace hairvox {
namespace {

struct Fixture {
    explicit Fixture(const FiberParams& p = {}, const DualScatteringParams& ds = {})
        : bcsdf(p), tables(DualScatteringTables::build(p)), shader(bcsdf, tables, ds) {}
    MarschnerBcsdf bcsdf;
    DualScatteringTables tables;
    DualScatteringShader shader;
};

/// The global term after n expected crossings at the shading point's own
/// inclination θ, under a Poisson model of crossings (DESIGN.md §5):
/// V = e^{−n}, P = e^{−n(1 − ā_f)}, T_s = d_f(P − V), σ_f² = n β̄_f² / (1 − V).
GlobalTerm poissonTerm(const DualScatteringTables& t, float theta, float n, float d_f) {
    GlobalTerm g;
    g.n = n;
    g.V = std::exp(-n);
    const Rgb aBar_f = min(t.aBar_f(theta), Rgb(1.0f));
    g.P = exp(-n * (Rgb(1.0f) - aBar_f));
    g.T_s = d_f * max(g.P - Rgb(g.V), Rgb(0.0f));
    // n/(1 − e^{−n}) → 1 as n → 0: the variance of at least one crossing.
    const float conditioning = n > 0 ? n / -std::expm1(-n) : 1.0f;
    g.sigma2_f = conditioning * t.beta2Bar_f(theta);
    return g;
}

/// The RenderMan report's form: T_s = d_f(ā_f^n − V) (clamped: it goes negative
/// for ā_f < 1/e), σ_f² = n β̄_f²; the product in log space.
GlobalTerm paperTerm(const DualScatteringTables& t, float theta, float n, float d_f) {
    GlobalTerm g;
    g.n = n;
    g.V = std::exp(-n);
    g.P = exp(n * log(max(t.aBar_f(theta), Rgb(1e-30f))));
    g.T_s = d_f * max(g.P - Rgb(g.V), Rgb(0.0f));
    g.sigma2_f = n * t.beta2Bar_f(theta);
    return g;
}

TEST(DualScatteringShader, UnshadowedIsSingleScatteringPlusLocalBackscatter) {
    // V = 1, T_s = 0: (f_s + d_b f_back^direct)·cos θ_i, nothing else.
    const Fixture f;
    Pcg32 rng(2);
    for (int k = 0; k < 2000; ++k) {
        const Vec3f u = test::fiberDirection(Vec3f(0, 1, 0), rng.uniform(-1.5f, 1.5f), rng.uniform(-3, 3));
        const Vec3f wi = test::fiberDirection(u, rng.uniform(-1.5f, 1.5f), rng.uniform(-3, 3));
        const Vec3f wo = test::fiberDirection(u, rng.uniform(-1.5f, 1.5f), rng.uniform(-3, 3));
        const ShadeResult r = f.shader.shade(wi, wo, u, GlobalTerm::unoccluded());
        const FiberAngles a = FiberAngles::fromDirections(wi, wo, u);
        const LobeValues fs = f.bcsdf.eval(a);
        const Rgb back = f.shader.fBack(a, Rgb(0.0f));
        EXPECT_EQ(r.directR, fs.R * a.cosTheta_i);
        EXPECT_EQ(r.directTT, fs.TT * a.cosTheta_i);
        EXPECT_EQ(r.directTRT, fs.TRT * a.cosTheta_i);
        const float d_b = DualScatteringParams{}.d_b;
        EXPECT_EQ(r.backDirect, back * (d_b * a.cosTheta_i));
        EXPECT_EQ(r.scatter, Rgb(0.0f));
        const Rgb expected = (fs.sum() + d_b * back) * a.cosTheta_i;
        EXPECT_NEAR(r.total().g, expected.g, 1e-5f * expected.g + 1e-9f);
    }
}

TEST(DualScatteringShader, BlockedLightGivesNothing) {
    const Fixture f;
    const Vec3f u(0, 1, 0);
    const ShadeResult r = f.shader.shade(test::fiberDirection(u, 0.2, 0.0),
                                         test::fiberDirection(u, -0.1, 2.0), u, GlobalTerm::blocked());
    EXPECT_EQ(r.total(), Rgb(0.0f));
}

TEST(DualScatteringShader, BackscatterCarriesABarIntoTheBackHalf) {
    // ∫_{Ω_b} f_back cos θ dω = Ā_b(θ_i) for narrow σ̄_b (σ_f² = 0) when the lobe
    // sits on the specular cone (α_R = 0 gives Δ̄_b = 0); shifted by Δ̄_b it is
    // Ā_b·cos²θ_o*/cos²θ_d* at the lobe's peak θ_o* = 2Δ̄_b − θ_i, the same
    // 1/cos²θ_d weighting as the M_p N_p lobes of f_s. Nothing reaches the front half.
    for (float alphaDeg : {0.0f, -5.0f}) {
        FiberParams p;
        p.beta_R = radians(0.5f); // σ̄_b ≈ 1°: the weight's curvature costs < 0.1%
        p.alpha_R = radians(alphaDeg);
        const Fixture f(p);
        for (double thetaDeg : {-40.0, 0.0, 30.0}) {
            const double theta_i = radians(thetaDeg);
            const test::HalfAlbedo a = test::integrateOverSphere(
                theta_i, 1800, 360, [&](const FiberAngles& x) { return f.shader.fBack(x, Rgb(0.0f)); });
            const auto s = f.tables.lookup(static_cast<float>(theta_i));
            for (int c = 0; c < 3; ++c) {
                const double theta_o = 2 * double(s.DeltaBar_b[c]) - theta_i;
                const double weight = std::pow(std::cos(theta_o) / std::cos(0.5 * (theta_o - theta_i)), 2);
                if (alphaDeg == 0) {
                    EXPECT_NEAR(weight, 1.0, 1e-6);
                }
                const double expected = double(s.ABar_b[c]) * weight;
                EXPECT_NEAR(a.back[c], expected, 0.003 * expected) << alphaDeg << " " << thetaDeg;
                EXPECT_EQ(a.front[c], 0.0);
            }
            EXPECT_LT(std::sqrt(s.sigma2Bar_b.g), 0.02f); // the narrow case
        }
    }
}

TEST(DualScatteringShader, ScatteredSpreadKeepsEnergyAndWidens) {
    // f_s^scatter and f_back^scatter widen with σ_f²; their θ_o-integrals stay
    // put while the lobe is well inside the sphere, and their peaks drop.
    const Fixture f;
    const float theta_i = 0.1f, phi = 2.5f;
    double previousPeak = 1e30;
    for (float sigma2 : {0.0f, 0.01f, 0.05f}) {
        double energy = 0, peak = 0;
        const int n = 4000;
        for (int k = 0; k < n; ++k) {
            const double theta_o = -PiOver2 + Pi * (k + 0.5) / n;
            const FiberAngles a = FiberAngles::fromAngles(theta_i, float(theta_o), phi);
            const double v = double(f.shader.fsScatter(a, Rgb(sigma2)).g);
            energy += v * double(a.cos2Theta_d) * Pi / n; // undo 1/cos²θ_d: Σ N^G_p remains
            peak = std::max(peak, v);
        }
        const LobeValues ng = f.tables.NG(0.5f * (0.0f - theta_i), phi); // θ_d at the lobe peaks, roughly
        EXPECT_NEAR(energy, double(ng.sum().g), 0.03 * double(ng.sum().g)) << sigma2;
        EXPECT_LT(peak, previousPeak);
        previousPeak = peak;
    }
}

TEST(DualScatteringShader, ContinuousAsCrossingsVanish) {
    // Both forms of the global term: T_s ≥ 0 and the shade converges to the
    // unoccluded one as n → 0.
    const Fixture f;
    const Vec3f u(0, 0, 1);
    Pcg32 rng(9);
    for (int k = 0; k < 200; ++k) {
        const Vec3f wi = test::fiberDirection(u, rng.uniform(-1.4f, 1.4f), rng.uniform(-3, 3));
        const Vec3f wo = test::fiberDirection(u, rng.uniform(-1.4f, 1.4f), rng.uniform(-3, 3));
        const float theta = FiberAngles::fromDirections(wi, wo, u).theta_i;
        const Rgb at0 = f.shader.shade(wi, wo, u, GlobalTerm::unoccluded()).total();
        for (auto form : {poissonTerm, paperTerm}) {
            for (float n : {1e-6f, 1e-4f, 1e-2f, 1.0f, 10.0f, 1e4f}) {
                const GlobalTerm g = form(f.tables, theta, n, 0.7f);
                ASSERT_GE(g.T_s.minComponent(), 0.0f) << g;
                ASSERT_TRUE(g.T_s.isFinite() && g.sigma2_f.isFinite()) << g;
                const Rgb v = f.shader.shade(wi, wo, u, g).total();
                ASSERT_TRUE(v.isFinite());
                ASSERT_GE(v.minComponent(), 0.0f);
            }
            const Rgb small = f.shader.shade(wi, wo, u, form(f.tables, theta, 1e-6f, 0.7f)).total();
            EXPECT_NEAR(small.g, at0.g, 1e-5f * at0.g + 1e-7f);
        }
    }
}

TEST(DualScatteringShader, ShadeComponentsAreWeighted) {
    const Fixture f;
    const Vec3f u(0, 1, 0), wi = test::fiberDirection(u, 0.3, 0.2), wo = test::fiberDirection(u, -0.2, 2.9);
    GlobalTerm g;
    g.V = 0.25f;
    g.T_s = Rgb(0.1f, 0.05f, 0.02f);
    g.sigma2_f = Rgb(0.02f);
    const ShadeResult half = f.shader.shade(wi, wo, u, g);
    const ShadeResult full = f.shader.shade(wi, wo, u, GlobalTerm::unoccluded());
    EXPECT_NEAR(half.directTT.g, 0.25f * full.directTT.g, 1e-6f * full.directTT.g);
    EXPECT_NEAR(half.backDirect.g, 0.25f * full.backDirect.g, 1e-6f * full.backDirect.g + 1e-12f);
    const FiberAngles a = FiberAngles::fromDirections(wi, wo, u);
    const Rgb scatter = g.T_s *
                        (f.shader.fsScatter(a, g.sigma2_f) +
                         static_cast<float>(Pi) * DualScatteringParams{}.d_b * f.shader.fBack(a, g.sigma2_f)) *
                        a.cosTheta_i;
    EXPECT_NEAR(half.scatter.b, scatter.b, 1e-6f * scatter.b);
    EXPECT_GT(half.scatter.r, half.scatter.b);
}

TEST(DualScatteringShader, UsesItsOwnBackwardDensity) {
    // Tables built with the default d_b and a shader with d_b = 0.2: σ̄_b² follows the shader.
    const FiberParams p;
    const MarschnerBcsdf bcsdf(p);
    const DualScatteringTables tables = DualScatteringTables::build(p);
    DualScatteringParams ds;
    ds.d_b = 0.2f;
    const DualScatteringShader shader(bcsdf, tables, ds);
    EXPECT_EQ(shader.tables().options().d_b, 0.2f);
    TableBuildOptions o;
    o.d_b = 0.2f;
    const DualScatteringTables expected = DualScatteringTables::build(p, o);
    EXPECT_NEAR(shader.tables().lookup(0.3f).sigma2Bar_b.g, expected.lookup(0.3f).sigma2Bar_b.g, 1e-6f);
}

TEST(DualScatteringShader, RejectsMismatchedTablesAndBadParams) {
    FiberParams other;
    other.sigma_a = Rgb(1.0f);
    const MarschnerBcsdf bcsdf{FiberParams{}};
    EXPECT_THROW(DualScatteringShader(bcsdf, DualScatteringTables::build(other), DualScatteringParams{}),
                 std::invalid_argument);
    DualScatteringParams bad;
    bad.d_f = 2.0f;
    EXPECT_THROW(DualScatteringShader(bcsdf, DualScatteringTables::build(FiberParams{}), bad), InputError);
}

TEST(DualScatteringShader, ABatchShadesEachPointAsAloneAndSumsTheLights) {
    // The renderer's path: many points (not a whole number of SIMD vectors),
    // two lights with their irradiance, some points unlit by one of them.
    // Each light's share must be the single-point shade (the same lanes),
    // scaled by its irradiance, and an unlit point gets nothing from it.
    const Fixture f;
    Pcg32 rng(12);
    constexpr std::size_t count = 1001;
    struct Point {
        Vec3f wo, u, wi[2];
        GlobalTerm g[2];
    };
    std::vector<Point> points(count);
    const Rgb E[2] = {Rgb(1.0f, 0.9f, 0.8f), Rgb(3.0f, 3.5f, 4.0f)};
    ShadeBatch batch;
    batch.reset(count);
    for (std::size_t i = 0; i < count; ++i) {
        Point& p = points[i];
        p.u = test::fiberDirection(Vec3f(0, 1, 0), rng.uniform(-1.5f, 1.5f), rng.uniform(-3, 3));
        p.wo = test::fiberDirection(p.u, rng.uniform(-1.5f, 1.5f), rng.uniform(-3, 3));
        for (int l = 0; l < 2; ++l) {
            p.wi[l] = test::fiberDirection(p.u, rng.uniform(-1.5f, 1.5f), rng.uniform(-3, 3));
            const FiberAngles a = FiberAngles::fromDirections(p.wi[l], p.wo, p.u);
            p.g[l] = i % 7 == 0 ? GlobalTerm::blocked()
                                : poissonTerm(f.tables, a.theta_i, rng.uniform(0.0f, 4.0f), 1.0f);
        }
        batch.setView(i, p.wo, p.u);
    }
    for (int l = 0; l < 2; ++l) {
        for (std::size_t i = 0; i < count; ++i) {
            batch.setIncident(i, points[i].wi[l], E[l]);
            batch.setGlobalTerm(i, points[i].g[l]);
        }
        f.shader.shade(batch);
    }
    for (std::size_t i = 0; i < count; ++i) {
        const Point& p = points[i];
        const ShadeResult r = batch.radiance(i);
        Rgb expected(0.0f);
        for (int l = 0; l < 2; ++l)
            expected += E[l] * f.shader.shade(p.wi[l], p.wo, p.u, p.g[l]).total();
        const Rgb total = r.total();
        for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(total[c], expected[c], 1e-5f * expected[c] + 1e-12f) << "point " << i;
        if (i % 7 == 0) {
            ASSERT_EQ(total, Rgb(0.0f)) << "point " << i;
        }
    }
}

TEST(DualScatteringShader, OutlivesItsArguments) {
    std::optional<DualScatteringShader> shader;
    {
        const MarschnerBcsdf bcsdf{FiberParams{}};
        const DualScatteringTables tables = DualScatteringTables::build(FiberParams{});
        shader.emplace(bcsdf, tables, DualScatteringParams{});
    }
    const Vec3f u(0, 1, 0);
    const Rgb v = shader->shade(test::fiberDirection(u, 0.1, 0), test::fiberDirection(u, 0, 3), u,
                                GlobalTerm::unoccluded())
                      .total();
    EXPECT_GT(v.g, 0.0f);
}

} // namespace
} // namespace hairvox
