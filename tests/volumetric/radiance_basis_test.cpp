#include <hairvox/core/math.h>
#include <hairvox/core/rng.h>
#include <hairvox/core/sampling.h>
#include <hairvox/shading/marschner.h>
#include <hairvox/volumetric/radiance_basis.h>
#include <hairvox/volumetric/scattering_kernel.h>

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace hairvox {
namespace {

TEST(RadianceBasis, HarmonicsAreTheAzimuthsCosinesAndSines) {
    const FiberFrame frame = FiberFrame::about(glm::normalize(Vec3f(0.3f, 1.0f, -0.2f)));
    Pcg32 rng(4);
    for (int i = 0; i < 100; ++i) {
        const Vec3f w = uniformSphere(rng.uniformFloat(), rng.uniformFloat());
        const AzimuthalHarmonics h = AzimuthalHarmonics::of(w, frame, RadianceBasis::kMaxOrder);
        EXPECT_NEAR(h.s, glm::dot(w, frame.axis), 1e-6f);
        const float phi = std::atan2(glm::dot(w, frame.e2), glm::dot(w, frame.e1));
        for (int k = 1; k <= RadianceBasis::kMaxOrder; ++k) {
            EXPECT_NEAR(h.harmonic[std::size_t(2 * k - 1)], std::cos(float(k) * phi), 2e-5f);
            EXPECT_NEAR(h.harmonic[std::size_t(2 * k)], std::sin(float(k) * phi), 2e-5f);
        }
    }
    // Along the axis: the constant alone.
    const AzimuthalHarmonics pole = AzimuthalHarmonics::of(frame.axis, frame, 4);
    EXPECT_EQ(pole.harmonic[1], 1.0f);
    EXPECT_EQ(pole.harmonic[2], 0.0f);
}

TEST(RadianceBasis, BinsCoverSinThetaEvenly) {
    RadianceBasis b;
    b.thetaBins = 16;
    EXPECT_EQ(b.bin(-1.0f), 0);
    EXPECT_EQ(b.bin(1.0f), 15);
    EXPECT_EQ(b.bin(0.0f), 8);
    for (int i = 0; i < b.thetaBins; ++i)
        EXPECT_EQ(b.bin(b.binCentre(i)), i);
    EXPECT_FLOAT_EQ(b.binWidth(), 0.125f);
}

TEST(RadianceBasis, InvalidSettingsNameTheKey) {
    RadianceBasis b;
    b.thetaBins = 1;
    EXPECT_THROW(
        {
            try {
                b.validate();
            } catch (const std::exception& e) {
                EXPECT_NE(std::string(e.what()).find("theta_bins"), std::string::npos);
                throw;
            }
        },
        std::exception);
    b.thetaBins = 16;
    b.azimuthalOrder = 9;
    EXPECT_THROW(b.validate(), std::exception);
}

/// ∫ f_s(ω_i, ω_o) cos θ_i L(ω_i) dω_i by an independent midpoint rule in
/// (θ_i, φ_i) on a fine grid (dω = cos θ dθ dφ), for the fiber along +y.
Rgb bruteForceOutgoing(const MarschnerBcsdf& bcsdf, float theta_o, float phi_o,
                       const std::function<float(float sinTheta, float phi)>& L) {
    const int nTheta = 480, nPhi = 480;
    Rgbd sum(0.0);
    for (int a = 0; a < nTheta; ++a) {
        const double theta = -PiOver2 + (a + 0.5) * Pi / nTheta;
        for (int b = 0; b < nPhi; ++b) {
            const double phi = -Pi + (b + 0.5) * TwoPi / nPhi;
            const LobeValues f = bcsdf.eval(
                FiberAngles::fromAngles(float(theta), theta_o, float(double(phi_o) - phi)));
            const double w = std::cos(theta) * std::cos(theta) * (Pi / nTheta) * (TwoPi / nPhi);
            sum += Rgbd(f.sum()) * (w * double(L(float(std::sin(theta)), float(phi))));
        }
    }
    return Rgb(sum);
}

TEST(ScatteringKernel, OutgoingRadianceMatchesAnIndependentQuadrature) {
    FiberParams params; // light hair: every lobe matters
    params.sigma_a = FiberParams::sigmaFromMelanin(0.3f, 0.1f);
    const MarschnerBcsdf bcsdf(params);
    RadianceBasis basis;
    basis.thetaBins = 16;
    basis.azimuthalOrder = 3;
    const ScatteringKernel kernel(bcsdf, basis);
    // A field the basis holds exactly: constant in s within each bin (a
    // function of the bin), with harmonics up to order 2 in φ.
    const auto field = [&](float s, float phi) {
        const float binShape = 1.0f + 0.5f * float(basis.bin(s)) / float(basis.thetaBins);
        return binShape * (1.0f + 0.5f * std::cos(phi) + 0.3f * std::sin(2.0f * phi));
    };
    const std::size_t perChannel = std::size_t(basis.coefficients());
    std::vector<float> incident(3 * perChannel, 0.0f), outgoing(3 * perChannel);
    const int perBin = basis.coefficientsPerBin();
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < basis.thetaBins; ++i) {
            float* a = incident.data() + std::size_t(c) * perChannel + std::size_t(i * perBin);
            const float binShape = 1.0f + 0.5f * float(i) / float(basis.thetaBins);
            a[0] = binShape;         // a_0
            a[1] = 0.5f * binShape;  // a_1: cos φ
            a[4] = 0.3f * binShape;  // b_2: sin 2φ
        }
    kernel.apply(incident, outgoing);
    const FiberFrame frame = FiberFrame::about(Vec3f(0, 1, 0));
    for (const int j : {3, 8, 13})
        for (const float phi_o : {0.0f, 2.5f}) {
            const float s_o = basis.binCentre(j);
            const float theta_o = std::asin(s_o);
            const Vec3f w = std::cos(theta_o) * (std::cos(phi_o) * frame.e1 + std::sin(phi_o) * frame.e2) +
                            s_o * frame.axis;
            const AzimuthalHarmonics h = AzimuthalHarmonics::of(w, frame, basis.azimuthalOrder);
            Rgb fromKernel(0.0f);
            for (int c = 0; c < 3; ++c)
                for (int m = 0; m < perBin; ++m)
                    fromKernel[c] += outgoing[std::size_t(c) * perChannel +
                                              std::size_t(j * perBin + m)] *
                                     h.harmonic[std::size_t(m)];
            const Rgb expected = bruteForceOutgoing(bcsdf, theta_o, phi_o, field);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(fromKernel[c], expected[c], 0.01f * expected[c] + 1e-4f)
                    << "channel " << c << ", theta_o " << degrees(theta_o) << ", phi_o " << phi_o;
        }
}

} // namespace
} // namespace hairvox
