// hairvox render [SCENE.json] [-o OUT.exr] [--integrator dual_scattering|path]
//                [--mode exact|grid|approx] [--spp N] [--time-limit S] [--seed S] [--continue]
//                [--width W --height H] [--voxel-size V] [--threads N] [--quiet]
// Renders a scene (or the embedded default scene) to EXR + PNG and prints the
// time per stage. A path trace stopped by Ctrl-C writes the whole passes it
// finished and exits with 130.
#include "../commands.h"

#include <hairvox/core/error.h>
#include <hairvox/core/progress.h>
#include <hairvox/pipeline/pipeline.h>

#include <cstdint>
#include <iostream>
#include <memory>
#include <optional>

namespace hairvox::cli {

namespace {

struct RenderCommandOptions {
    std::string scene;
    std::string output;
    std::string mode, integrator;
    std::optional<std::uint32_t> spp;
    std::optional<double> timeLimit;
    std::optional<std::uint64_t> seed;
    bool continueRun = false;
    std::optional<std::uint32_t> width, height;
    std::optional<float> voxelSize;
    int threads = 0;
    bool quiet = false;
};

void runRender(const RenderCommandOptions& opt) {
    Scene scene = opt.scene.empty() ? defaultScene() : loadScene(opt.scene);
    if (!opt.mode.empty())
        scene.globalTermMode = *kGlobalTermModeNames.parse(opt.mode); // CLI11 checked the choice
    if (!opt.integrator.empty())
        scene.integrator = *kIntegratorNames.parse(opt.integrator);
    if ((opt.spp || opt.timeLimit || opt.seed || opt.continueRun) &&
        scene.integrator != Integrator::Path)
        throw InputError("--spp, --time-limit, --seed and --continue apply to the path integrator "
                         "(--integrator path)");
    if (opt.spp)
        scene.pathTrace.spp = *opt.spp;
    if (opt.timeLimit)
        scene.pathTrace.timeLimit = *opt.timeLimit;
    if (opt.seed)
        scene.pathTrace.seed = *opt.seed;
    if (opt.width)
        scene.camera.width = *opt.width;
    if (opt.height)
        scene.camera.height = *opt.height;
    if (opt.voxelSize)
        scene.voxelSize = *opt.voxelSize;
    if (!opt.output.empty()) {
        scene.output.exr = opt.output;
        scene.output.png = std::filesystem::path(opt.output).replace_extension(".png");
    }
    scene.validate();

    PipelineOptions options;
    options.threads = opt.threads;
    options.progress = !opt.quiet && stderrIsTerminal();
    options.continuePathTrace = opt.continueRun;
    const SceneRender render = renderScene(scene, options);
    for (const std::string& warning : render.warnings)
        std::cerr << "hairvox: warning: " << warning << "\n";
    if (!opt.quiet)
        printTimingReport(std::cout, scene, render);
    for (const auto& path : render.written)
        std::cout << "wrote " << path.string() << "\n";
    if (render.pathTrace && render.pathTrace->interrupted)
        throw Interrupted(strCat("interrupted after ", render.pathTrace->spp, " samples per pixel; ",
                                 render.written.empty()
                                     ? "no output was written"
                                     : "the image holds them (add samples with --continue)"));
}

} // namespace

void addRenderCommand(CLI::App& app) {
    auto opt = std::make_shared<RenderCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render",
        "Render a scene (default: the embedded default scene) to EXR with AOVs and a PNG");
    cmd->add_option("scene", opt->scene,
                    "Scene JSON file (docs/scene.md); omit for the default scene");
    cmd->add_option("-o,--output", opt->output,
                    "Output EXR (the PNG preview goes beside it); default: the scene's outputs");
    cmd->add_option("--integrator", opt->integrator,
                    "dual_scattering (default) or path (the unbiased reference)")
        ->check(CLI::IsMember(kIntegratorNames.names()));
    cmd->add_option("--mode", opt->mode, "Global-term mode (dual scattering)")
        ->check(CLI::IsMember(kGlobalTermModeNames.names()));
    cmd->add_option("--spp", opt->spp, "Path tracing: samples per pixel [1, 1000000]");
    cmd->add_option("--time-limit", opt->timeLimit,
                    "Path tracing: stop after this many seconds (whole passes) [0, 1e7]");
    cmd->add_option("--seed", opt->seed, "Path tracing: random seed");
    cmd->add_flag("--continue", opt->continueRun,
                  "Path tracing: add samples to the output EXR of an earlier run of this scene");
    cmd->add_option("--width", opt->width, "Image width in pixels")->check(CLI::Range(1u, 8192u));
    cmd->add_option("--height", opt->height, "Image height in pixels")
        ->check(CLI::Range(1u, 8192u));
    cmd->add_option("--voxel-size", opt->voxelSize, "Fiber grid voxel size (scene units)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--threads", opt->threads, "Worker threads (0: all cores)")
        ->check(CLI::Range(0, 1024));
    cmd->add_flag("--quiet", opt->quiet, "No progress bar and no timing report");
    cmd->callback([opt] { runRender(*opt); });
}

} // namespace hairvox::cli
