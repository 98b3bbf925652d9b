// hairvox render [SCENE.json] [-o OUT.exr] [--mode exact|grid|approx] [--width W --height H]
//                [--voxel-size V] [--threads N] [--quiet]
// Renders a scene (or the embedded default scene) to EXR + PNG and prints the
// time per stage.
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
    std::string mode;
    std::optional<std::uint32_t> width, height;
    std::optional<float> voxelSize;
    int threads = 0;
    bool quiet = false;
};

void runRender(const RenderCommandOptions& opt) {
    Scene scene = opt.scene.empty() ? defaultScene() : loadScene(opt.scene);
    if (!opt.mode.empty())
        scene.globalTermMode = *kGlobalTermModeNames.parse(opt.mode); // CLI11 checked the choice
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
    const SceneRender render = renderScene(scene, options);
    for (const std::string& warning : render.image.warnings)
        std::cerr << "hairvox: warning: " << warning << "\n";
    if (!opt.quiet)
        printTimingReport(std::cout, scene, render);
    for (const auto& path : render.written)
        std::cout << "wrote " << path.string() << "\n";
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
    cmd->add_option("--mode", opt->mode, "Global-term mode")
        ->check(CLI::IsMember(kGlobalTermModeNames.names()));
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
