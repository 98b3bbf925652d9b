// hairvox shading (internal): the per-point maths of the fiber model written
// once, across SIMD lanes (Google Highway, dispatched at run time to the
// widest instruction set the CPU has: AVX-512, AVX2+FMA, SSE4 or baseline).
//
// What lives here and nowhere else (docs/DESIGN.md §2–§5):
//  - the angles of a light/camera pair about a fiber (FiberAngles, §2);
//  - Marschner's f_s = Σ_p M_p(θ_h)·N_p(θ_d, φ)/cos²θ_d with N_p read from its
//    table (§3);
//  - the dual-scattering shader (Sadeghi & Tamstorf 2010 §2.3, as revised in
//    dual_scattering_shader.h): f_back^direct, f_back^scatter, f_s^scatter and
//    their combination with the global term.
// The scalar entry points (FiberAngles::fromDirections, MarschnerBcsdf::eval,
// DualScatteringShader::shade/fBack/fsScatter) are batches of one: a batch
// of the renderer and a test of one point run the same instructions.
//
// The kernel reads the tables through the views below (raw pointers into
// the objects that own them), and batches as structure of arrays: row r of a
// batch of capacity c holds its values for every point at [r·c, r·c + count).
#pragma once

#include <array>
#include <cstddef>

namespace hairvox::detail {

/// N_p sampled on a regular grid (MarschnerBcsdf's table): R and TT
/// interleaved, 4 floats per node [cos θ_d][φ][R, TT.r, TT.g, TT.b]; TRT
/// [cos θ_d][cos 2φ_h][φ][r, g, b]. φ ∈ [0, π], cos θ_d ∈ [0, 1], cos 2φ_h ∈ [−1, 1].
struct AzimuthalTableView {
    const float* rtt = nullptr;
    const float* trt = nullptr;
    int thetaCount = 0, phiCount = 0, eccCount = 0;
    float phiScale = 0; ///< grid index per radian of φ
};

/// What f_s needs: per lobe M_p = scale·exp(−(θ_h − α)²·invTwoVariance), and N_p.
struct MarschnerView {
    std::array<float, 3> alpha{}, variance{}, scale{}, invTwoVariance{};
    AzimuthalTableView N;
};

/// Rows of f_s per lobe: R, TT, TRT per channel (LobeValues' floats).
inline constexpr int kLobeRows = 9;

/// DualScatteringTables: rows of DualScatteringTables::Sample (27 floats, 9
/// RGB fields) over θ ∈ [−π/2, π/2], and N^G as LobeValues (9 floats) per
/// [row][φ node] with φ ∈ [0, π].
inline constexpr int kSampleFloats = 27;      ///< floats per Sample
inline constexpr int kSampleABar_b = 18;      ///< first float of Sample::ABar_b
inline constexpr int kSampleDeltaBar_b = 21;  ///< ... of Sample::DeltaBar_b
inline constexpr int kSampleSigma2Bar_b = 24; ///< ... of Sample::sigma2Bar_b
inline constexpr int kNGPhiNodes = 37;        ///< DualScatteringTables::kNGPhiSamples
struct DualScatteringTablesView {
    const float* rows = nullptr;
    const float* ng = nullptr;
    int rowCount = 0;
    float invStep = 0, lastIndex = 0;
};

struct ShadeKernelParams {
    MarschnerView fs;
    DualScatteringTablesView ds;
    float d_b = 1;
    /// The incident light's own longitudinal variance in θ_h (rad²), added to
    /// f_back's (fs's lobe variances carry it already): 0 for a directional light.
    float lightVariance = 0;
};

/// Rows of a batch of directions (unit vectors): ω_i, ω_o, u.
inline constexpr int kWiX = 0, kWiY = 1, kWiZ = 2, kWoX = 3, kWoY = 4, kWoZ = 5, kUX = 6, kUY = 7,
                     kUZ = 8, kDirectionRows = 9;

/// Rows of a batch of angles, FiberAngles' fields in order.
inline constexpr int kSinThetaI = 0, kCosThetaI = 1, kSinThetaO = 2, kCosThetaO = 3, kThetaI = 4,
                     kThetaO = 5, kThetaH = 6, kThetaD = 7, kCos2ThetaD = 8, kPhi = 9, kCosPhi = 10,
                     kCos2PhiH = 11, kAngleRows = 12;

/// Rows of a batch of global terms: V, then T_s and σ_f² per channel.
inline constexpr int kV = 0, kTsR = 1, kTsG = 2, kTsB = 3, kSigma2R = 4, kSigma2G = 5, kSigma2B = 6,
                     kGlobalTermRows = 7;

/// Rows of a shade result: ShadeResult's five RGB components in order
/// (directR, directTT, directTRT, backDirect, scatter), then — only when a
/// batch asks for them (ShadeOutputs::terms) — f_s^scatter(σ_f²) and
/// f_back(σ_f²) per channel, the terms before their weights.
inline constexpr int kShadeRows = 15;
inline constexpr int kShadeTermRows = 6;

/// Rows are padded to whole vectors of the widest target: a batch's
/// capacity is a multiple of this, and the kernel reads and writes whole
/// vectors up to count rounded up to it (the padding's values are ignored).
inline constexpr std::size_t kBatchAlignment = 16;

/// A batch: `count` points, rows `capacity` floats apart.
struct Batch {
    std::size_t count = 0, capacity = 0;
    const float* row(int r) const { return data + std::size_t(r) * capacity; }
    const float* data = nullptr;
};
struct MutableBatch {
    std::size_t count = 0, capacity = 0;
    float* row(int r) const { return data + std::size_t(r) * capacity; }
    float* data = nullptr;
};

// Batches (every lane of the widest vector).

/// Angles (kAngleRows) of directions (kDirectionRows).
void anglesFromDirections(const Batch& directions, const MutableBatch& angles);
/// f_s per lobe (kLobeRows) at the angles (kAngleRows).
void evalMarschner(const MarschnerView& fs, const Batch& angles, const MutableBatch& lobes);
/// The shader from directions: adds E·result to `radiance` (kShadeRows),
/// with E the irradiance per channel (3 rows).
void shadeDirections(const ShadeKernelParams& p, const Batch& directions, const Batch& globalTerms,
                     const Batch& irradiance, const MutableBatch& radiance);

// One point (one lane; the same code, the same bits): its rows as arrays.

void anglesFromDirection(const float* directions, float* angles);
void evalMarschner(const MarschnerView& fs, const float* angles, float* lobes);
void shadeDirection(const ShadeKernelParams& p, const float* directions, const float* globalTerm,
                    const float* irradiance, float* radiance);
/// The shader from angles (kAngleRows): `out` gets kShadeRows and then the
/// kShadeTermRows of f_s^scatter(σ_f²) and f_back(σ_f²).
void shadeAngle(const ShadeKernelParams& p, const float* angles, const float* globalTerm,
                float* out);

/// The instruction set the kernel dispatches to on this CPU (e.g. "AVX3", "AVX2").
const char* shadeKernelTarget();

} // namespace hairvox::detail
