#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/film/image_file.h>
#include <hairvox/geometry/environment_map.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace hairvox {

namespace {

/// cos and sin of a rotation in degrees, exact at multiples of 90°.
void rotationOf(float degrees, float& c, float& s) {
    const double turns = std::remainder(double(degrees), 360.0); // (−180, 180]
    if (turns == 0 || turns == 90 || turns == -90 || turns == 180 || turns == -180) {
        c = turns == 0 ? 1.0f : (turns == 180 || turns == -180 ? -1.0f : 0.0f);
        s = turns == 90 ? 1.0f : (turns == -90 ? -1.0f : 0.0f);
        return;
    }
    const double r = radians(turns);
    c = float(std::cos(r));
    s = float(std::sin(r));
}

std::string gibText(double bytes) {
    std::ostringstream os;
    os << std::fixed << std::setprecision(bytes < double(1ull << 30) ? 0 : 1);
    if (bytes < double(1ull << 30))
        os << bytes / double(1ull << 20) << " MiB";
    else
        os << bytes / double(1ull << 30) << " GiB";
    return os.str();
}

} // namespace

std::ostream& operator<<(std::ostream& os, const EnvironmentRegion& r) {
    return os << "EnvironmentRegion([" << r.x0 << ", " << r.x1 << ") x [" << r.y0 << ", " << r.y1
              << "), direction " << r.direction << ", irradiance " << r.irradiance << ", "
              << r.solidAngle << " sr, spread " << std::sqrt(r.spread2) << " rad)";
}

EnvironmentMap::EnvironmentMap(int width, std::vector<Rgb> pixels, std::string source,
                               const Rgb& scale, float rotationDegrees)
    : width_(width)
    , pixels_(std::move(pixels))
    , source_(std::move(source))
    , scale_(scale)
    , rotationDegrees_(rotationDegrees) {
    const std::size_t count = pixels_.size();
    if (width_ < 2 || count % std::size_t(width_) != 0 ||
        count / std::size_t(width_) * 2 != std::size_t(width_))
        throw InputError(strCat(
            source_, ": ", width_, " x ", width_ > 0 ? count / std::size_t(width_) : 0,
            " pixels: expected a latitude-longitude map twice as wide as high (e.g. 512 x 256)"));
    height_ = width_ / 2;
    if (!scale_.isFinite() || scale_.minComponent() < 0)
        throw InputError(strCat(source_, ": scale ", scale_, ": expected finite values >= 0"));
    if (!std::isfinite(rotationDegrees_))
        throw InputError(
            strCat(source_, ": rotation ", rotationDegrees_, ": expected a finite angle"));
    rotationOf(rotationDegrees_, cosRotation_, sinRotation_);

    // Every pixel finite: count the others, name the first.
    std::uint64_t nonFinite = 0;
    std::string where;
    for (std::size_t p = 0; p < count; ++p) {
        const Rgb& c = pixels_[p];
        if (c.isFinite())
            continue;
        if (++nonFinite <= 3)
            where += strCat(where.empty() ? "" : "; ", "column ", p % std::size_t(width_), ", row ",
                            p / std::size_t(width_), " = (", c.r, ", ", c.g, ", ", c.b, ")");
    }
    if (nonFinite > 0)
        throw InputError(strCat(source_, ": ", nonFinite, " of ", count,
                                " pixels are not finite (NaN or infinite): an environment map "
                                "holds radiance (first at ",
                                where, ")"));
    foldNegatives();

    // Sampling: luminance × sin θ at each row's centre.
    std::vector<float> f(count);
    for (int j = 0; j < height_; ++j) {
        const float sinTheta = float(std::sin(Pi * (j + 0.5) / height_));
        for (int i = 0; i < width_; ++i) {
            const std::size_t p = std::size_t(j) * std::size_t(width_) + std::size_t(i);
            const float y = (scale_ * pixels_[p]).luminance();
            maxLuminance_ = std::max(maxLuminance_, y);
            f[p] = y * sinTheta;
        }
    }
    distribution_ = PiecewiseConstant2D(f, std::size_t(width_), std::size_t(height_));
}

void EnvironmentMap::foldNegatives() {
    std::vector<double> dOmega(static_cast<std::size_t>(height_));
    for (int j = 0; j < height_; ++j)
        dOmega[std::size_t(j)] = pixelSolidAngle(j);
    std::uint64_t unabsorbed = 0;
    std::string where;
    for (int c = 0; c < 3; ++c) {
        for (int j = 0; j < height_; ++j)
            for (int i = 0; i < width_; ++i) {
                float& v = pixels_[std::size_t(j) * std::size_t(width_) + std::size_t(i)][c];
                if (!(v < 0))
                    continue;
                ++negativeFolds_.values;
                negativeFolds_.lowest = std::min(negativeFolds_.lowest, v);
                const double deficit = -double(v) * dOmega[std::size_t(j)];
                // The smallest square around the pixel whose positive light absorbs it.
                bool absorbed = false;
                for (int r = 1; r <= kFoldRadius && !absorbed; ++r) {
                    double pool = 0;
                    const int j0 = std::max(j - r, 0), j1 = std::min(j + r, height_ - 1);
                    const int span = std::min(2 * r + 1, width_);
                    for (int y = j0; y <= j1; ++y)
                        for (int k = 0; k < span; ++k) {
                            const int x = ((i - r + k) % width_ + width_) % width_;
                            const float q =
                                pixels_[std::size_t(y) * std::size_t(width_) + std::size_t(x)][c];
                            if (q > 0)
                                pool += double(q) * dOmega[std::size_t(y)];
                        }
                    if (!(pool >= deficit))
                        continue;
                    const float keep = float(1.0 - deficit / pool);
                    for (int y = j0; y <= j1; ++y)
                        for (int k = 0; k < span; ++k) {
                            const int x = ((i - r + k) % width_ + width_) % width_;
                            float& q =
                                pixels_[std::size_t(y) * std::size_t(width_) + std::size_t(x)][c];
                            if (q > 0)
                                q *= keep;
                        }
                    negativeFolds_.radius = std::max(negativeFolds_.radius, r);
                    negativeFolds_.energy += deficit;
                    absorbed = true;
                }
                if (!absorbed && ++unabsorbed <= 3)
                    where += strCat(where.empty() ? "" : "; ", "column ", i, ", row ", j, ", ",
                                    "RGB"[c], " = ", v);
                v = 0;
            }
    }
    if (unabsorbed > 0)
        throw InputError(strCat(
            source_, ": ", unabsorbed, " negative pixel values that the positive light within ",
            kFoldRadius, " pixels around them cannot absorb (first at ", where,
            "): an environment map holds radiance >= 0 (a lossy codec's small negative "
            "ringing beside bright pixels is folded into them; this is more)"));
    double total = 0;
    for (int j = 0; j < height_; ++j)
        for (int i = 0; i < width_; ++i) {
            const Rgb& q = pixels_[std::size_t(j) * std::size_t(width_) + std::size_t(i)];
            total += double(q.r + q.g + q.b) * dOmega[std::size_t(j)];
        }
    negativeFolds_.energy = total > 0 ? negativeFolds_.energy / total : 0;
}

EnvironmentMap EnvironmentMap::uniform(const Rgb& radiance) {
    constexpr int width = 2 * kUniformRows;
    return EnvironmentMap(width, std::vector<Rgb>(std::size_t(width * kUniformRows), Rgb(1.0f)),
                          "uniform", radiance, 0);
}

EnvironmentMap EnvironmentMap::readExr(const ExrSource& source, const Rgb& scale,
                                       float rotationDegrees, std::uint64_t maxBytes) {
    const ExrInfo info = readExrInfo(source);
    const std::string& name = source.name;
    if (info.width != 2 * info.height)
        throw InputError(strCat(name, ": ", info.width, " x ", info.height,
                                " pixels: expected a latitude-longitude map twice as wide as "
                                "high (e.g. 512 x 256)"));
    const std::uint64_t maxPixels = maxBytes / kBytesPerPixel;
    const auto pixels = std::uint64_t(info.width) * std::uint64_t(info.height);
    if (pixels > maxPixels)
        throw InputError(strCat(name, ": ", info.width, " x ", info.height, " pixels would need ",
                                gibText(double(pixels * kBytesPerPixel)),
                                " as an environment map (", kBytesPerPixel,
                                " bytes a pixel), over its budget of ", gibText(double(maxBytes)),
                                "; use a smaller map (at most ", maxPixels, " pixels)"));
    ExrRgbImage image = readExrRgb(source, maxPixels);
    std::vector<Rgb> rgb(std::size_t(image.width) * std::size_t(image.height));
    for (std::size_t p = 0; p < rgb.size(); ++p)
        rgb[p] = {image.rgb[3 * p], image.rgb[3 * p + 1], image.rgb[3 * p + 2]};
    image.rgb = {};
    return EnvironmentMap(image.width, std::move(rgb), name, scale, rotationDegrees);
}

Vec3f EnvironmentMap::direction(float u, float v) const {
    const float theta = float(Pi) * v, psi = float(TwoPi) * (u - 0.5f);
    const float sinTheta = std::sin(theta);
    const float x = sinTheta * std::sin(psi), z = -sinTheta * std::cos(psi);
    return {x * cosRotation_ + z * sinRotation_, std::cos(theta),
            -x * sinRotation_ + z * cosRotation_};
}

Vec2f EnvironmentMap::coordinates(const Vec3f& omega) const {
    const float x = omega.x * cosRotation_ - omega.z * sinRotation_;
    const float z = omega.x * sinRotation_ + omega.z * cosRotation_;
    float u = std::atan2(x, -z) * float(1.0 / TwoPi) + 0.5f;
    if (!(u >= 0.0f && u < 1.0f))
        u = 0.0f; // atan2's +π at the seam (+z) is column 0's edge
    const float v = safeACos(std::clamp(omega.y, -1.0f, 1.0f)) * float(InvPi);
    return {u, std::min(v, std::nextafter(1.0f, 0.0f))};
}

double EnvironmentMap::pixelSolidAngle(int row) const {
    return TwoPi / width_ * (std::cos(Pi * row / height_) - std::cos(Pi * (row + 1) / height_));
}

std::size_t EnvironmentMap::pixelIndex(float u, float v) const {
    const int i = std::min(int(u * float(width_)), width_ - 1);
    const int j = std::min(int(v * float(height_)), height_ - 1);
    return std::size_t(std::max(j, 0)) * std::size_t(width_) + std::size_t(std::max(i, 0));
}

Rgb EnvironmentMap::radiance(const Vec3f& omega) const {
    const Vec2f uv = coordinates(omega);
    return scale_ * pixels_[pixelIndex(uv.x, uv.y)];
}

Rgb EnvironmentMap::backdrop(const Vec3f& omega) const {
    const Vec2f uv = coordinates(omega);
    const float x = uv.x * float(width_) - 0.5f, y = uv.y * float(height_) - 0.5f;
    const float x0 = std::floor(x), y0 = std::floor(y);
    const float fx = x - x0, fy = std::clamp(y - y0, 0.0f, 1.0f);
    // x0 ∈ [−1, width − 1] (u ∈ [0, 1)): the columns wrap without an
    // integer division (three a lookup, the camera's 4 a pixel).
    const int i0 = x0 < 0 ? int(x0) + width_ : int(x0), i1 = i0 + 1 == width_ ? 0 : i0 + 1;
    const int j0 = std::clamp(int(y0), 0, height_ - 1),
              j1 = std::min(std::max(int(y0) + 1, 0), height_ - 1);
    const auto at = [&](int i, int j) {
        return pixels_[std::size_t(j) * std::size_t(width_) + std::size_t(i)];
    };
    const Rgb top = (1.0f - fx) * at(i0, j0) + fx * at(i1, j0);
    const Rgb bottom = (1.0f - fx) * at(i0, j1) + fx * at(i1, j1);
    return scale_ * ((1.0f - fy) * top + fy * bottom);
}

EnvironmentSample EnvironmentMap::sample(float u0, float u1) const {
    const PiecewiseConstant2D::Sample s = distribution_.sample(u0, u1);
    // The point kept a thousandth of a cell inside the cell the uniforms
    // chose: the round trip through direction() and coordinates() (two
    // rotations, trigonometry) must find that cell again, and at a cell's
    // edge rounding can step into a neighbour of another density — one of
    // none gave a sample of pdf 0 under another compiler's contractions.
    static constexpr float kInside = 1e-3f;
    const auto inside = [](float x, std::size_t cell, int cells) {
        const float f = std::clamp(x * float(cells) - float(cell), kInside, 1.0f - kInside);
        return (float(cell) + f) / float(cells);
    };
    EnvironmentSample out;
    out.omega = direction(inside(s.u, s.column, width_), inside(s.v, s.row, height_));
    // The radiance and density of the direction as made (not of the cell the
    // uniforms chose): the same numbers pdf() and radiance() give for it.
    out.pdf = pdf(out.omega);
    if (out.pdf > 0)
        out.radiance = radiance(out.omega);
    return out;
}

float EnvironmentMap::pdf(const Vec3f& omega) const {
    // sin θ from the components across +y: within a few cells of a pole
    // cos θ rounds to ±1 in float, while x and z keep the direction's distance
    // from it (a sample drawn there had a density of 0 read back).
    const float sinTheta = std::min(1.0f, std::sqrt(omega.x * omega.x + omega.z * omega.z));
    if (!(sinTheta > 0))
        return 0;
    const Vec2f uv = coordinates(omega);
    const std::size_t p = pixelIndex(uv.x, uv.y);
    return distribution_.pdf(p % std::size_t(width_), p / std::size_t(width_)) /
           (float(2.0 * Pi * Pi) * sinTheta);
}

Rgb EnvironmentMap::integral() const {
    Rgbd sum(0.0);
    for (int j = 0; j < height_; ++j) {
        const double dOmega = pixelSolidAngle(j);
        Rgbd row(0.0);
        for (int i = 0; i < width_; ++i)
            row += Rgbd(pixel(i, j));
        sum += row * dOmega;
    }
    return scale_ * Rgb(sum);
}

Rgb EnvironmentMap::irradiance(const Vec3f& n) const {
    Rgbd sum(0.0);
    for (int j = 0; j < height_; ++j) {
        const double dOmega = pixelSolidAngle(j);
        for (int i = 0; i < width_; ++i) {
            const Vec3f omega =
                direction((float(i) + 0.5f) / float(width_), (float(j) + 0.5f) / float(height_));
            const float cosine = glm::dot(n, omega);
            if (cosine > 0)
                sum += Rgbd(pixel(i, j)) * (double(cosine) * dOmega);
        }
    }
    return scale_ * Rgb(sum);
}

std::vector<EnvironmentRegion> EnvironmentMap::split(std::size_t count, EnvironmentSplit by) const {
    EnvironmentRegion all;
    all.x1 = width_;
    all.y1 = height_;
    return split(count, by, all);
}

std::vector<EnvironmentRegion> EnvironmentMap::split(std::size_t count, EnvironmentSplit by,
                                                     const EnvironmentRegion& within) const {
    if (count < 1)
        throw std::invalid_argument("EnvironmentMap::split: at least one region");
    if (within.x0 < 0 || within.y0 < 0 || within.x1 > width_ || within.y1 > height_ ||
        within.x0 >= within.x1 || within.y0 >= within.y1)
        throw std::invalid_argument("EnvironmentMap::split: a region outside the map");
    // Per row: its solid angle per pixel; the pixels' centres' directions in
    // the map's frame (a rotation about +y keeps a region's spread).
    std::vector<double> dOmega(static_cast<std::size_t>(height_)), sinTheta(dOmega.size()),
        cosTheta(dOmega.size());
    for (int j = 0; j < height_; ++j) {
        dOmega[std::size_t(j)] = pixelSolidAngle(j);
        sinTheta[std::size_t(j)] = std::sin(Pi * (j + 0.5) / height_);
        cosTheta[std::size_t(j)] = std::cos(Pi * (j + 0.5) / height_);
    }
    std::vector<double> sinPsi(static_cast<std::size_t>(width_)), cosPsi(sinPsi.size());
    for (int i = 0; i < width_; ++i) {
        sinPsi[std::size_t(i)] = std::sin(TwoPi * ((i + 0.5) / width_ - 0.5));
        cosPsi[std::size_t(i)] = std::cos(TwoPi * ((i + 0.5) / width_ - 0.5));
    }
    const auto weight = [&](int i, int j) {
        const double w = dOmega[std::size_t(j)];
        return by == EnvironmentSplit::Energy ? double((scale_ * pixel(i, j)).luminance()) * w : w;
    };
    struct Rect {
        int x0, y0, x1, y1;
        double weight;
        double priority; ///< weight × spread about the mean direction
    };
    const auto weigh = [&](Rect& r) {
        r.weight = 0;
        Vec3d moment(0.0);
        for (int j = r.y0; j < r.y1; ++j)
            for (int i = r.x0; i < r.x1; ++i) {
                const double w = weight(i, j);
                const auto sj = std::size_t(j), si = std::size_t(i);
                r.weight += w;
                moment +=
                    w * Vec3d(sinTheta[sj] * sinPsi[si], cosTheta[sj], -sinTheta[sj] * cosPsi[si]);
            }
        const double spread =
            r.weight > 0 ? std::max(0.0, 1.0 - glm::length(moment) / r.weight) : 0;
        r.priority = r.weight * std::min(1.0, spread / double(kPointLikeSpread2));
    };
    std::vector<Rect> rects{{within.x0, within.y0, within.x1, within.y1, 0.0, 0.0}};
    weigh(rects[0]);
    std::vector<double> marginal;
    while (rects.size() < count) {
        // The rectangle whose point light would be most wrong: the largest
        // weight × min(1, spread / kPointLikeSpread2), the first of equals.
        // (By weight alone, a sun a few pixels wide would take a cut per
        // halving of its rectangle, and the sky none.)
        std::size_t best = rects.size();
        for (std::size_t k = 0; k < rects.size(); ++k) {
            const Rect& r = rects[k];
            if ((r.x1 - r.x0 > 1 || r.y1 - r.y0 > 1) && r.priority > 0 &&
                (best == rects.size() || r.priority > rects[best].priority))
                best = k;
        }
        if (best == rects.size())
            break;
        Rect r = rects[best];
        // Across its longer side, in angle: its width at its rows' mean sin θ.
        const double theta0 = Pi * r.y0 / height_, theta1 = Pi * r.y1 / height_;
        const double meanSin = (std::cos(theta0) - std::cos(theta1)) / (theta1 - theta0);
        const double angularWidth = TwoPi * (r.x1 - r.x0) / width_ * meanSin;
        const double angularHeight = theta1 - theta0;
        const bool cutColumns =
            r.y1 - r.y0 < 2 || (r.x1 - r.x0 >= 2 && angularWidth >= angularHeight);
        const int n = cutColumns ? r.x1 - r.x0 : r.y1 - r.y0;
        marginal.assign(std::size_t(n), 0.0);
        for (int j = r.y0; j < r.y1; ++j)
            for (int i = r.x0; i < r.x1; ++i)
                marginal[std::size_t(cutColumns ? i - r.x0 : j - r.y0)] += weight(i, j);
        // The cut k ∈ [1, n − 1] whose weight before it is nearest half.
        double before = 0, bestError = std::numeric_limits<double>::infinity();
        int cut = 1;
        for (int k = 1; k < n; ++k) {
            before += marginal[std::size_t(k - 1)];
            const double error = std::abs(before - 0.5 * r.weight);
            if (error < bestError) {
                bestError = error;
                cut = k;
            }
        }
        Rect a = r, b = r;
        if (cutColumns)
            a.x1 = b.x0 = r.x0 + cut;
        else
            a.y1 = b.y0 = r.y0 + cut;
        weigh(a);
        weigh(b);
        rects[best] = a;
        rects.push_back(b);
    }

    std::vector<EnvironmentRegion> regions;
    regions.reserve(rects.size());
    for (const Rect& r : rects) {
        EnvironmentRegion out;
        out.x0 = r.x0, out.y0 = r.y0, out.x1 = r.x1, out.y1 = r.y1;
        Rgbd irradiance(0.0);
        Vec3d energyDirection(0.0), areaDirection(0.0);
        double energy = 0, solidAngle = 0;
        for (int j = r.y0; j < r.y1; ++j)
            for (int i = r.x0; i < r.x1; ++i) {
                const double w = dOmega[std::size_t(j)];
                const Rgb L = scale_ * pixel(i, j);
                const Vec3d omega(direction((float(i) + 0.5f) / float(width_),
                                            (float(j) + 0.5f) / float(height_)));
                irradiance += Rgbd(L) * w;
                energy += double(L.luminance()) * w;
                energyDirection += (double(L.luminance()) * w) * omega;
                areaDirection += w * omega;
                solidAngle += w;
            }
        const bool lit = energy > 0 && glm::length(energyDirection) > 0;
        const Vec3d mean = lit ? energyDirection / energy : areaDirection / solidAngle;
        const double length = glm::length(mean);
        out.direction = length > 0 ? Vec3f(mean / length) : Vec3f(0.0f, 1.0f, 0.0f);
        out.irradiance = Rgb(irradiance);
        out.solidAngle = float(solidAngle);
        out.spread2 = float(std::clamp(1.0 - length, 0.0, 1.0));
        regions.push_back(out);
    }
    return regions;
}

std::size_t EnvironmentMap::memoryBytes() const {
    return pixels_.capacity() * sizeof(Rgb) + distribution_.memoryBytes();
}

void EnvironmentMap::hashInto(Hasher& hasher) const {
    hasher.value(width_)
        .values(std::span<const Rgb>(pixels_))
        .value(scale_)
        .value(rotationDegrees_);
}

std::ostream& operator<<(std::ostream& os, const EnvironmentMap& m) {
    return os << "EnvironmentMap(" << m.source() << ", " << m.width() << " x " << m.height()
              << ", scale " << m.scale() << ", rotation " << m.rotationDegrees()
              << " deg, max luminance " << m.maxLuminance() << ")";
}

} // namespace hairvox
