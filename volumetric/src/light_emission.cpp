#include "light_emission.h"

#include <hairvox/core/math.h>
#include <hairvox/core/sampling.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hairvox {

namespace {

/// Texels of the footprint grid a side at most (a coarser texel beyond).
constexpr float kMaxGridWidth = 2048.0f;
/// A point light sends over the sphere when a voxel centre lies further than
/// this (cosine) off its axis: the plane would stretch toward infinity.
constexpr float kMinCosOffAxis = 0.2f;

} // namespace

LightEmission::LightEmission(const Light& light, const FiberGrid& grid, const Vec3f& centre,
                             float radius)
    : light_(&light)
    , centre_(centre)
    , radius_(radius) {
    const float h = float(grid.info.voxelSize);
    const bool directional = light.kind == Light::Kind::Directional;
    axis_ = directional ? -light.direction : normalizeOr(centre - light.position, Vec3f(0, -1, 0));
    coordinateSystem(axis_, s_, t_);
    const float axisDistance = directional ? 0.0f : glm::distance(centre, light.position);

    // Project every voxel centre onto the plane; a point light too close for it spreads uniformly.
    std::vector<Vec2f> points;
    points.reserve(grid.activeVoxelCount());
    Vec2f lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
    bool tooClose = !directional && axisDistance <= radius * 1.001f;
    grid.forEachVoxel([&](std::size_t, const openvdb::Coord& ijk) {
        if (tooClose)
            return;
        Vec3f p = Vec3f(float(ijk.x()), float(ijk.y()), float(ijk.z())) * h;
        if (!directional) {
            const Vec3f d = p - light.position;
            const float along = glm::dot(d, axis_);
            if (!(along > kMinCosOffAxis * glm::length(d))) {
                tooClose = true;
                return;
            }
            p = light.position + d * (axisDistance / along);
        }
        const Vec2f q(glm::dot(p - centre, s_), glm::dot(p - centre, t_));
        points.push_back(q);
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    });
    if (tooClose) {
        uniform_ = true;
        power_ = light.irradiance(1.0f) * float(2.0 * TwoPi);
        return;
    }
    if (points.empty())
        return;
    texel_ = std::max(h, std::max(hi.x - lo.x, hi.y - lo.y) / kMaxGridWidth);
    gridMin_ = lo - 1.5f * texel_;
    gridWidth_ = int(std::ceil(std::max(hi.x - lo.x, hi.y - lo.y) / texel_)) + 4;
    std::vector<std::uint8_t> mark(std::size_t(gridWidth_) * std::size_t(gridWidth_), 0);
    for (const Vec2f& q : points) {
        const int x = int((q.x - gridMin_.x) / texel_), y = int((q.y - gridMin_.y) / texel_);
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int xx = std::clamp(x + dx, 0, gridWidth_ - 1);
                const int yy = std::clamp(y + dy, 0, gridWidth_ - 1);
                mark[std::size_t(yy) * std::size_t(gridWidth_) + std::size_t(xx)] = 1;
            }
    }
    double solidAngle = 0;
    for (std::size_t i = 0; i < mark.size(); ++i) {
        if (!mark[i])
            continue;
        marked_.push_back(static_cast<std::uint32_t>(i));
        if (!directional) {
            const Vec2f q = gridMin_ + (Vec2f(float(i % std::size_t(gridWidth_)),
                                              float(i / std::size_t(gridWidth_))) +
                                        0.5f) * texel_;
            const Vec3f p = centre + q.x * s_ + q.y * t_;
            const float r = glm::distance(p, light.position);
            solidAngle += double(texel_) * double(texel_) * double(axisDistance) / (double(r) * double(r) * double(r));
        }
    }
    const double area = double(marked_.size()) * double(texel_) * double(texel_);
    power_ = directional ? light.irradiance(0.0f) * float(area)
                         : light.irradiance(1.0f) * float(solidAngle);
}

LightEmission::Start LightEmission::start(float u1, float u2, std::uint64_t paths) const {
    const Light& light = *light_;
    if (uniform_)
        return {light.position, uniformSphere(u1, u2),
                light.irradiance(1.0f) * float(2.0 * TwoPi / double(paths))};
    // u1 picks the texel; its fraction and u2 the point in it.
    const double scaled = double(u1) * double(marked_.size());
    const std::size_t k = std::min(marked_.size() - 1, std::size_t(scaled));
    const auto fx = float(scaled - double(k));
    const std::uint32_t texel = marked_[k];
    const Vec2f q = gridMin_ + Vec2f(float(texel % std::uint32_t(gridWidth_)) + fx,
                                     float(texel / std::uint32_t(gridWidth_)) + u2) * texel_;
    const Vec3f onPlane = centre_ + q.x * s_ + q.y * t_;
    const double area = double(marked_.size()) * double(texel_) * double(texel_);
    if (light.kind == Light::Kind::Directional)
        return {onPlane - axis_ * (1.01f * radius_), axis_,
                light.irradiance(0.0f) * float(area / double(paths))};
    const Vec3f d = onPlane - light.position;
    const float r = glm::length(d);
    const Vec3f dir = d / r;
    const double cosTheta = double(glm::dot(dir, axis_));
    // I / (N p_ω), p_ω = r² / (cos θ · A).
    return {light.position, dir,
            light.irradiance(1.0f) * float(cosTheta * area / (double(r) * double(r) * double(paths)))};
}

} // namespace hairvox
