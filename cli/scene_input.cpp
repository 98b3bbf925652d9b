#include "scene_input.h"

#include <hairvox/core/error.h>
#include <hairvox/core/math.h>

namespace hairvox::cli {

std::vector<CLI::Option*> FiberOptions::add(CLI::App* cmd) {
    std::vector<CLI::Option*> options;
    options.push_back(
        cmd->add_option("--eta", eta, "Index of refraction [1.1, 2.5] (default 1.55)"));
    CLI::Option* sigma = cmd->add_option("--sigma-a", sigmaA,
                                         "Absorption per unit fiber radius r,g,b, each in [0, 50] "
                                         "(default 0.2,0.3,0.5)")
                             ->delimiter(',')
                             ->expected(3);
    options.push_back(sigma);
    options.push_back(cmd->add_option("--melanin", melanin,
                                      "Eumelanin,pheomelanin concentrations, each in [0, 20] "
                                      "(sets sigma_a)")
                          ->delimiter(',')
                          ->expected(2)
                          ->excludes(sigma));
    options.push_back(
        cmd->add_option("--alpha-r", alphaRDeg, "R-lobe shift (deg) [-20, 20] (default -7.5)"));
    options.push_back(
        cmd->add_option("--beta-r", betaRDeg, "R-lobe width (deg) [0.5, 45] (default 7.5)"));
    options.push_back(cmd->add_option("--eccentricity", eccentricity,
                                      "Cross-section eccentricity [0.5, 1] (default 1)"));
    options.push_back(cmd->add_option("--caustic-width", causticWidthDeg,
                                      "TRT caustic width w_c (deg) [1, 45] (default 15)"));
    options.push_back(cmd->add_option("--caustic-gain", causticGain,
                                      "TRT caustic gain k_G [0, 10] (default 0.5)"));
    options.push_back(cmd->add_option("--caustic-fade", causticFade,
                                      "Caustic fade-out range [0.01, 1] (default 0.3)"));
    options.push_back(cmd->add_option("--caustic-max-width", causticMaxWidth,
                                      "Maximum caustic h-interval [0.01, 2] (default 0.5)"));
    return options;
}

FiberParams FiberOptions::apply(FiberParams p) const {
    if (!sigmaA.empty())
        p.sigma_a = Rgb(sigmaA[0], sigmaA[1], sigmaA[2]);
    if (!melanin.empty())
        p.sigma_a = FiberParams::sigmaFromMelanin(melanin[0], melanin[1]);
    if (eta)
        p.eta = *eta;
    if (alphaRDeg)
        p.alpha_R = radians(*alphaRDeg);
    if (betaRDeg)
        p.beta_R = radians(*betaRDeg);
    if (eccentricity)
        p.eccentricity = *eccentricity;
    if (causticWidthDeg)
        p.causticWidth = radians(*causticWidthDeg);
    if (causticGain)
        p.causticGain = *causticGain;
    if (causticFade)
        p.causticFade = *causticFade;
    if (causticMaxWidth)
        p.causticMaxWidth = *causticMaxWidth;
    p.validate();
    return p;
}

void SceneInput::add(CLI::App* cmd) {
    CLI::Option* scene = cmd->add_option("--scene", sceneFile, "Scene JSON file (docs/scene.md)");
    CLI::Option* groom =
        cmd->add_option("groom", groomFile, "Groom file (.hair, .tfx, .obj), instead of --scene");
    scene->excludes(groom);
    for (CLI::Option* o : fiber.add(cmd))
        o->excludes(scene);
    cmd->add_option("--diameter", diameter, "Fiber diameter D (scene units)")
        ->check(CLI::PositiveNumber)
        ->excludes(scene);
    cmd->add_option("--density-multiplier", densityMultiplier,
                    "Real hairs per modeled strand [0.01, 10000]")
        ->excludes(scene);
    cmd->add_option("--voxel-size", voxelSize, "Fiber grid voxel size (default: from the groom)")
        ->check(CLI::PositiveNumber);
}

Scene SceneInput::resolve() const {
    if (sceneFile.empty() && groomFile.empty())
        throw InputError("give a groom file or --scene FILE");
    Scene scene;
    if (!sceneFile.empty()) {
        scene = loadScene(sceneFile);
    } else {
        scene = defaultScene();
        scene.name = groomFile;
        scene.head.reset();
        scene.meshes.clear(); // the default mannequin belongs to the default groom
        scene.fiberScale = FiberScale{};
        scene.groom.file = groomFile;
        scene.fiber = fiber.apply(scene.fiber);
        if (diameter)
            scene.fiberScale.diameter = *diameter;
        if (densityMultiplier)
            scene.fiberScale.densityMultiplier = *densityMultiplier;
    }
    if (voxelSize)
        scene.voxelSize = *voxelSize;
    scene.validate();
    return scene;
}

} // namespace hairvox::cli
