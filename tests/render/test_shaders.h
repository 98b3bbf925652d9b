// hairvox render tests: simple FragmentShaders and scene helpers.
#pragma once

#include <hairvox/render/fragment_shader.h>
#include <hairvox/render/scene.h>
#include <hairvox/strands/groom.h>

#include <cmath>
#include <limits>
#include <vector>

namespace hairvox::test {

/// The same result everywhere: each lobe its own colour, a fixed global term per light.
class ConstantShader : public FragmentShader {
public:
    static ShadeResult result() {
        ShadeResult r;
        r.directR = Rgb(0.5f, 0.1f, 0.05f);
        r.directTT = Rgb(0.05f, 0.2f, 0.05f);
        r.directTRT = Rgb(0.02f, 0.02f, 0.3f);
        r.backDirect = Rgb(0.1f, 0.08f, 0.06f);
        r.scatter = Rgb(0.2f, 0.15f, 0.1f);
        return r;
    }
    static GlobalTerm term() { return {2.0f, 0.25f, Rgb(0.5f), Rgb(0.1f, 0.2f, 0.3f), Rgb(0.04f)}; }
    void shade(std::span<const ShadingPoint> points, std::span<ShadeResult> radiance,
               std::span<GlobalTerm> terms) const override {
        for (std::size_t i = 0; i < points.size(); ++i)
            radiance[i] = result();
        for (GlobalTerm& g : terms)
            g = term();
    }
};

/// Colour by strand: strand 0 red, strand 1 green, others blue (directR only).
class StrandColorShader : public FragmentShader {
public:
    void shade(std::span<const ShadingPoint> points, std::span<ShadeResult> radiance,
               std::span<GlobalTerm>) const override {
        for (std::size_t i = 0; i < points.size(); ++i) {
            radiance[i] = ShadeResult{};
            radiance[i].directR = points[i].strand == 0   ? Rgb(1, 0, 0)
                                  : points[i].strand == 1 ? Rgb(0, 1, 0)
                                                          : Rgb(0, 0, 1);
        }
    }
};

/// A smooth function of position, tangent and view, for shading-rate comparisons.
class SmoothShader : public FragmentShader {
public:
    explicit SmoothShader(std::size_t lights) : lights_(lights) {}
    void shade(std::span<const ShadingPoint> points, std::span<ShadeResult> radiance,
               std::span<GlobalTerm> terms) const override {
        const Vec3f light = glm::normalize(Vec3f(0.6f, 0.7f, 0.4f));
        for (std::size_t i = 0; i < points.size(); ++i) {
            const ShadingPoint& p = points[i];
            const float sinI = glm::dot(light, p.tangent), sinO = glm::dot(p.toCamera, p.tangent);
            const float cosI = std::sqrt(std::max(0.0f, 1 - sinI * sinI));
            const float cosO = std::sqrt(std::max(0.0f, 1 - sinO * sinO));
            const float wave = 0.5f + 0.4f * std::sin(15.0f * p.position.y + 10.0f * p.position.x);
            ShadeResult& r = radiance[i];
            r = ShadeResult{};
            r.directR = Rgb(0.3f * cosI * cosO);
            r.directTT = Rgb(0.3f, 0.25f, 0.15f) * wave;
            r.directTRT = Rgb(0.2f, 0.15f, 0.05f) * cosO;
            r.backDirect = Rgb(0.2f, 0.16f, 0.1f) * cosI;
            r.scatter = Rgb(0.25f, 0.2f, 0.12f) * (1.0f - 0.5f * wave);
            for (std::size_t l = 0; l < lights_; ++l)
                terms[i * lights_ + l] = {wave, 1.0f - 0.5f * wave, Rgb(wave), Rgb(0.2f * wave),
                                          Rgb(0.01f)};
        }
    }

private:
    std::size_t lights_;
};

/// Returns NaN for strand 3, a constant elsewhere.
class NaNShader : public FragmentShader {
public:
    void shade(std::span<const ShadingPoint> points, std::span<ShadeResult> radiance,
               std::span<GlobalTerm>) const override {
        for (std::size_t i = 0; i < points.size(); ++i) {
            radiance[i] = ConstantShader::result();
            if (points[i].strand == 3)
                radiance[i].scatter.g = std::numeric_limits<float>::quiet_NaN();
        }
    }
};

/// A scene with no lights, no head, black background and no outputs, camera at
/// `position` looking at `lookAt`.
inline Scene testScene(std::uint32_t width, std::uint32_t height, const Vec3f& position,
                       const Vec3f& lookAt, float fovY = 30.0f) {
    Scene s;
    s.name = "test scene";
    s.camera.position = position;
    s.camera.lookAt = lookAt;
    s.camera.fovY = fovY;
    s.camera.width = width;
    s.camera.height = height;
    s.output = {};
    return s;
}

/// A straight strand from a to b with `segments` equal segments.
inline void addStraightStrand(Groom& g, const Vec3f& a, const Vec3f& b, int segments) {
    std::vector<Vec3f> pts;
    for (int k = 0; k <= segments; ++k)
        pts.push_back(a + (float(k) / float(segments)) * (b - a));
    g.addStrand(pts);
}

} // namespace hairvox::test
