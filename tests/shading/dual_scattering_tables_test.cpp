// Tests of the dual-scattering tables: anchors, quadrature convergence,
// energy bounds, the backscattering heuristics, interpolation, the disk cache,
// the CSV and the `hairvox tables` command.
#include "shading_test_util.h"
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/shading/dual_scattering_tables.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace hairvox {
namespace {

using test::readBytes;

using Sample = DualScatteringTables::Sample;

const std::vector<Rgb Sample::*> kAllFields{
    &Sample::aBar_f,     &Sample::aBar_b,     &Sample::alphaBar_f,
    &Sample::alphaBar_b, &Sample::beta2Bar_f, &Sample::beta2Bar_b,
    &Sample::ABar_b,     &Sample::DeltaBar_b, &Sample::sigma2Bar_b};

TEST(DualScatteringTables, MatchDesignAnchors) {
    // DESIGN.md §3: σ_a = (0.2, 0.3, 0.5), θ_o-normalised M_p.
    const DualScatteringTables t = DualScatteringTables::build(FiberParams{});
    const Sample s = t.lookup(0.0f);
    EXPECT_NEAR(s.aBar_f.r, 0.62f, 0.01f);
    EXPECT_NEAR(s.aBar_f.g, 0.52f, 0.01f);
    EXPECT_NEAR(s.aBar_f.b, 0.37f, 0.01f);
    EXPECT_NEAR(s.aBar_b.r, 0.042f, 0.001f);
    EXPECT_NEAR(s.aBar_b.g, 0.039f, 0.001f);
    EXPECT_NEAR(s.aBar_b.b, 0.035f, 0.001f);
    EXPECT_EQ(t.size(), 181);
    EXPECT_FLOAT_EQ(t.theta(0), -static_cast<float>(PiOver2));
    EXPECT_FLOAT_EQ(t.theta(180), static_cast<float>(PiOver2));
}

TEST(DualScatteringTables, QuadratureConverges) {
    // The same tables at increasing Gauss–Legendre orders against order 96:
    // the error falls by orders of magnitude and is below 1e-3 at the default 24.
    FiberParams params;
    params.eccentricity = 0.9f; // exercises the φ_h average too
    TableBuildOptions options;
    options.thetaSamples = 13; // 15° steps, including ±90°
    options.quadratureOrder = 96;
    const DualScatteringTables reference = DualScatteringTables::build(params, options);
    double previous = std::numeric_limits<double>::infinity();
    for (int order : {8, 16, 24, 48}) {
        options.quadratureOrder = order;
        const DualScatteringTables t = DualScatteringTables::build(params, options);
        double worst = 0;
        for (int k = 0; k < t.size(); ++k) {
            for (auto field : {&Sample::aBar_f, &Sample::aBar_b, &Sample::ABar_b})
                for (int c = 0; c < 3; ++c)
                    worst = std::max(worst, std::abs(double((t.sample(k).*field)[c]) -
                                                     double((reference.sample(k).*field)[c])));
            for (int j = 0; j < DualScatteringTables::kNGPhiSamples; ++j)
                for (Lobe p : kLobes)
                    for (int c = 0; c < 3; ++c)
                        worst = std::max(worst, std::abs(double(t.NGSample(k, j)[p][c]) -
                                                         double(reference.NGSample(k, j)[p][c])));
        }
        RecordProperty("order_" + std::to_string(order), std::to_string(worst));
        EXPECT_LT(worst, previous) << "order " << order;
        if (order >= 24) {
            EXPECT_LT(worst, 1e-3) << "order " << order;
        }
        previous = worst;
    }
}

TEST(DualScatteringTables, EnergyBoundedAndDecreasingInAbsorption) {
    // Marschner's range (α_R ∈ [−10°, −5°], β_R ∈ [5°, 10°]); within 5° of the
    // poles the model's 1/cos²θ_d exceeds unit albedo (ā_b reaches 1.2 at
    // θ = −90° for light hair) where the fiber's projected width cos θ
    // vanishes, so the bound is asserted on |θ| ≤ 85°. Monotonicity in σ_a
    // holds everywhere: every path's attenuation decreases with σ_a.
    for (float alphaDeg : {-10.0f, -5.0f})
        for (float betaDeg : {5.0f, 10.0f}) {
            std::vector<DualScatteringTables> tables;
            for (float sigma : {1e-8f, 0.05f, 0.3f, 1.0f, 5.0f, 50.0f}) {
                FiberParams p;
                p.alpha_R = radians(alphaDeg);
                p.beta_R = radians(betaDeg);
                p.sigma_a = Rgb(sigma, std::min(2 * sigma, 50.0f), 0.5f * sigma);
                TableBuildOptions o;
                o.thetaSamples = 37;
                tables.push_back(DualScatteringTables::build(p, o));
            }
            for (std::size_t i = 0; i < tables.size(); ++i)
                for (int k = 0; k < tables[i].size(); ++k) {
                    const Sample& s = tables[i].sample(k);
                    const bool inside = std::abs(tables[i].theta(k)) <= radians(85.0f) + 1e-6f;
                    for (int c = 0; c < 3; ++c) {
                        EXPECT_GE(s.aBar_f[c], 0.0f);
                        EXPECT_GE(s.aBar_b[c], 0.0f);
                        if (inside) {
                            EXPECT_LE(s.aBar_f[c], 1.0f) << alphaDeg << " " << betaDeg << " " << k;
                            EXPECT_LE(s.aBar_b[c], 1.0f) << alphaDeg << " " << betaDeg << " " << k;
                        }
                        if (i > 0) {
                            const Sample& prev = tables[i - 1].sample(k);
                            EXPECT_LE(s.aBar_f[c], prev.aBar_f[c] * (1 + 1e-6f)) << k;
                            EXPECT_LE(s.aBar_b[c], prev.aBar_b[c] * (1 + 1e-6f)) << k;
                        }
                    }
                }
            // Strong absorption leaves the R lobe only, strictly inside (0, 1).
            const Sample dark = tables.back().lookup(0.0f);
            EXPECT_GT(dark.aBar_b.b, 0.01f);
            EXPECT_LT(dark.aBar_f.g, 0.05f);
        }
}

TEST(DualScatteringTables, BackscatteringTermsFiniteAndPlausible) {
    // Eqs. 10–12 over parameter extremes, including σ_a = 0 where their
    // geometric series diverge without the ā_f cap.
    for (float sigma : {0.0f, 1e-8f, 0.2f, 50.0f})
        for (float betaDeg : {0.5f, 7.5f, 45.0f})
            for (float alphaDeg : {-20.0f, 0.0f, 20.0f}) {
                FiberParams p;
                p.sigma_a = Rgb(sigma);
                p.beta_R = radians(betaDeg);
                p.alpha_R = radians(alphaDeg);
                TableBuildOptions o;
                o.thetaSamples = 19;
                const DualScatteringTables t = DualScatteringTables::build(p, o);
                for (int k = 0; k < t.size(); ++k) {
                    const Sample& s = t.sample(k);
                    for (auto field : kAllFields)
                        ASSERT_TRUE((s.*field).isFinite()) << s;
                    for (int c = 0; c < 3; ++c) {
                        ASSERT_GE(s.ABar_b[c], 0.0f) << s;
                        ASSERT_LE(s.ABar_b[c], 1.0f) << s;
                        ASSERT_GT(s.beta2Bar_f[c], 0.0f) << s;
                        ASSERT_GT(s.beta2Bar_b[c], 0.0f) << s;
                        // σ̄_b is a spread of back-scattered light, at least β̄_b.
                        ASSERT_GE(std::sqrt(s.sigma2Bar_b[c]), std::sqrt(s.beta2Bar_b[c]) * 0.999f)
                            << s;
                        ASSERT_LT(s.sigma2Bar_b[c], 25.0f) << s;
                        ASSERT_LE(std::abs(s.DeltaBar_b[c]), static_cast<float>(PiOver2)) << s;
                        // Averages of α_p and β_p² lie between the lobes' values.
                        const float a = std::abs(p.alpha_R) * 1.5f + 1e-6f;
                        ASSERT_LE(std::abs(s.alphaBar_f[c]), a);
                        ASSERT_LE(std::abs(s.alphaBar_b[c]), a);
                        ASSERT_LE(s.beta2Bar_f[c], 4 * p.beta_R * p.beta_R * 1.0001f);
                        ASSERT_GE(s.beta2Bar_f[c], 0.25f * p.beta_R * p.beta_R * 0.9999f);
                    }
                }
            }
}

TEST(DualScatteringTables, NGIsNpAveragedOverTheHalfCircleFacingTheLight) {
    // N^G_p(θ_d, φ) = (1/π) ∫_{φ−π/2}^{φ+π/2} N_p(θ_d, φ') dφ', by the midpoint
    // rule on the exact N_p (between and on the table's φ samples); at φ = π
    // it is the printed (2/π) ∫_{π/2}^{π} N_p, and over the circle it carries
    // N_p's own energy — the printed constant applied at every φ carries twice
    // the front half's.
    FiberParams params;
    params.eccentricity = 0.9f; // the φ_h average and the caustic fade too
    const DualScatteringTables t = DualScatteringTables::build(params);
    const MarschnerBcsdf bcsdf(params);
    for (double theta_d : {0.0, 0.3, 0.8, 1.2}) {
        const auto window = [&](double phi) {
            LobeValues mean;
            const int n = 4000;
            for (int k = 0; k < n; ++k) {
                const double phi_k = phi - PiOver2 + Pi * (k + 0.5) / n;
                LobeValues v;
                const int orientations = 16; // φ_h uniform, for the eccentric TRT
                for (int o = 0; o < orientations; ++o) {
                    const LobeValues w =
                        bcsdf.NExact(theta_d, phi_k, std::cos(Pi * (o + 0.5) / orientations));
                    for (Lobe p : kLobes)
                        v[p] += w[p] * static_cast<float>(1.0 / orientations);
                }
                for (Lobe p : kLobes)
                    mean[p] += v[p] * static_cast<float>(1.0 / n);
            }
            return mean;
        };
        double energy[3] = {0, 0, 0}, total[3] = {0, 0, 0};
        for (double phi : {0.0, 0.4, Pi / 2, 2.0, 2.6, Pi}) {
            const LobeValues expected = window(phi);
            const LobeValues ng = t.NG(static_cast<float>(theta_d), static_cast<float>(phi));
            for (Lobe p : kLobes)
                EXPECT_NEAR(ng[p].g, expected[p].g, 3e-3f * expected.sum().g + 1e-6f)
                    << int(p) << " θ_d " << theta_d << " φ " << phi;
        }
        // Energy: 2 ∫_0^π N^G dφ (trapezoid on the table) against 2 ∫_0^π N_p dφ.
        const int m = 720;
        for (int k = 0; k <= m; ++k) {
            const double phi = Pi * k / m, w = (k == 0 || k == m ? 0.5 : 1.0) * 2 * Pi / m;
            const LobeValues ng = t.NG(static_cast<float>(theta_d), static_cast<float>(phi));
            for (int o = 0; o < 16; ++o) { // φ_h uniform
                const LobeValues n = bcsdf.N(static_cast<float>(theta_d), static_cast<float>(phi),
                                             static_cast<float>(std::cos(Pi * (o + 0.5) / 16)));
                for (Lobe p : kLobes)
                    total[int(p)] += w / 16 * double(n[p].g);
            }
            for (Lobe p : kLobes)
                energy[int(p)] += w * double(ng[p].g);
        }
        for (Lobe p : kLobes)
            EXPECT_NEAR(energy[int(p)], total[int(p)], 0.01 * total[int(p)] + 1e-6)
                << int(p) << " θ_d " << theta_d;
    }
}

TEST(DualScatteringTables, EccentricTablesAverageOverOrientation) {
    // With eccentricity the tables average over the cross-section orientation
    // (equivalently over φ_i): compare ā_f + ā_b with brute-force integrals of
    // f_s averaged over φ_i.
    FiberParams params;
    params.eccentricity = 0.85f;
    params.sigma_a = Rgb(0.1f);
    const MarschnerBcsdf bcsdf(params);
    TableBuildOptions o;
    o.thetaSamples = 13;
    const DualScatteringTables t = DualScatteringTables::build(params, o);
    for (double thetaDeg : {-30.0, 0.0, 45.0}) {
        Rgbd back(0.0), front(0.0);
        const int orientations = 8;
        for (int k = 0; k < orientations; ++k) {
            const test::HalfAlbedo a = test::integrateOverSphere(
                radians(thetaDeg), 240, 360,
                [&](const FiberAngles& x) { return bcsdf.eval(x).sum(); },
                Pi * (k + 0.5) / orientations);
            back += a.back / double(orientations);
            front += a.front / double(orientations);
        }
        const Sample s = t.lookup(static_cast<float>(radians(thetaDeg)));
        EXPECT_NEAR(s.aBar_f.g, front.g, 0.005) << thetaDeg;
        EXPECT_NEAR(s.aBar_b.g, back.g, 0.003) << thetaDeg;
    }
}

TEST(DualScatteringTables, LookupInterpolatesAndClamps) {
    TableBuildOptions o;
    o.thetaSamples = 7;
    const DualScatteringTables t = DualScatteringTables::build(FiberParams{}, o);
    for (int k = 0; k < t.size(); ++k) {
        const Sample s = t.lookup(t.theta(k));
        for (auto field : kAllFields)
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR((s.*field)[c], (t.sample(k).*field)[c], 1e-6f);
    }
    const float mid = 0.5f * (t.theta(2) + t.theta(3));
    const Rgb expected = 0.5f * (t.sample(2).aBar_f + t.sample(3).aBar_f);
    EXPECT_NEAR(t.aBar_f(mid).g, expected.g, 1e-6f);
    EXPECT_EQ(t.aBar_f(mid), t.lookup(mid).aBar_f);
    EXPECT_EQ(t.beta2Bar_f(mid), t.lookup(mid).beta2Bar_f);
    EXPECT_EQ(t.interpolate(mid, &Sample::ABar_b), t.lookup(mid).ABar_b);
    const auto [A, D] = t.interpolate(mid, &Sample::ABar_b, &Sample::DeltaBar_b);
    EXPECT_EQ(A, t.lookup(mid).ABar_b);
    EXPECT_EQ(D, t.lookup(mid).DeltaBar_b);
    EXPECT_EQ(t.aBar_f(-5.0f), t.sample(0).aBar_f);
    EXPECT_EQ(t.aBar_f(5.0f), t.sample(6).aBar_f);
    EXPECT_TRUE(t.aBar_f(std::numeric_limits<float>::quiet_NaN()).isFinite());
    for (int j = 0; j < DualScatteringTables::kNGPhiSamples; ++j) {
        const float phi = static_cast<float>(Pi * j / (DualScatteringTables::kNGPhiSamples - 1));
        for (float sign : {1.0f, -1.0f}) {
            const LobeValues ng = t.NG(t.theta(4), sign * phi);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(ng.TT[c], t.NGSample(4, j).TT[c],
                            1e-5f * t.NGSample(4, j).TT[c] + 1e-9f);
        }
    }
    EXPECT_TRUE(
        t.NG(std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::quiet_NaN())
            .sum()
            .isFinite());
}

TEST(DualScatteringTables, DeterministicForAnyThreadCount) {
    TableBuildOptions o;
    o.thetaSamples = 31;
    o.threaded = false;
    const DualScatteringTables serial = DualScatteringTables::build(FiberParams{}, o);
    o.threaded = true;
    const DualScatteringTables threaded = DualScatteringTables::build(FiberParams{}, o);
    for (int k = 0; k < serial.size(); ++k)
        for (auto field : kAllFields)
            ASSERT_EQ(serial.sample(k).*field, threaded.sample(k).*field) << k;
}

TEST(DualScatteringTables, BackwardDensityOnlyChangesSigmaB) {
    TableBuildOptions o;
    o.thetaSamples = 19;
    const DualScatteringTables base = DualScatteringTables::build(FiberParams{}, o);
    o.d_b = 0.3f;
    const DualScatteringTables direct = DualScatteringTables::build(FiberParams{}, o);
    const DualScatteringTables derived = base.withBackwardDensity(0.3f);
    EXPECT_EQ(derived.options().d_b, 0.3f);
    EXPECT_EQ(derived.cacheKey(), direct.cacheKey());
    for (int k = 0; k < base.size(); ++k)
        for (auto field : kAllFields)
            for (int c = 0; c < 3; ++c) {
                const float want = (direct.sample(k).*field)[c];
                EXPECT_NEAR((derived.sample(k).*field)[c], want, 1e-5f * std::abs(want) + 1e-7f);
            }
    EXPECT_LT(derived.sample(9).sigma2Bar_b.g, base.sample(9).sigma2Bar_b.g);
}

TEST(DualScatteringTables, ValidatesOptions) {
    TableBuildOptions o;
    o.thetaSamples = 2;
    EXPECT_THROW(DualScatteringTables::build(FiberParams{}, o), InputError);
    o = TableBuildOptions{};
    o.quadratureOrder = 1000;
    EXPECT_THROW(DualScatteringTables::build(FiberParams{}, o), InputError);
    o = TableBuildOptions{};
    o.d_b = 1.5f;
    EXPECT_THROW(DualScatteringTables::build(FiberParams{}, o), InputError);
    FiberParams p;
    p.causticGain = -1;
    EXPECT_THROW(DualScatteringTables::build(p), InputError);
}

// ---- cache --------------------------------------------------------------------------

TEST(DualScatteringTablesCache, SecondRunLoadsInsteadOfRebuilding) {
    test::TempDir dir;
    TableBuildOptions o;
    o.thetaSamples = 19;
    const DualScatteringTables first =
        DualScatteringTables::loadOrBuild(FiberParams{}, dir.path(), o);
    EXPECT_FALSE(first.loadedFromCache());
    const auto file = DualScatteringTables::cacheFile(dir.path(), FiberParams{}, o);
    ASSERT_TRUE(std::filesystem::exists(file));
    const auto written = std::filesystem::last_write_time(file);

    const DualScatteringTables second =
        DualScatteringTables::loadOrBuild(FiberParams{}, dir.path(), o);
    EXPECT_TRUE(second.loadedFromCache());
    EXPECT_EQ(std::filesystem::last_write_time(file), written);
    for (int k = 0; k < first.size(); ++k)
        for (auto field : kAllFields)
            ASSERT_EQ(first.sample(k).*field, second.sample(k).*field);

    // Other parameters or options: another file.
    FiberParams other;
    other.sigma_a = Rgb(1.0f);
    EXPECT_FALSE(DualScatteringTables::loadOrBuild(other, dir.path(), o).loadedFromCache());
    EXPECT_NE(DualScatteringTables::cacheFile(dir.path(), other, o), file);
    o.quadratureOrder = 16;
    EXPECT_NE(DualScatteringTables::cacheFile(dir.path(), FiberParams{}, o), file);
}

TEST(DualScatteringTablesCache, CorruptOrTruncatedFilesAreRebuilt) {
    test::TempDir dir;
    TableBuildOptions o;
    o.thetaSamples = 19;
    const DualScatteringTables good =
        DualScatteringTables::loadOrBuild(FiberParams{}, dir.path(), o);
    const auto file = DualScatteringTables::cacheFile(dir.path(), FiberParams{}, o);
    const std::string bytes = readBytes(file);

    std::string corrupt = bytes;
    corrupt[bytes.size() / 2] = static_cast<char>(corrupt[bytes.size() / 2] ^ 0x10);
    for (const std::string& damaged :
         {corrupt, bytes.substr(0, bytes.size() - 9), std::string("junk")}) {
        test::ByteWriter().putBytes(damaged.data(), damaged.size()).writeTo(file);
        const DualScatteringTables t =
            DualScatteringTables::loadOrBuild(FiberParams{}, dir.path(), o);
        EXPECT_FALSE(t.loadedFromCache());
        EXPECT_EQ(t.sample(9).aBar_f, good.sample(9).aBar_f);
        EXPECT_EQ(readBytes(file), bytes); // rewritten whole
        EXPECT_TRUE(
            DualScatteringTables::loadOrBuild(FiberParams{}, dir.path(), o).loadedFromCache());
    }
}

TEST(DualScatteringTablesCache, UnwritableCacheDirectoryStillGivesTables) {
    TableBuildOptions o;
    o.thetaSamples = 7;
    const DualScatteringTables t =
        DualScatteringTables::loadOrBuild(FiberParams{}, "/proc/hairvox-no-such-dir", o);
    EXPECT_EQ(t.size(), 7);
    EXPECT_FALSE(t.loadedFromCache());
}

TEST(DualScatteringTablesCache, DefaultDirectoryFollowsEnvironment) {
    const char* saved[] = {std::getenv("HAIRVOX_CACHE_DIR"), std::getenv("XDG_CACHE_HOME"),
                           std::getenv("HOME")};
    const std::string keep[] = {saved[0] ? saved[0] : "", saved[1] ? saved[1] : "",
                                saved[2] ? saved[2] : ""};
    ::setenv("HAIRVOX_CACHE_DIR", "/a/b", 1);
    EXPECT_EQ(defaultTableCacheDir(), std::filesystem::path("/a/b"));
    ::unsetenv("HAIRVOX_CACHE_DIR");
    ::setenv("XDG_CACHE_HOME", "/x", 1);
    EXPECT_EQ(defaultTableCacheDir(), std::filesystem::path("/x/hairvox"));
    ::unsetenv("XDG_CACHE_HOME");
    ::setenv("HOME", "/h", 1);
    EXPECT_EQ(defaultTableCacheDir(), std::filesystem::path("/h/.cache/hairvox"));
    const char* names[] = {"HAIRVOX_CACHE_DIR", "XDG_CACHE_HOME", "HOME"};
    for (int k = 0; k < 3; ++k) {
        if (saved[k])
            ::setenv(names[k], keep[k].c_str(), 1);
        else
            ::unsetenv(names[k]);
    }
}

// ---- CSV and CLI ----------------------------------------------------------------------

std::vector<std::string> csvLines(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);)
        lines.push_back(line);
    return lines;
}

constexpr const char* kHeader =
    "theta,af_r,af_g,af_b,ab_r,ab_g,ab_b,alphaf_r,alphaf_g,alphaf_b,alphab_r,alphab_g,alphab_b,"
    "beta2f_r,beta2f_g,beta2f_b,beta2b_r,beta2b_g,beta2b_b,Ab_r,Ab_g,Ab_b,Deltab_r,Deltab_g,"
    "Deltab_b,sigma2b_r,sigma2b_g,sigma2b_b";

/// kHeader followed by N^G per lobe at φ = 0°, 5°, …, 180° and channel.
std::string csvHeader() {
    std::string header = kHeader;
    for (const char* lobe : {"NGR", "NGTT", "NGTRT"})
        for (int deg = 0; deg <= 180; deg += 5)
            for (const char* c : {"_r", "_g", "_b"})
                header +=
                    strCat(",", lobe, "_phi", deg < 100 ? "0" : "", deg < 10 ? "0" : "", deg, c);
    return header;
}

TEST(DualScatteringTables, WritesCsv) {
    test::TempDir dir;
    TableBuildOptions o;
    o.thetaSamples = 5;
    const DualScatteringTables t = DualScatteringTables::build(FiberParams{}, o);
    t.writeCsv(dir / "t.csv");
    const std::vector<std::string> lines = csvLines(dir / "t.csv");
    ASSERT_EQ(lines.size(), 6u);
    EXPECT_EQ(lines[0], csvHeader());
    std::istringstream row(lines[3]);
    std::vector<double> values;
    for (std::string cell; std::getline(row, cell, ',');)
        values.push_back(std::stod(cell));
    ASSERT_EQ(values.size(), 28u + 3u * 37u * 3u);
    EXPECT_NEAR(values[0], 0.0, 1e-7);
    EXPECT_NEAR(values[1], t.sample(2).aBar_f.r, 1e-6);
    EXPECT_NEAR(values[28 + 37 * 3 + 36 * 3 + 1], t.NGSample(2, 36).TT.g, 1e-6); // TT at φ = π
    EXPECT_NEAR(values.back(), t.NGSample(2, 36).TRT.b, 1e-6);
}

TEST(TablesCli, WritesCsvAndUsesCache) {
    test::TempDir dir;
    const std::string common = "tables -o '" + (dir / "t.csv").string() + "' --cache-dir '" +
                               (dir / "cache").string() + "' --samples 19";
    auto r =
        test::runHairvox(common + " --melanin 0.5,0.2 --alpha-r -5 --beta-r 6 --eccentricity 0.9");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("built in"), std::string::npos) << r.output;
    const std::vector<std::string> lines = csvLines(dir / "t.csv");
    ASSERT_EQ(lines.size(), 20u);
    EXPECT_EQ(lines[0], csvHeader());
    r = test::runHairvox(common + " --melanin 0.5,0.2 --alpha-r -5 --beta-r 6 --eccentricity 0.9");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("loaded from the cache"), std::string::npos) << r.output;
    r = test::runHairvox(common + " --sigma-a 0.1,0.2,0.3 --caustic-width 20 --caustic-gain 2 "
                                  "--caustic-fade 0.2 --caustic-max-width 0.4 --eta 1.5 --d-b 0.5");
    EXPECT_EQ(r.exitCode, 0) << r.output;
}

TEST(TablesCli, BadValuesExitWith2) {
    test::TempDir dir;
    const std::string out = " -o '" + (dir / "t.csv").string() + "' --cache-dir '" +
                            (dir / "cache").string() + "' --samples 7";
    for (const char* bad :
         {"--eta 3", "--eta nan", "--sigma-a 1,2", "--sigma-a 1,2,-3",
          "--sigma-a 1,2,3 --melanin 1,1", "--melanin 1,30", "--beta-r 0.1", "--alpha-r 25",
          "--eccentricity 0.2", "--caustic-width 0", "--caustic-gain 11", "--caustic-fade 2",
          "--caustic-max-width 0", "--samples 2", "--d-b 2", "--eta abc"}) {
        const auto r = test::runHairvox(std::string("tables") + out + " " + bad);
        EXPECT_EQ(r.exitCode, 2) << bad << ": " << r.output;
    }
    EXPECT_EQ(test::runHairvox("tables --samples 7").exitCode, 2); // -o is required
    EXPECT_FALSE(std::filesystem::exists(dir / "t.csv"));
    const auto r = test::runHairvox("tables --eta 3" + out);
    EXPECT_NE(r.output.find("eta = 3 should be in the range [1.1, 2.5]"), std::string::npos)
        << r.output;
    EXPECT_EQ(test::runHairvox("tables --help").exitCode, 0);
}

} // namespace
} // namespace hairvox
