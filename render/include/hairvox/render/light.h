// hairvox render: the lights of a scene.
//
// Directions follow docs/DESIGN.md §2: ω_i points away from the shaded point,
// toward the light; a directional light stores that unit vector. Radiometry:
//  - directional: the irradiance on a surface facing the light is
//    E = colour · intensity (intensity is an irradiance);
//  - point: E = colour · intensity / d² at distance d (intensity is a radiant
//    intensity), d clamped to ≥ 1e-6 scene units so that E stays finite.
// Reflected radiance is E ⊙ (the shader's result per unit incident radiance).
#pragma once

#include <hairvox/core/rgb.h>
#include <hairvox/core/vecmath.h>
#include <hairvox/transmittance/light_geometry.h>

#include <ostream>
#include <string>

namespace hairvox {

/// A scene light: where it is (LightGeometry, shared with the transmittance
/// stage: kind, direction or position, pathFrom()) and what it emits.
struct Light : LightGeometry {
    std::string name; ///< prefix of the light's AOV layers in the EXR ("key", "light1")
    Rgb color{1.0f};        ///< each channel in [0, 1000]
    float intensity = 1.0f; ///< [0, 1e6]

    /// Irradiance at a point `distance` away (pathFrom), facing the light.
    Rgb irradiance(float distance) const;
};

std::ostream& operator<<(std::ostream& os, const Light& light);

} // namespace hairvox
