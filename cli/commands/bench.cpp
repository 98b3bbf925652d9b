// hairvox bench [--scene FILE ...] [--out DIR] [--quick] [--threads N] [--runs N] [--no-scaling]
//               [--no-accuracy] [--no-model] [--hair NAME ...] [--model-spp N]
//               [--frontier-spp N ...] [--frontier-paths N ...]
// Sweeps global-term mode × voxel size × shading rate against exact-mode
// references, dual scattering against the path tracer (the model sweep), then
// time and memory against segment count, image size and active voxels
// (bench/sweep); writes results.csv, results.md and PNG plots.
// `hairvox bench --one JOB.json` is the worker that runs one job of a sweep in
// its own process (so that its peak memory is its own).
#include "../commands.h"

#include <hairvox/bench/sweep.h>
#include <hairvox/core/error.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace hairvox::cli {

namespace {

struct BenchOptions {
    std::vector<std::string> scenes;
    std::string out = "bench";
    bool quick = false;
    int threads = 0;
    std::optional<int> runs;
    bool noScaling = false;
    bool noModel = false;
    bool noAccuracy = false;
    std::vector<std::string> hair;
    std::optional<std::uint32_t> modelSpp;
    std::optional<std::vector<std::uint32_t>> frontierSpp;
    std::optional<std::vector<float>> frontierPaths;
    std::string job;
};

/// The command that regenerates the results, as recorded in results.md.
std::string commandLine(const BenchOptions& opt) {
    std::string line = "hairvox bench";
    for (const std::string& s : opt.scenes)
        line += " --scene " + s;
    line += " --out " + opt.out;
    if (opt.quick)
        line += " --quick";
    if (opt.threads > 0)
        line += " --threads " + std::to_string(opt.threads);
    if (opt.runs)
        line += " --runs " + std::to_string(*opt.runs);
    if (opt.noScaling)
        line += " --no-scaling";
    if (opt.noModel)
        line += " --no-model";
    if (opt.noAccuracy)
        line += " --no-accuracy";
    for (const std::string& h : opt.hair)
        line += " --hair " + h;
    if (opt.modelSpp)
        line += " --model-spp " + std::to_string(*opt.modelSpp);
    if (opt.frontierSpp)
        for (const std::uint32_t n : *opt.frontierSpp)
            line += " --frontier-spp " + std::to_string(n);
    if (opt.frontierPaths)
        for (const float n : *opt.frontierPaths)
            line += strCat(" --frontier-paths ", n);
    return line;
}

void runBench(const BenchOptions& opt) {
    if (!opt.job.empty()) {
        runBenchJobFile(opt.job);
        return;
    }
    SweepOptions sweep =
        opt.quick ? SweepOptions::quick("data/scenes") : SweepOptions::full("data/scenes");
    if (!opt.scenes.empty()) {
        // The model sweep path traces the given scenes at its own width.
        const std::uint32_t modelWidth =
            sweep.model.scenes.empty() ? 256 : sweep.model.scenes.front().width;
        sweep.scenes.clear();
        sweep.model.scenes.clear();
        for (const std::string& file : opt.scenes) {
            BenchScene scene;
            scene.file = std::filesystem::absolute(file);
            scene.label = scene.file.stem().string();
            sweep.scenes.push_back(scene);
            if (std::filesystem::exists(scene.file))
                sweep.model.scenes.push_back(scene.atWidth(modelWidth));
        }
    }
    if (opt.noModel)
        sweep.model.scenes.clear();
    if (opt.noAccuracy)
        sweep.scenes.clear();
    if (opt.noScaling) {
        sweep.segmentScaling.clear();
        sweep.pixelScaling.clear();
        sweep.voxelScaling.clear();
    }
    if (!opt.hair.empty()) {
        std::vector<std::pair<std::string, float>> melanins;
        for (const std::string& name : opt.hair) {
            const auto known =
                std::find_if(sweep.model.melanins.begin(), sweep.model.melanins.end(),
                             [&](const auto& m) { return m.first == name; });
            if (known == sweep.model.melanins.end())
                throw InputError(strCat("bench --hair ", name, ": expected blond, medium or dark"));
            melanins.push_back(*known);
        }
        sweep.model.melanins = melanins;
    }
    if (opt.modelSpp)
        sweep.model.spp = *opt.modelSpp;
    if (opt.frontierSpp)
        sweep.model.frontierSpp = *opt.frontierSpp;
    if (opt.frontierPaths)
        sweep.model.frontierPathsPerCell = *opt.frontierPaths;
    if (opt.runs)
        sweep.runs = *opt.runs;
    sweep.threads = opt.threads;
    sweep.outDir = opt.out;
    sweep.workerCommand = {std::filesystem::read_symlink("/proc/self/exe").string(), "bench",
                           "--one"};
    sweep.commandLine = commandLine(opt);
    sweep.log = &std::cout;
    const SweepResult result = runSweep(sweep);
    for (const auto& path : result.written)
        std::cout << "wrote " << path.string() << "\n";
}

} // namespace

void addBenchCommand(CLI::App& app) {
    auto opt = std::make_shared<BenchOptions>();
    CLI::App* cmd = app.add_subcommand(
        "bench", "Benchmark: run time against error per mode, voxel size and shading rate, and "
                 "how cost grows with segment count, image size and voxel size");
    cmd->add_option("--scene", opt->scenes,
                    "Scene JSON file(s) to sweep instead of the default set (repeatable)");
    cmd->add_option("-o,--out", opt->out, "Output directory (results.csv, results.md, PNG plots)");
    cmd->add_flag("--quick", opt->quick,
                  "A representative subset, 3-7 minutes on a 2-core machine: 2 scenes at 512², 3 "
                  "voxel sizes, fragment shading, 1 run each; the model sweep at 128², 64 spp; "
                  "a short scaling sweep");
    cmd->add_option("--threads", opt->threads, "Worker threads (0: all cores)")
        ->check(CLI::Range(0, 1024));
    cmd->add_option("--runs", opt->runs, "Timed renders per configuration (default 3; --quick: 1)")
        ->check(CLI::Range(1, 100));
    cmd->add_flag("--no-scaling", opt->noScaling, "Skip the scaling sweep");
    cmd->add_flag("--no-accuracy", opt->noAccuracy,
                  "Skip the accuracy sweep (modes and voxel sizes against exact mode)");
    cmd->add_flag("--no-model", opt->noModel,
                  "Skip the model sweep (dual scattering against the path tracer)");
    cmd->add_option("--hair", opt->hair,
                    "The model sweep's hair colours (blond, medium, dark; default all three)");
    cmd->add_option("--model-spp", opt->modelSpp,
                    "Samples per pixel of the model sweep's path-traced references (default 1024; "
                    "--quick: 64)")
        ->check(CLI::Range(2, 1000000));
    cmd->add_option("--frontier-spp", opt->frontierSpp,
                    "The frontier's path tracer at these samples per pixel, each below --model-spp "
                    "(default 4 16 64 256; --quick: 4 16)")
        ->expected(0, -1);
    cmd->add_option("--frontier-paths", opt->frontierPaths,
                    "The frontier's volumetric integrator also at these paths per cache cell "
                    "(default 3 48; --quick: 4)")
        ->expected(0, -1);
    cmd->add_option("--one", opt->job, "Run one job of a sweep (internal)")->group("");
    cmd->callback([opt] { runBench(*opt); });
}

} // namespace hairvox::cli
