#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/core/rng.h>
#include <hairvox/strands/procedural.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace hairvox {

std::uint32_t ProceduralGroomParams::resolvedPointsPerStrand() const {
    if (pointsPerStrand != 0)
        return pointsPerStrand;
    return style == GroomStyle::Curly ? 64u : 32u;
}

namespace {

template <typename T>
void requireRange(const char* name, T value, T lo, T hi) {
    if (!(value >= lo && value <= hi))
        throw InputError(strCat("procedural groom: ", name, " = ", value,
                                " should be in the range [", lo, ", ", hi, "]"));
}

} // namespace

void ProceduralGroomParams::validate() const {
    requireRange("strands", strands, 1u, 10'000'000u);
    requireRange("points per strand", resolvedPointsPerStrand(), 2u, 4096u);
    if (!isFinite(headCenter))
        throw InputError("procedural groom: head centre must be finite");
    requireRange("head radius", headRadius, 1e-4f, 1e3f);
    requireRange("length", length, 1e-4f, 1e3f);
    requireRange("length variation", lengthVariation, 0.0f, 0.9f);
    requireRange("wave amplitude", waveAmplitude, 0.0f, 1e2f);
    requireRange("wave length", waveLength, 1e-5f, 1e3f);
    requireRange("curl radius", curlRadius, 0.0f, 1e2f);
    requireRange("curl pitch", curlPitch, 1e-5f, 1e3f);
    requireRange("clump strength", clumpStrength, 0.0f, 1.0f);
    requireRange("colours", colors.size(), std::size_t(0), kMaxFiberTypes);
    for (const Rgb& c : colors)
        for (int k = 0; k < 3; ++k)
            requireRange("colour channel", c[k], 0.0f, 1.0f);
}

std::ostream& operator<<(std::ostream& os, const ProceduralGroomParams& p) {
    return os << "ProceduralGroomParams(style=" << toString(p.style) << ", strands=" << p.strands
              << ", pointsPerStrand=" << p.resolvedPointsPerStrand() << ", seed=" << p.seed
              << ", headRadius=" << p.headRadius << ", length=" << p.length << ")";
}

namespace {

constexpr Vec3f kUp(0.0f, 1.0f, 0.0f);
constexpr Vec3f kForward(0.0f, 0.0f, 1.0f); // the face looks towards +z

/// Scalp mask: the hairline is high at the forehead, at ear level on the
/// sides and low at the nape. `d` is a unit direction from the head centre.
bool onScalp(const Vec3f& d) {
    const float horizontal = std::sqrt(d.x * d.x + d.z * d.z);
    const float front = horizontal > 1e-6f ? d.z / horizontal : 0.0f; // +1 face, −1 nape
    const float hairline =
        front >= 0 ? 0.05f + 0.45f * front * std::sqrt(front) : 0.05f + 0.5f * front;
    return d.y > hairline;
}

/// `count` root directions spread evenly over the scalp: a jittered Fibonacci
/// lattice on the sphere, grown until enough points fall on the scalp, then
/// thinned with a uniform stride (so that no region is favoured).
std::vector<Vec3f> scalpDirections(std::uint32_t count, std::uint64_t seed) {
    constexpr double goldenAngle = 2.39996322972865332;
    auto lattice = static_cast<std::uint64_t>(count) * 2 + 8;
    std::vector<Vec3f> accepted;
    for (;;) {
        accepted.clear();
        Pcg32 rng(seed, 0x5ca1b);
        const auto n = static_cast<double>(lattice);
        for (std::uint64_t i = 0; i < lattice; ++i) {
            const double y = 1.0 - 2.0 * (static_cast<double>(i) + rng.uniformDouble()) / n;
            const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
            const double phi = static_cast<double>(i) * goldenAngle + 0.5 * rng.uniformDouble();
            const Vec3f d(static_cast<float>(r * std::cos(phi)), static_cast<float>(y),
                          static_cast<float>(r * std::sin(phi)));
            if (onScalp(d))
                accepted.push_back(d);
        }
        if (accepted.size() >= count)
            break;
        lattice = lattice * count / std::max<std::uint64_t>(accepted.size(), 1) + 16;
    }
    std::vector<Vec3f> roots(count);
    for (std::uint64_t k = 0; k < count; ++k)
        roots[k] = accepted[k * accepted.size() / count];
    return roots;
}

/// A standard normal variate (Box–Muller).
float normalVariate(Pcg32& rng) {
    const float u1 = std::max(rng.uniformFloat(), 1e-7f), u2 = rng.uniformFloat();
    return std::sqrt(-2.0f * std::log(u1)) * std::cos(static_cast<float>(TwoPi) * u2);
}

struct HeadSphere {
    Vec3f center;
    float radius;

    /// Moves p radially out of the sphere of radius `r` around the centre.
    Vec3f pushOut(const Vec3f& p, float r) const {
        const Vec3f q = p - center;
        const float len = glm::length(q);
        return len >= r ? p : center + r * normalizeOr(q, kUp);
    }
};

/// The gravity-shaped centreline of one strand: it leaves the scalp at a
/// shallow angle, combed back and down, bends downwards and slides over the
/// head (collision with a per-strand layer sphere, which gives the hair volume).
std::vector<Vec3f> growCentreline(const HeadSphere& head, const Vec3f& rootDir, float length,
                                  std::uint32_t points, Pcg32& rng) {
    std::vector<Vec3f> line(points);
    const float step = length / static_cast<float>(points - 1);
    const float layer = head.radius * (1.01f + 0.05f * rng.uniformFloat());
    // Comb direction: "back and down" projected onto the scalp's tangent plane.
    const Vec3f combTarget = -kForward - 0.6f * kUp;
    const Vec3f comb = normalizeOr(combTarget - glm::dot(combTarget, rootDir) * rootDir, -kForward);
    // One draw per statement: the evaluation order of constructor arguments is
    // unspecified (GCC and Clang differ), and a groom must not depend on the
    // compiler. z, y, x is the order GCC used, so existing grooms keep their points.
    const float tiltZ = normalVariate(rng);
    const float tiltY = normalVariate(rng);
    const float tiltX = normalVariate(rng);
    Vec3f tilt(tiltX, tiltY, tiltZ);
    tilt -= glm::dot(tilt, rootDir) * rootDir;
    Vec3f dir =
        normalizeOr(comb + (0.15f + 0.15f * rng.uniformFloat()) * rootDir + 0.2f * tilt, rootDir);
    // Bending rate towards −y, per unit length: stiffer hair falls later.
    const float bend = 2.5f / head.radius;
    line[0] = head.center + head.radius * rootDir;
    for (std::uint32_t k = 1; k < points; ++k) {
        dir = normalizeOr(dir - bend * step * kUp, dir);
        const Vec3f p = head.pushOut(line[k - 1] + step * dir, layer);
        dir = normalizeOr(p - line[k - 1], dir);
        line[k] = head.pushOut(line[k - 1] + step * dir, layer);
    }
    return line;
}

/// Unit tangents at the points of a polyline (central differences).
std::vector<Vec3f> tangents(const std::vector<Vec3f>& line) {
    std::vector<Vec3f> t(line.size());
    for (std::size_t k = 0; k < line.size(); ++k) {
        const Vec3f& a = line[k == 0 ? 0 : k - 1];
        const Vec3f& b = line[std::min(k + 1, line.size() - 1)];
        t[k] = normalizeOr(b - a, k > 0 ? t[k - 1] : kUp);
    }
    return t;
}

/// Per-clump look shared by its strands so that locks move together.
struct ClumpLook {
    float phase;     ///< wave/curl phase, radians
    float frameTurn; ///< rotation of the wave plane about the root tangent
    float scale;     ///< multiplies wave length / curl radius
};

/// Adds the wave or curl of `style` around a centreline, in a parallel-transport
/// frame (rotation-minimising, so the offset plane does not twist).
void addStyleOffsets(std::vector<Vec3f>& line, const ProceduralGroomParams& params,
                     const ClumpLook& look, float strandPhase) {
    if (params.style == GroomStyle::Straight)
        return;
    const std::vector<Vec3f> t = tangents(line);
    Vec3f n0, b0;
    coordinateSystem(t[0], n0, b0);
    Vec3f n = std::cos(look.frameTurn) * n0 + std::sin(look.frameTurn) * b0;
    float s = 0;
    const std::vector<Vec3f> centre = line;
    for (std::size_t k = 0; k < line.size(); ++k) {
        if (k > 0) {
            s += glm::distance(centre[k], centre[k - 1]);
            n = normalizeOr(n - glm::dot(n, t[k]) * t[k], n); // parallel transport
        }
        const Vec3f b = glm::cross(t[k], n);
        const float phase = look.phase + strandPhase;
        if (params.style == GroomStyle::Wavy) {
            const float amplitude = params.waveAmplitude * smoothStep(0.0f, 0.08f, s);
            const float angle = static_cast<float>(TwoPi) * s / (params.waveLength * look.scale);
            line[k] = centre[k] + amplitude * std::sin(angle + phase) * n;
        } else {
            const float radius = params.curlRadius * look.scale * smoothStep(0.0f, 0.02f, s);
            const float angle = static_cast<float>(TwoPi) * s / params.curlPitch;
            line[k] =
                centre[k] + radius * (std::cos(angle + phase) * n + std::sin(angle + phase) * b);
        }
    }
}

/// Fiber length per unit of centreline length for the style (1 unless curly).
float lengthFactor(const ProceduralGroomParams& params) {
    if (params.style != GroomStyle::Curly)
        return 1.0f;
    const float turn = static_cast<float>(TwoPi) * params.curlRadius / params.curlPitch;
    return std::sqrt(1.0f + turn * turn);
}

} // namespace

Groom generateGroom(const ProceduralGroomParams& params) {
    params.validate();
    const std::uint32_t points = params.resolvedPointsPerStrand();
    // Points are indexed by 32 bits (Groom::strandStart); a scene caps them
    // lower (pipeline's kMaxProceduralPoints), a library caller may not.
    if (const std::uint64_t total = std::uint64_t(params.strands) * points;
        total > std::numeric_limits<std::uint32_t>::max())
        throw InputError(strCat("procedural groom: ", params.strands, " strands × ", points,
                                " points = ", total,
                                " points, more than the 4,294,967,295 a groom can index"));
    const HeadSphere head{params.headCenter, params.headRadius};
    const float centrelineLength = params.length / lengthFactor(params);

    const std::vector<Vec3f> roots = scalpDirections(params.strands, params.seed);

    // Clumps: every `perClump`-th root is a clump centre with its own guide strand.
    const std::uint32_t clumpCount = std::max(1u, params.strands / 48u);
    std::vector<Vec3f> clumpDirs(clumpCount);
    std::vector<std::vector<Vec3f>> guides(clumpCount);
    std::vector<ClumpLook> looks(clumpCount);
    for (std::uint32_t c = 0; c < clumpCount; ++c) {
        Pcg32 rng(params.seed, 0xc1u + 2ull * c);
        clumpDirs[c] = roots[std::uint64_t(c) * params.strands / clumpCount];
        guides[c] = growCentreline(head, clumpDirs[c], centrelineLength, points, rng);
        looks[c] = {static_cast<float>(TwoPi) * rng.uniformFloat(),
                    static_cast<float>(TwoPi) * rng.uniformFloat(),
                    0.85f + 0.3f * rng.uniformFloat()};
    }
    // Each clump's colour, from a stream of its own (the geometry's are untouched).
    std::vector<Rgb> clumpColor;
    for (std::uint32_t c = 0; c < clumpCount && !params.colors.empty(); ++c) {
        Pcg32 rng(params.seed, 0xc0105ull + 2ull * c);
        clumpColor.push_back(params.colors[std::min<std::size_t>(
            static_cast<std::size_t>(rng.uniformFloat() * float(params.colors.size())),
            params.colors.size() - 1)]);
    }

    // Every strand has `points` points and a random stream of its own: they
    // are grown in parallel into their places (the same bytes for any thread count).
    Groom groom;
    groom.points.resize(std::size_t(params.strands) * points);
    groom.strandStart.resize(std::size_t(params.strands) + 1);
    for (std::uint32_t i = 0; i <= params.strands; ++i)
        groom.strandStart[i] = i * points;
    if (!clumpColor.empty())
        groom.color.resize(groom.points.size());
    tbb::parallel_for(std::uint32_t(0), params.strands, [&](std::uint32_t i) {
        Pcg32 rng(params.seed, 0x57a4dull + 2ull * i);
        const Vec3f& root = roots[i];
        std::uint32_t clump = 0;
        float best = -2.0f;
        for (std::uint32_t c = 0; c < clumpCount; ++c) {
            const float d = glm::dot(root, clumpDirs[c]);
            if (d > best) {
                best = d;
                clump = c;
            }
        }
        const float variation =
            std::clamp(1.0f + params.lengthVariation * normalVariate(rng), 0.2f, 2.0f);
        std::vector<Vec3f> line =
            growCentreline(head, root, centrelineLength * variation, points, rng);
        // Draw the strand towards its clump's guide, more so towards the tip.
        const std::vector<Vec3f>& guide = guides[clump];
        for (std::uint32_t k = 1; k < points; ++k) {
            const float u = static_cast<float>(k) / static_cast<float>(points - 1);
            const float w = params.clumpStrength * u * std::sqrt(u);
            const Vec3f target = guide[k] + (line[0] - guide[0]) * (1.0f - u);
            line[k] = lerp(w, line[k], target);
        }
        addStyleOffsets(line, params, looks[clump], 0.15f * normalVariate(rng));
        const std::size_t first = std::size_t(i) * points;
        for (std::uint32_t k = 0; k < points; ++k)
            groom.points[first + k] = head.pushOut(line[k], head.radius * 1.003f);
        if (!clumpColor.empty())
            std::fill_n(groom.color.begin() + std::ptrdiff_t(first), points, clumpColor[clump]);
    });
    return groom;
}

} // namespace hairvox
