// hairvox render tests: simple FragmentShaders and camera helpers.
#pragma once

#include <hairvox/geometry/camera.h>
#include <hairvox/render/fragment_shader.h>
#include <hairvox/render/rasterizer.h>
#include <hairvox/strands/groom.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace hairvox::test {

/// Radiance layers r0, r1, ... and, per light, the averages "<light>.V" (1)
/// and "<light>.T_s" (3).
inline ShaderLayout testLayout(std::size_t radianceLayers, std::size_t lights) {
    ShaderLayout layout;
    for (std::size_t i = 0; i < radianceLayers; ++i)
        layout.radiance.push_back("r" + std::to_string(i));
    for (std::size_t l = 0; l < lights; ++l) {
        layout.averages.push_back({"light" + std::to_string(l) + ".V", 1});
        layout.averages.push_back({"light" + std::to_string(l) + ".T_s", 3});
    }
    return layout;
}

/// The same result everywhere: radiance layer r0 = (0.5, 0.1, 0.05), r1 =
/// (0.05, 0.2, 0.05); per light V = 0.25, T_s = (0.1, 0.2, 0.3).
class ConstantShader : public FragmentShader {
public:
    explicit ConstantShader(std::size_t lights = 0)
        : layout_(testLayout(2, lights)) {}
    static constexpr float kR0[3] = {0.5f, 0.1f, 0.05f};
    static constexpr float kR1[3] = {0.05f, 0.2f, 0.05f};
    static constexpr float kLight[4] = {0.25f, 0.1f, 0.2f, 0.3f};

    const ShaderLayout& layout() const override { return layout_; }
    void shade(std::span<const ShadingPoint> points, std::span<float> out) const override {
        const std::size_t stride = layout_.stride();
        for (std::size_t i = 0; i < points.size(); ++i) {
            float* o = out.data() + i * stride;
            for (int c = 0; c < 3; ++c) {
                o[c] = kR0[c];
                o[3 + c] = kR1[c];
            }
            for (std::size_t k = 6; k < stride; ++k)
                o[k] = kLight[(k - 6) % 4];
        }
    }

private:
    ShaderLayout layout_;
};

/// Colour by strand in r0: strand 0 red, strand 1 green, others blue.
class StrandColorShader : public FragmentShader {
public:
    const ShaderLayout& layout() const override { return layout_; }
    void shade(std::span<const ShadingPoint> points, std::span<float> out) const override {
        for (std::size_t i = 0; i < points.size(); ++i) {
            float* o = out.data() + 3 * i;
            const std::uint32_t s = points[i].strand;
            o[0] = s == 0 ? 1.0f : 0.0f;
            o[1] = s == 1 ? 1.0f : 0.0f;
            o[2] = s > 1 ? 1.0f : 0.0f;
        }
    }

private:
    ShaderLayout layout_ = testLayout(1, 0);
};

/// A smooth function of position, tangent and view, for shading-rate comparisons.
class SmoothShader : public FragmentShader {
public:
    explicit SmoothShader(std::size_t lights)
        : layout_(testLayout(3, lights)) {}
    const ShaderLayout& layout() const override { return layout_; }
    void shade(std::span<const ShadingPoint> points, std::span<float> out) const override {
        const Vec3f light = glm::normalize(Vec3f(0.6f, 0.7f, 0.4f));
        const std::size_t stride = layout_.stride();
        for (std::size_t i = 0; i < points.size(); ++i) {
            const ShadingPoint& p = points[i];
            const float sinI = glm::dot(light, p.tangent), sinO = glm::dot(p.toCamera, p.tangent);
            const float cosI = std::sqrt(std::max(0.0f, 1 - sinI * sinI));
            const float cosO = std::sqrt(std::max(0.0f, 1 - sinO * sinO));
            const float wave = 0.5f + 0.4f * std::sin(15.0f * p.position.y + 10.0f * p.position.x);
            float* o = out.data() + i * stride;
            const float r[9] = {0.3f * cosI * cosO, 0.3f * cosI * cosO, 0.3f * cosI * cosO,
                                0.3f * wave,        0.25f * wave,       0.15f * wave,
                                0.2f * cosO,        0.15f * cosO,       0.05f * cosO};
            std::copy(r, r + 9, o);
            for (std::size_t k = 9; k < stride; k += 4) {
                o[k] = 1.0f - 0.5f * wave;
                o[k + 1] = o[k + 2] = o[k + 3] = 0.2f * wave;
            }
        }
    }

private:
    ShaderLayout layout_;
};

/// Returns NaN for strand 3, ConstantShader's values elsewhere.
class NaNShader : public ConstantShader {
public:
    void shade(std::span<const ShadingPoint> points, std::span<float> out) const override {
        ConstantShader::shade(points, out);
        for (std::size_t i = 0; i < points.size(); ++i)
            if (points[i].strand == 3)
                out[i * layout().stride() + 4] = std::numeric_limits<float>::quiet_NaN();
    }
};

/// A camera at `position` looking at `lookAt`.
inline Camera testCamera(std::uint32_t width, std::uint32_t height, const Vec3f& position,
                         const Vec3f& lookAt, float fovY = 30.0f) {
    CameraParams c;
    c.position = position;
    c.lookAt = lookAt;
    c.fovY = fovY;
    c.width = width;
    c.height = height;
    return Camera(c);
}

/// Raster settings with fiber diameter D, one hair per strand.
inline RasterSettings testSettings(float diameter) {
    RasterSettings s;
    s.fiberScale.diameter = diameter;
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
