// hairvox transmittance (--scene FILE | GROOM [fiber options])
//                       (--light-dir x,y,z | --light-pos x,y,z) [--mode grid|approx|exact]
//                       [--voxel-size V] -o lit.vdb
// The global term toward one light at every active voxel of the fiber grid,
// written as a .vdb (n, V, T_s, sigma2_f) for any VDB viewer.
#include "../commands.h"
#include "../light_option.h"
#include "../scene_input.h"

#include <hairvox/core/error.h>
#include <hairvox/core/parallel.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/transmittance/lit_grid.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <sstream>

namespace hairvox::cli {

namespace {

struct TransmittanceOptions {
    SceneInput input;
    LightOption light;
    std::string mode = "grid";
    std::string output;
    int threads = 0;
};

std::string describe(const Light& light) {
    std::ostringstream os;
    os << light;
    return os.str();
}

void runTransmittance(const TransmittanceOptions& opt) {
    Scene scene = opt.input.resolve();
    const Light light = opt.light.resolve();
    scene.globalTermMode = *kGlobalTermModeNames.parse(opt.mode); // CLI11 checked the choice
    const ThreadLimit threadLimit(opt.threads);
    const auto start = std::chrono::steady_clock::now();
    PipelineOptions options;
    options.threads = opt.threads;
    const std::unique_ptr<SceneAssets> assets = loadSceneAssets(scene, options);
    if (!assets->grid) { // exact mode builds no grid: the voxels to query come from one
        checkVoxelSizeForGroom(scene, assets->groom.groom);
        SplatOptions splat;
        splat.voxelSize = scene.voxelSize.value_or(0.0f);
        splat.fiberScale = scene.fiberScale;
        splat.sourceFile = scene.groom.file.string();
        assets->grid = std::make_shared<const FiberGrid>(splatStrands(assets->groom.groom, splat));
    }
    const LitGrid lit = evaluateOnFiberGrid(*assets->grid, *assets->globalTerm->forLight(light));
    const auto evaluated = std::chrono::steady_clock::now();
    const FiberGridInfo& info = assets->grid->info;
    writeLitGrid(
        opt.output, lit,
        litGridMetadata(light, scene.globalTermMode, info, scene.fiber, scene.dualScattering));
    std::printf("wrote %s: global term (%s mode) at %llu voxels of %.4g toward %s\n",
                opt.output.c_str(), toString(scene.globalTermMode),
                static_cast<unsigned long long>(lit.stats.queries), info.voxelSize,
                describe(light).c_str());
    std::printf(
        "time: %.3f s (write %.3f s)\n",
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
        std::chrono::duration<double>(std::chrono::steady_clock::now() - evaluated).count());
}

} // namespace

void addTransmittanceCommand(CLI::App& app) {
    auto opt = std::make_shared<TransmittanceOptions>();
    CLI::App* cmd = app.add_subcommand(
        "transmittance",
        "Write the global term toward one light at every voxel of the fiber grid (.vdb)");
    opt->input.add(cmd);
    opt->light.add(cmd);
    cmd->add_option("--mode", opt->mode, "Global-term mode")
        ->capture_default_str()
        ->check(CLI::IsMember(kGlobalTermModeNames.names()));
    cmd->add_option("--threads", opt->threads, "Threads (0: all cores)")
        ->check(CLI::Range(0, 1024));
    cmd->add_option("-o,--output", opt->output, "Output .vdb")->required();
    cmd->callback([opt] { runTransmittance(*opt); });
}

} // namespace hairvox::cli
