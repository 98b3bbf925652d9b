// hairvox geometry: the environment light — radiance arriving from every
// direction, given as a latitude–longitude map (docs/scene.md "Environment
// light" has the picture; docs/environment.md the design and measurements).
//
// Layout. A map is W × H pixels with W = 2H. Pixel (i, j) — column i, row j,
// row 0 at the top of the image — covers u ∈ [i/W, (i + 1)/W) and
// v ∈ [j/H, (j + 1)/H); a point (u, v) of the map is the direction
//     θ = π·v (from +y),  ψ = 2π·(u − ½),
//     ω_map = (sin θ · sin ψ,  cos θ,  −sin θ · cos ψ),
// so row 0 is the zenith (+y), the middle row the horizon, and along a row
// the middle column faces −z, three quarters +x, the edges +z and one
// quarter −x: the map seen from inside, unmirrored — a viewer at the origin
// facing −z sees the middle of the map, with its right half to their right.
//
// Rotation ρ (degrees) turns the map about +y, right-handed (counter-clockwise
// seen from above): ω_world = R_y(ρ)·ω_map. A world direction whose own
// coordinate is u sees the map at u + ρ/360: ρ = 90° is the map rolled left by a
// quarter of its width, its middle (−z) now facing −x.
//
// Radiance: L(ω) = scale ⊙ map(ω), scale = the light's colour × intensity.
// One map, two reconstructions:
//  - radiance(ω), what lights: the pixel ω falls in (piecewise constant over
//    the sphere). sample()/pdf(), integral(), irradiance() and split() are
//    exact for this function, so that the path tracer's estimator and the
//    dual-scattering lights integrate the same radiance;
//  - backdrop(ω), what a camera sees behind everything: bilinear between the
//    pixel centres (wrapping around in u), since a camera pixel is often a
//    tenth of a map pixel (a 512-wide map is 0.7° a pixel).
//
// Importance sampling (pbrt-v4's ImageInfiniteLight): a PiecewiseConstant2D
// over the pixels of luminance × sin θ_j (θ_j at the row's centre); a sample
// (u, v) is the direction above, with solid-angle density
//     pdf(ω) = p(u, v) / (2π² sin θ),
// exact (dω = 2π² sin θ du dv), so L/pdf is unbiased for any map.
//
// Splitting into lights (median cut, Debevec 2005, "A Median Cut Algorithm
// for Light Probe Sampling"): the map's pixels are cut into rectangles — a
// rectangle is cut across its longer side (its angular width measured at its
// rows' mean sin θ) where the weight on either side is half — until there are
// the number asked for. Weight is luminance × solid angle (energy: bright
// areas get many small regions), or solid angle alone (equal areas: the
// baseline of K uniform directions). Debevec cuts every rectangle each round;
// here the rectangle cut next is the one of the largest weight ×
// min(1, spread / kPointLikeSpread2): its weight while it is wider than the
// narrowest lobe it lights (hair's R, 5–10°), then its second moment about
// its mean direction in units of that lobe — so a sun a few pixels wide is
// cut down to a few degrees and the rest of the cuts go to the sky, where
// cutting by weight alone spends one per halving of the sun's rectangle and
// leaves the sky one or two, and a bright softbox is cut until its pieces are
// about as narrow as the R lobe, where the second moment alone could leave it
// one wide region (docs/environment.md). A region stands for a directional
// light of irradiance ∫_region L dω from its energy-weighted mean direction,
// with the angular spread of its energy about that direction.
#pragma once

#include <hairvox/core/distribution.h>
#include <hairvox/core/enum_names.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/film/image_file.h>

#include <cstdint>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

namespace hairvox {

struct EnvironmentSample {
    Vec3f omega{0.0f, 1.0f, 0.0f}; ///< unit, world, toward where the light comes from
    Rgb radiance{0.0f};            ///< radiance(omega)
    float pdf = 0;                 ///< solid-angle density of omega (0: no sample)
};

/// A rectangle of map pixels and the directional light it stands for.
struct EnvironmentRegion {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0; ///< pixels [x0, x1) × [y0, y1)
    /// Unit, world: the mean of the region's directions weighted by
    /// luminance × solid angle (by solid angle alone where it is black).
    Vec3f direction{0.0f, 1.0f, 0.0f};
    Rgb irradiance{0.0f}; ///< ∫_region L dω: the irradiance of a surface facing the region
    float solidAngle = 0; ///< sr
    /// Angular variance of the region's energy about `direction`, per axis
    /// across it (rad²): E[1 − ω·direction] ≈ ½ E[angle²] (0 for one direction).
    float spread2 = 0;
};

std::ostream& operator<<(std::ostream& os, const EnvironmentRegion& r);

/// What a median cut weighs: energy (luminance × solid angle) or solid angle.
enum class EnvironmentSplit { Energy, SolidAngle };

inline constexpr EnumNames<EnvironmentSplit, 2> kEnvironmentSplitNames{{{
    {EnvironmentSplit::Energy, "energy"},
    {EnvironmentSplit::SolidAngle, "solid-angle"},
}}};

class EnvironmentMap {
public:
    /// Negative values are not radiance, but every map stored with a lossy
    /// codec has some: DWA's ringing beside bright pixels (the six maps of
    /// ../shared/data/hdri have 33 to 5270 each, as low as −3394 beside a
    /// 22,672 sun, up to 11% of the map's energy). Each negative value (per
    /// channel, in raster order) is set to 0 and its energy (× solid angle)
    /// taken from the positive values of the smallest square around it, up to
    /// kFoldRadius pixels, that holds enough — in proportion to them, so that
    /// every channel's energy is kept exactly where the codec put it. A value
    /// no such square can absorb is an error (the map holds negative light).
    struct NegativeFolds {
        std::uint64_t values = 0; ///< negative channel values folded
        float lowest = 0;         ///< the most negative
        int radius = 0;           ///< the widest square needed (pixels from the value)
        double energy = 0;        ///< what they carried, a share of the map's energy after
    };
    static constexpr int kFoldRadius = 8;
    /// A region's spread (EnvironmentRegion::spread2, rad²) below which it
    /// lights like a point: (0.1 rad)², about hair's R lobe (β_R 5–10°).
    static constexpr float kPointLikeSpread2 = 0.01f;

    /// What a map costs a pixel: its RGB (12 bytes), the sampling
    /// distribution's value and cumulative sum (12), and while it is read the
    /// file's floats (12) and the luminance (4).
    static constexpr std::uint64_t kBytesPerPixel = 40;
    /// The rows of a uniform map (64 × 32 pixels: the density of a sample
    /// follows sin θ within 3% of a row's height).
    static constexpr int kUniformRows = 32;

    /// A map of `width` × `width`/2 pixels, row-major. Validates (InputError
    /// prefixed with `source`): the layout 2:1, every pixel finite (the
    /// message counts the others and says where the first are), scale finite
    /// and ≥ 0, rotation finite. Negative values are folded (NegativeFolds).
    EnvironmentMap(int width, std::vector<Rgb> pixels, std::string source,
                   const Rgb& scale = Rgb(1.0f), float rotationDegrees = 0);
    /// The same radiance from every direction.
    static EnvironmentMap uniform(const Rgb& radiance);
    /// Reads an EXR, a file or a built-in map (film/image_file.h readExrRgb: RGB or RGBA, half or
    /// float, any compression). InputError naming the file: unreadable, not
    /// RGB, not 2:1, non-finite pixels or negative ones that cannot be
    /// folded, or more pixels than `maxBytes` allows at kBytesPerPixel
    /// (checked from its header, before reading).
    static EnvironmentMap readExr(const ExrSource& source, const Rgb& scale, float rotationDegrees,
                                  std::uint64_t maxBytes);
    static EnvironmentMap readExr(const std::filesystem::path& path, const Rgb& scale,
                                  float rotationDegrees, std::uint64_t maxBytes) {
        return readExr(ExrSource::file(path), scale, rotationDegrees, maxBytes);
    }

    /// Radiance arriving from the unit world direction ω (what lights).
    Rgb radiance(const Vec3f& omega) const;
    /// Radiance a camera ray toward ω sees (bilinear).
    Rgb backdrop(const Vec3f& omega) const;

    /// A direction drawn with density ∝ luminance of radiance() (× sin θ's
    /// Jacobian, i.e. pdf() in solid angle) from two uniforms in [0, 1).
    EnvironmentSample sample(float u0, float u1) const;
    /// The solid-angle density sample() draws ω with.
    float pdf(const Vec3f& omega) const;

    /// ∫ L dω over the sphere (radiance × sr): 4π·L for a uniform map.
    Rgb integral() const;
    /// Irradiance on a surface of unit normal n with nothing in the way:
    /// ∫_{n·ω > 0} L(ω) (n·ω) dω (each pixel at its centre; exact for a
    /// uniform map up to the pixels' curvature, 0.1% at 32 rows).
    Rgb irradiance(const Vec3f& n) const;
    /// Median cut into `count` regions (fewer when the map has fewer pixels,
    /// or where the rest is black), in the order they were made
    /// (deterministic). count ≥ 1.
    std::vector<EnvironmentRegion> split(std::size_t count, EnvironmentSplit by) const;
    /// The same within one region's pixels (the region's x0, y0, x1, y1).
    std::vector<EnvironmentRegion> split(std::size_t count, EnvironmentSplit by,
                                         const EnvironmentRegion& within) const;

    /// The world direction of map coordinates (u, v) ∈ [0, 1]² (layout above).
    Vec3f direction(float u, float v) const;
    /// The map coordinates (u, v) ∈ [0, 1)² of a unit world direction.
    Vec2f coordinates(const Vec3f& omega) const;

    int width() const { return width_; }
    int height() const { return height_; }
    /// The map's own pixel (before scale).
    const Rgb& pixel(int column, int row) const {
        return pixels_[std::size_t(row) * std::size_t(width_) + std::size_t(column)];
    }
    const Rgb& scale() const { return scale_; }
    float rotationDegrees() const { return rotationDegrees_; }
    /// The file it was read from, or "uniform".
    const std::string& source() const { return source_; }
    /// What reading folded away (NegativeFolds; values = 0: nothing).
    const NegativeFolds& negativeFolds() const { return negativeFolds_; }
    /// The largest luminance of a pixel (× scale).
    float maxLuminance() const { return maxLuminance_; }
    std::size_t memoryBytes() const;
    /// Everything it lights with: pixels, scale, rotation.
    void hashInto(Hasher& hasher) const;

private:
    /// Pixel of map coordinates (u, v) ∈ [0, 1)².
    std::size_t pixelIndex(float u, float v) const;
    /// The solid angle of a pixel of the row: 2π/W·(cos θ_j − cos θ_{j+1}).
    double pixelSolidAngle(int row) const;
    /// Folds the negative values (NegativeFolds); InputError where it cannot.
    void foldNegatives();

    int width_ = 0, height_ = 0;
    std::vector<Rgb> pixels_;
    std::string source_;
    Rgb scale_{1.0f};
    float rotationDegrees_ = 0, cosRotation_ = 1, sinRotation_ = 0;
    PiecewiseConstant2D distribution_;
    float maxLuminance_ = 0;
    NegativeFolds negativeFolds_;
};

std::ostream& operator<<(std::ostream& os, const EnvironmentMap& map);

} // namespace hairvox
