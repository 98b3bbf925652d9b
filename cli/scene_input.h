// hairvox CLI: the options that say what a command works on — a scene file,
// or a groom file with fiber options (the fiber optics of docs/DESIGN.md §3,
// degrees on the command line) — shared by tables, probe and transmittance.
#pragma once

#include <hairvox/pipeline/scene.h>
#include <hairvox/shading/fiber_params.h>

#include <CLI/CLI.hpp>

#include <optional>
#include <string>
#include <vector>

namespace hairvox::cli {

/// Fiber optics flags (--eta, --sigma-a | --melanin, --alpha-r, --beta-r, ...).
struct FiberOptions {
    std::vector<float> sigmaA;  ///< r,g,b
    std::vector<float> melanin; ///< eumelanin,pheomelanin
    std::optional<float> eta, alphaRDeg, betaRDeg, eccentricity, causticWidthDeg, causticGain,
        causticFade, causticMaxWidth;

    /// Adds the flags; returns them so that a command can make them exclude --scene.
    std::vector<CLI::Option*> add(CLI::App* cmd);
    /// `base` with the given flags applied, validated.
    FiberParams apply(FiberParams base) const;
};

/// `--scene FILE`, or a positional groom file with fiber and scale options.
struct SceneInput {
    std::string sceneFile;
    std::string groomFile;
    FiberOptions fiber;
    std::optional<float> diameter, densityMultiplier, voxelSize;

    void add(CLI::App* cmd);
    /// The scene file as given, or a scene made of the groom file, the fiber
    /// options and the default scene's settings without its head (a groom file
    /// says nothing about a head) and with one hair per strand. Overrides
    /// applied; validated.
    Scene resolve() const;
};

} // namespace hairvox::cli
