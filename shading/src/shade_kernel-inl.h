// hairvox shading (internal): the body of shade_kernel.cpp, included there
// once per vector width inside a namespace that defines D, the Highway tag:
// every lane of the widest vector (batches) and one lane (single points).
// No include guard and no #include: it is included twice per SIMD target.
//
// Conventions are those of the headers whose functions this implements:
// marschner.h (angles, f_s), longitudinal.h (the lobe ½·g(x; σ), normalised
// over θ_o), dual_scattering_shader.h (the shader and its departures from
// the paper).
// Branches of the scalar code are lane masks here: a lane that the scalar
// code would skip computes finite values and is then zeroed, and a whole
// vector of skipped lanes skips the work (DESIGN.md §7).

namespace {

using V = hn::Vec<D>;
using DI = hn::RebindToSigned<D>;
using VI = hn::Vec<DI>;
using M = hn::Mask<D>;

constexpr float kPi = static_cast<float>(Pi);
constexpr float kPiOver2 = static_cast<float>(PiOver2);

V constant(float x) {
    return hn::Set(D(), x);
}

struct Vec3V {
    V x, y, z;
};
V dot(const Vec3V& a, const Vec3V& b) {
    return hn::MulAdd(a.x, b.x, hn::MulAdd(a.y, b.y, hn::Mul(a.z, b.z)));
}
Vec3V cross(const Vec3V& a, const Vec3V& b) {
    return {hn::NegMulAdd(a.z, b.y, hn::Mul(a.y, b.z)), hn::NegMulAdd(a.x, b.z, hn::Mul(a.z, b.x)),
            hn::NegMulAdd(a.y, b.x, hn::Mul(a.x, b.y))};
}
V clampUnit(V x) {
    return hn::Min(hn::Max(x, constant(-1.0f)), constant(1.0f));
}

/// cos θ from sin θ as sqrt((1 − s)(1 + s)): exact near |s| = 1.
V cosFromSin(V s) {
    const V one = constant(1.0f);
    return hn::Sqrt(hn::Max(hn::Mul(hn::Sub(one, s), hn::Add(one, s)), hn::Zero(D())));
}

/// asin(clamp(x, −1, 1)): Cephes asinf (S. Moshier), a degree-4 minimax
/// polynomial in z = x² on |x| ≤ ½ and asin x = π/2 − 2 asin sqrt((1 − x)/2)
/// above; peak relative error 2.5e-7 (tested through FiberAngles in
/// tests/shading/marschner_test.cpp).
V asin(V x) {
    const V a = hn::Min(hn::Abs(x), constant(1.0f));
    const M upper = hn::Gt(a, constant(0.5f));
    const V z =
        hn::IfThenElse(upper, hn::Mul(constant(0.5f), hn::Sub(constant(1.0f), a)), hn::Mul(a, a));
    const V s = hn::IfThenElse(upper, hn::Sqrt(z), a);
    V poly = constant(4.2163199048e-2f);
    poly = hn::MulAdd(poly, z, constant(2.4181311049e-2f));
    poly = hn::MulAdd(poly, z, constant(4.5470025998e-2f));
    poly = hn::MulAdd(poly, z, constant(7.4953002686e-2f));
    poly = hn::MulAdd(poly, z, constant(1.6666752422e-1f));
    const V r = hn::MulAdd(hn::Mul(poly, z), s, s);
    return hn::CopySign(
        hn::IfThenElse(upper, hn::NegMulAdd(constant(2.0f), r, constant(kPiOver2)), r), x);
}

/// Grid coordinate of x ∈ [0, maxIndex] (NaN and below 0 → 0): the cell index
/// (at most maxIndex − 1) and the fraction within it.
void gridCoordinate(V x, float maxIndex, VI& index, V& frac) {
    x = hn::IfThenElse(hn::Gt(x, hn::Zero(D())), hn::Min(x, constant(maxIndex)), hn::Zero(D()));
    index = hn::Min(hn::ConvertTo(DI(), x), hn::Set(DI(), static_cast<int>(maxIndex) - 1));
    frac = hn::Sub(x, hn::ConvertTo(D(), index));
}

V gather(const float* base, VI index) {
    return hn::GatherIndex(D(), base, index);
}
VI offset(VI index, int k) {
    return hn::Add(index, hn::Set(DI(), k));
}

struct Angles {
    V sinTheta_i, cosTheta_i, sinTheta_o, cosTheta_o, theta_i, theta_o, theta_h, theta_d,
        cos2Theta_d, phi, cosPhi, cos2Phi_h;
};

/// FiberAngles::fromDirections (marschner.h; DESIGN.md §2).
Angles anglesOf(const Vec3V& wi, const Vec3V& wo, const Vec3V& u, bool eccentric) {
    const V zero = hn::Zero(D()), one = constant(1.0f), half = constant(0.5f);
    Angles a;
    a.sinTheta_i = clampUnit(dot(wi, u));
    a.sinTheta_o = clampUnit(dot(wo, u));
    a.cosTheta_i = cosFromSin(a.sinTheta_i);
    a.cosTheta_o = cosFromSin(a.sinTheta_o);
    a.theta_i = asin(a.sinTheta_i);
    a.theta_o = asin(a.sinTheta_o);
    a.theta_h = hn::Mul(half, hn::Add(a.theta_i, a.theta_o));
    a.theta_d = hn::Mul(half, hn::Sub(a.theta_o, a.theta_i));
    // cos²θ_d = (1 + cos(θ_o − θ_i))/2, floored at FiberAngles::kMinCos2Theta_d.
    a.cos2Theta_d =
        hn::Max(hn::Mul(half, hn::Add(one, hn::MulAdd(a.cosTheta_i, a.cosTheta_o,
                                                      hn::Mul(a.sinTheta_i, a.sinTheta_o)))),
                constant(1e-7f));
    // u·(ω_i × ω_o) and ω_i·ω_o − sin θ_i sin θ_o are |ω_i⊥||ω_o⊥| sin φ and cos φ.
    const V sinPhi = dot(u, cross(wi, wo));
    const V cosPhiRaw = hn::NegMulAdd(a.sinTheta_i, a.sinTheta_o, dot(wi, wo));
    const V r2 = hn::MulAdd(sinPhi, sinPhi, hn::Mul(cosPhiRaw, cosPhiRaw));
    const M defined = hn::Gt(r2, zero);
    const V invR = hn::Div(one, hn::Sqrt(hn::IfThenElse(defined, r2, one)));
    const V cosPhi = clampUnit(hn::Mul(cosPhiRaw, invR));
    // |φ| from whichever of asin(|sin φ|), acos(cos φ) is well conditioned.
    const M nearHalfPi = hn::Lt(hn::Abs(cosPhi), constant(0.7f));
    const V r =
        asin(hn::IfThenElse(nearHalfPi, cosPhi, hn::Min(hn::Mul(hn::Abs(sinPhi), invR), one)));
    const V magnitude =
        hn::IfThenElse(nearHalfPi, hn::Sub(constant(kPiOver2), r),
                       hn::IfThenElse(hn::Gt(cosPhi, zero), r, hn::Sub(constant(kPi), r)));
    a.cosPhi = hn::IfThenElse(defined, cosPhi, one);
    a.phi = hn::IfThenElseZero(defined, hn::CopySign(magnitude, sinPhi));
    a.cos2Phi_h = one;
    if (eccentric) {
        // The cross-section's axes: coordinateSystem(u) (core/vecmath.h).
        const V sign = hn::CopySign(one, u.z);
        const V k = hn::Div(constant(-1.0f), hn::Add(sign, u.z));
        const V b = hn::Mul(hn::Mul(u.x, u.y), k);
        const Vec3V s{hn::MulAdd(hn::Mul(sign, hn::Mul(u.x, u.x)), k, one), hn::Mul(sign, b),
                      hn::Neg(hn::Mul(sign, u.x))};
        const Vec3V t{b, hn::MulAdd(hn::Mul(u.y, u.y), k, sign), hn::Neg(u.y)};
        const V den = hn::Mul(a.cosTheta_i, a.cosTheta_o);
        const M positive = hn::Gt(den, zero);
        const V value =
            hn::Div(hn::Sub(hn::Mul(dot(wi, s), dot(wo, s)), hn::Mul(dot(wi, t), dot(wo, t))),
                    hn::IfThenElse(positive, den, one));
        a.cos2Phi_h = hn::IfThenElse(positive, clampUnit(value), one);
    }
    return a;
}

struct Rgb3 {
    V r, g, b;
};
Rgb3 operator*(const Rgb3& a, const Rgb3& b) {
    return {hn::Mul(a.r, b.r), hn::Mul(a.g, b.g), hn::Mul(a.b, b.b)};
}
Rgb3 operator*(const Rgb3& a, V s) {
    return {hn::Mul(a.r, s), hn::Mul(a.g, s), hn::Mul(a.b, s)};
}
Rgb3 operator+(const Rgb3& a, const Rgb3& b) {
    return {hn::Add(a.r, b.r), hn::Add(a.g, b.g), hn::Add(a.b, b.b)};
}
Rgb3 zeroUnless(M m, const Rgb3& a) {
    return {hn::IfThenElseZero(m, a.r), hn::IfThenElseZero(m, a.g), hn::IfThenElseZero(m, a.b)};
}
Rgb3 splat(V x) {
    return {x, x, x};
}

struct Lobes {
    Rgb3 R, TT, TRT;
    Rgb3& operator[](int p) { return p == 0 ? R : (p == 1 ? TT : TRT); }
    const Rgb3& operator[](int p) const { return p == 0 ? R : (p == 1 ? TT : TRT); }
};

/// The longitudinal lobe ½·g(x; √variance) (longitudinal.h), variance > 0.
V longitudinalLobe(V x, V variance) {
    const V scale = hn::Sqrt(
        hn::Div(constant(1.0f), hn::Mul(constant(static_cast<float>(8.0 * Pi)), variance)));
    return hn::Mul(scale,
                   hn::Exp(D(), hn::Div(hn::Neg(hn::Mul(x, x)), hn::Add(variance, variance))));
}
Rgb3 longitudinalLobe(const Rgb3& x, const Rgb3& variance) {
    return {longitudinalLobe(x.r, variance.r), longitudinalLobe(x.g, variance.g),
            longitudinalLobe(x.b, variance.b)};
}

/// N_p from the table, bilinear in (cos θ_d, |φ|), and linear in cos 2φ_h for
/// eccentric TRT (MarschnerBcsdf's table).
Lobes azimuthal(const AzimuthalTableView& t, const Angles& a) {
    const V one = constant(1.0f);
    VI i, j;
    V fx, fy;
    gridCoordinate(hn::Mul(hn::Sqrt(a.cos2Theta_d), constant(float(t.thetaCount - 1))),
                   float(t.thetaCount - 1), i, fx);
    gridCoordinate(hn::Mul(hn::Abs(a.phi), constant(t.phiScale)), float(t.phiCount - 1), j, fy);
    const V w00 = hn::Mul(hn::Sub(one, fx), hn::Sub(one, fy)), w01 = hn::Mul(hn::Sub(one, fx), fy);
    const V w10 = hn::Mul(fx, hn::Sub(one, fy)), w11 = hn::Mul(fx, fy);
    const auto bilinear = [&](const float* base, VI node, int rowStride, int nodeStride, int c) {
        const VI a0 = offset(node, c), b0 = offset(node, rowStride + c);
        return hn::MulAdd(
            w00, gather(base, a0),
            hn::MulAdd(w01, gather(base, offset(a0, nodeStride)),
                       hn::MulAdd(w10, gather(base, b0),
                                  hn::Mul(w11, gather(base, offset(b0, nodeStride))))));
    };
    const VI nPhi = hn::Set(DI(), t.phiCount);
    const VI node = hn::Mul(hn::Add(hn::Mul(i, nPhi), j), hn::Set(DI(), 4));
    Lobes n;
    n.R = splat(bilinear(t.rtt, node, t.phiCount * 4, 4, 0));
    n.TT = {bilinear(t.rtt, node, t.phiCount * 4, 4, 1),
            bilinear(t.rtt, node, t.phiCount * 4, 4, 2),
            bilinear(t.rtt, node, t.phiCount * 4, 4, 3)};
    const int sliceStride = t.phiCount * 3, rowStride = t.eccCount * sliceStride;
    const auto trtSlice = [&](VI k) {
        const VI base = hn::Add(hn::Mul(hn::Add(hn::Mul(i, hn::Set(DI(), t.eccCount)), k),
                                        hn::Mul(nPhi, hn::Set(DI(), 3))),
                                hn::Mul(j, hn::Set(DI(), 3)));
        return Rgb3{bilinear(t.trt, base, rowStride, 3, 0), bilinear(t.trt, base, rowStride, 3, 1),
                    bilinear(t.trt, base, rowStride, 3, 2)};
    };
    if (t.eccCount == 1) {
        n.TRT = trtSlice(hn::Zero(DI()));
    } else {
        VI k;
        V fz;
        gridCoordinate(hn::Mul(hn::Mul(constant(0.5f), hn::Add(a.cos2Phi_h, one)),
                               constant(float(t.eccCount - 1))),
                       float(t.eccCount - 1), k, fz);
        const Rgb3 lo = trtSlice(k), hi = trtSlice(offset(k, 1));
        n.TRT = lo * hn::Sub(one, fz) + hi * fz;
    }
    return n;
}

/// f_s per lobe: n_p·M_p(θ_h)/cos²θ_d (marschner.h).
Lobes marschner(const MarschnerView& fs, const Angles& a) {
    Lobes f = azimuthal(fs.N, a);
    const V invCos2Theta_d = hn::Div(constant(1.0f), a.cos2Theta_d);
    for (int p = 0; p < 3; ++p) {
        const auto up = static_cast<std::size_t>(p);
        const V x = hn::Sub(a.theta_h, constant(fs.alpha[up]));
        const V M_p =
            hn::Mul(constant(fs.scale[up]),
                    hn::Exp(D(), hn::Mul(hn::Neg(hn::Mul(x, x)), constant(fs.invTwoVariance[up]))));
        f[p] = f[p] * hn::Mul(M_p, invCos2Theta_d);
    }
    return f;
}

/// A row of the dual-scattering tables at θ: index of the row below and the fraction.
struct TableLocation {
    VI row;
    V t;
};
TableLocation locate(const DualScatteringTablesView& ds, V theta) {
    V x = hn::Mul(hn::Add(theta, constant(kPiOver2)), constant(ds.invStep));
    x = hn::IfThenElse(hn::Gt(x, hn::Zero(D())), hn::Min(x, constant(ds.lastIndex)), hn::Zero(D()));
    const VI row = hn::Min(hn::ConvertTo(DI(), x), hn::Set(DI(), ds.rowCount - 2));
    return {row, hn::Sub(x, hn::ConvertTo(D(), row))};
}

Rgb3 interpolateRow(const DualScatteringTablesView& ds, const TableLocation& l, int field) {
    const VI a = hn::Add(hn::Mul(l.row, hn::Set(DI(), kSampleFloats)), hn::Set(DI(), field));
    const VI b = offset(a, kSampleFloats);
    Rgb3 v;
    V* channels[3] = {&v.r, &v.g, &v.b};
    for (int c = 0; c < 3; ++c) {
        const V lo = gather(ds.rows, offset(a, c)), hi = gather(ds.rows, offset(b, c));
        *channels[c] = hn::MulAdd(l.t, hn::Sub(hi, lo), lo);
    }
    return v;
}

/// N^G_p(θ_d, φ), bilinear (DualScatteringTables::NG); φ ∈ [−π, π].
Lobes globalAzimuthal(const DualScatteringTablesView& ds, const Angles& a) {
    constexpr int nodes = kNGPhiNodes;
    const TableLocation l = locate(ds, a.theta_d);
    V x = hn::Mul(hn::Abs(a.phi), constant(float(double(nodes - 1) / Pi)));
    x = hn::IfThenElse(hn::Gt(x, hn::Zero(D())), hn::Min(x, constant(float(nodes - 1))),
                       hn::Zero(D()));
    const VI j = hn::Min(hn::ConvertTo(DI(), x), hn::Set(DI(), nodes - 2));
    const V s = hn::Sub(x, hn::ConvertTo(D(), j));
    const VI a0 =
        hn::Mul(hn::Add(hn::Mul(l.row, hn::Set(DI(), nodes)), j), hn::Set(DI(), kLobeRows));
    const VI b0 = offset(a0, nodes * kLobeRows);
    Lobes v;
    for (int p = 0; p < 3; ++p) {
        V* channels[3] = {&v[p].r, &v[p].g, &v[p].b};
        for (int c = 0; c < 3; ++c) {
            const int k = 3 * p + c;
            const V lo0 = gather(ds.ng, offset(a0, k)),
                    lo1 = gather(ds.ng, offset(a0, k + kLobeRows));
            const V hi0 = gather(ds.ng, offset(b0, k)),
                    hi1 = gather(ds.ng, offset(b0, k + kLobeRows));
            const V lo = hn::MulAdd(s, hn::Sub(lo1, lo0), lo0),
                    hi = hn::MulAdd(s, hn::Sub(hi1, hi0), hi0);
            *channels[c] = hn::MulAdd(l.t, hn::Sub(hi, lo), lo);
        }
    }
    return v;
}

struct Backscatter {
    Rgb3 ABar_b, DeltaBar_b, sigma2Bar_b;
};

/// f_back = Ā_b·S̄_b(θ_h, φ; σ̄_b² + σ²)/cos²θ_d with S̄_b = ½·g(θ_h − Δ̄_b)·½ max(cos φ, 0).
Rgb3 fBack(const Angles& a, const Backscatter& b, const Rgb3& sigma2) {
    const V azimuthal = hn::Mul(constant(0.5f), hn::Max(a.cosPhi, hn::Zero(D())));
    const Rgb3 shift{hn::Sub(a.theta_h, b.DeltaBar_b.r), hn::Sub(a.theta_h, b.DeltaBar_b.g),
                     hn::Sub(a.theta_h, b.DeltaBar_b.b)};
    const Rgb3 longitudinal = longitudinalLobe(shift, b.sigma2Bar_b + sigma2);
    return zeroUnless(hn::Gt(azimuthal, hn::Zero(D())),
                      b.ABar_b * longitudinal * hn::Div(azimuthal, a.cos2Theta_d));
}

/// f_s^scatter = Σ_p ½·g(θ_h − α_p; sqrt(β_p² + σ_f²))·N^G_p(θ_d, φ)/cos²θ_d.
Rgb3 fsScatter(const ShadeKernelParams& p, const Angles& a, const Rgb3& sigma2_f) {
    const Lobes ng = globalAzimuthal(p.ds, a);
    Rgb3 sum = splat(hn::Zero(D()));
    for (int lobe = 0; lobe < 3; ++lobe) {
        const auto up = static_cast<std::size_t>(lobe);
        const V x = hn::Sub(a.theta_h, constant(p.fs.alpha[up]));
        const V beta2 = constant(p.fs.variance[up]);
        const Rgb3 variance{hn::Add(beta2, sigma2_f.r), hn::Add(beta2, sigma2_f.g),
                            hn::Add(beta2, sigma2_f.b)};
        sum = sum + ng[lobe] * longitudinalLobe(splat(x), variance);
    }
    return sum * hn::Div(constant(1.0f), a.cos2Theta_d);
}

struct GlobalTermV {
    V V_;
    Rgb3 T_s, sigma2_f;
};

struct ShadeV {
    Rgb3 directR, directTT, directTRT, backDirect, scatter;
    Rgb3 fsScatterTerm, fBackTerm; ///< before weights (ShadeOutputs::terms)
};

/// DualScatteringShader::shade (dual_scattering_shader.h).
ShadeV shade(const ShadeKernelParams& p, const Angles& a, const GlobalTermV& g, bool terms) {
    const V zero = hn::Zero(D());
    const Rgb3 none = splat(zero);
    ShadeV r{none, none, none, none, none, none, none};
    const M direct = hn::And(hn::Gt(a.cosTheta_i, zero), hn::Gt(g.V_, zero));
    const M scatter = hn::And(
        hn::Gt(a.cosTheta_i, zero),
        hn::Or(hn::Ne(g.T_s.r, zero), hn::Or(hn::Ne(g.T_s.g, zero), hn::Ne(g.T_s.b, zero))));
    if (hn::AllFalse(D(), hn::Or(direct, scatter)) && !terms)
        return r;
    const TableLocation l = locate(p.ds, a.theta_i);
    const Backscatter b{interpolateRow(p.ds, l, kSampleABar_b),
                        interpolateRow(p.ds, l, kSampleDeltaBar_b),
                        interpolateRow(p.ds, l, kSampleSigma2Bar_b)};
    if (!hn::AllFalse(D(), direct)) {
        const V w = hn::Mul(g.V_, a.cosTheta_i);
        const Lobes f = marschner(p.fs, a);
        r.directR = zeroUnless(direct, f.R * w);
        r.directTT = zeroUnless(direct, f.TT * w);
        r.directTRT = zeroUnless(direct, f.TRT * w);
        r.backDirect = zeroUnless(direct, fBack(a, b, splat(constant(p.lightVariance))) *
                                              hn::Mul(constant(p.d_b), w));
    }
    if (!hn::AllFalse(D(), scatter) || terms) {
        const Rgb3 sigma2_f{hn::Max(g.sigma2_f.r, zero), hn::Max(g.sigma2_f.g, zero),
                            hn::Max(g.sigma2_f.b, zero)};
        const Rgb3 fs = fsScatter(p, a, sigma2_f);
        const Rgb3 back = fBack(a, b, sigma2_f + splat(constant(p.lightVariance)));
        r.scatter = zeroUnless(scatter, g.T_s * (fs + back * constant(kPi * p.d_b)) * a.cosTheta_i);
        r.fsScatterTerm = fs;
        r.fBackTerm = back;
    }
    return r;
}

V load(const Batch& b, int row, std::size_t i) {
    return hn::LoadU(D(), b.row(row) + i);
}
void store(const MutableBatch& b, int row, std::size_t i, V v) {
    hn::StoreU(v, D(), b.row(row) + i);
}
void store(const MutableBatch& b, int row, std::size_t i, const Rgb3& v) {
    store(b, row, i, v.r);
    store(b, row + 1, i, v.g);
    store(b, row + 2, i, v.b);
}

Angles loadAngles(const Batch& b, std::size_t i) {
    return {load(b, kSinThetaI, i), load(b, kCosThetaI, i), load(b, kSinThetaO, i),
            load(b, kCosThetaO, i), load(b, kThetaI, i),    load(b, kThetaO, i),
            load(b, kThetaH, i),    load(b, kThetaD, i),    load(b, kCos2ThetaD, i),
            load(b, kPhi, i),       load(b, kCosPhi, i),    load(b, kCos2PhiH, i)};
}

Angles loadDirections(const Batch& b, std::size_t i, bool eccentric) {
    const Vec3V wi{load(b, kWiX, i), load(b, kWiY, i), load(b, kWiZ, i)};
    const Vec3V wo{load(b, kWoX, i), load(b, kWoY, i), load(b, kWoZ, i)};
    const Vec3V u{load(b, kUX, i), load(b, kUY, i), load(b, kUZ, i)};
    return anglesOf(wi, wo, u, eccentric);
}

GlobalTermV loadGlobalTerm(const Batch& b, std::size_t i) {
    return {load(b, kV, i),
            {load(b, kTsR, i), load(b, kTsG, i), load(b, kTsB, i)},
            {load(b, kSigma2R, i), load(b, kSigma2G, i), load(b, kSigma2B, i)}};
}

/// radiance += E·r, component by component.
void accumulateShade(const MutableBatch& radiance, std::size_t i, const ShadeV& r, const Rgb3& E) {
    const Rgb3* components[5] = {&r.directR, &r.directTT, &r.directTRT, &r.backDirect, &r.scatter};
    const V* e[3] = {&E.r, &E.g, &E.b};
    for (int k = 0; k < 5; ++k) {
        const V* c[3] = {&components[k]->r, &components[k]->g, &components[k]->b};
        for (int ch = 0; ch < 3; ++ch) {
            float* row = radiance.row(3 * k + ch) + i;
            hn::StoreU(hn::MulAdd(*e[ch], *c[ch], hn::LoadU(D(), row)), D(), row);
        }
    }
}

void storeShade(const MutableBatch& out, std::size_t i, const ShadeV& r, bool terms) {
    store(out, 0, i, r.directR);
    store(out, 3, i, r.directTT);
    store(out, 6, i, r.directTRT);
    store(out, 9, i, r.backDirect);
    store(out, 12, i, r.scatter);
    if (terms) {
        store(out, kShadeRows, i, r.fsScatterTerm);
        store(out, kShadeRows + 3, i, r.fBackTerm);
    }
}

} // namespace

// The entry points (shade_kernel.h), for batches whose rows hold whole
// vectors of D.

void anglesFromDirections(const Batch& directions, const MutableBatch& angles) {
    const std::size_t lanes = hn::Lanes(D());
    for (std::size_t i = 0; i < directions.count; i += lanes) {
        const Angles a = loadDirections(directions, i, true);
        const V rows[kAngleRows] = {a.sinTheta_i,  a.cosTheta_i, a.sinTheta_o, a.cosTheta_o,
                                    a.theta_i,     a.theta_o,    a.theta_h,    a.theta_d,
                                    a.cos2Theta_d, a.phi,        a.cosPhi,     a.cos2Phi_h};
        for (int r = 0; r < kAngleRows; ++r)
            store(angles, r, i, rows[r]);
    }
}

void evalMarschner(const MarschnerView& fs, const Batch& angles, const MutableBatch& lobes) {
    const std::size_t lanes = hn::Lanes(D());
    for (std::size_t i = 0; i < angles.count; i += lanes) {
        const Lobes f = marschner(fs, loadAngles(angles, i));
        store(lobes, 0, i, f.R);
        store(lobes, 3, i, f.TT);
        store(lobes, 6, i, f.TRT);
    }
}

void shadeDirections(const ShadeKernelParams& p, const Batch& directions, const Batch& globalTerms,
                     const Batch& irradiance, const MutableBatch& radiance) {
    const std::size_t lanes = hn::Lanes(D());
    const bool eccentric = p.fs.N.eccCount > 1;
    for (std::size_t i = 0; i < directions.count; i += lanes) {
        const ShadeV r = shade(p, loadDirections(directions, i, eccentric),
                               loadGlobalTerm(globalTerms, i), false);
        accumulateShade(radiance, i, r,
                        {load(irradiance, 0, i), load(irradiance, 1, i), load(irradiance, 2, i)});
    }
}

void shadeAngles(const ShadeKernelParams& p, const Batch& angles, const Batch& globalTerms,
                 const MutableBatch& out, bool terms) {
    const std::size_t lanes = hn::Lanes(D());
    for (std::size_t i = 0; i < angles.count; i += lanes)
        storeShade(out, i, shade(p, loadAngles(angles, i), loadGlobalTerm(globalTerms, i), terms),
                   terms);
}
