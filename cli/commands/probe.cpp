// hairvox probe (--scene FILE | GROOM [fiber options]) --points IN.csv
//               (--light-dir x,y,z | --light-pos x,y,z) --mode exact|grid|approx
//               [--voxel-size V] [--diameter D] [--rays K --radius R] -o OUT.csv
// hairvox probe (--scene FILE | GROOM) --sample-points N [--seed S] -o IN.csv
// The global term (n, V, P, T_s, σ_f²) toward one light at given points on
// fibers (transmittance/probe.h has the CSV formats).
#include "../commands.h"
#include "../light_option.h"
#include "../scene_input.h"

#include <hairvox/core/parallel.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/transmittance/probe.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

namespace hairvox::cli {

namespace {

struct ProbeOptions {
    SceneInput input;
    LightOption light;
    std::string points;
    std::string output;
    std::string mode = "grid";
    std::optional<std::uint32_t> rays;
    std::optional<float> radius;
    std::optional<std::size_t> samplePoints;
    std::string evaluation = "auto";
    std::uint64_t seed = 1;
    int threads = 0;
};

void runProbe(const ProbeOptions& opt) {
    Scene scene = opt.input.resolve();
    const ThreadLimit threadLimit(opt.threads);
    if (opt.samplePoints) {
        const SceneGroom groom = loadGroom(scene);
        for (const std::string& w : groom.warnings)
            std::cerr << "hairvox: warning: " << w << "\n";
        const std::vector<GlobalTermQuery> points =
            sampleFiberPoints(groom.groom, *opt.samplePoints, opt.seed);
        writeProbePoints(opt.output, points);
        std::cout << "wrote " << opt.output << ": " << points.size() << " points on the fibers of "
                  << scene.name << "\n";
        return;
    }
    if (opt.points.empty())
        throw InputError("give --points IN.csv (or --sample-points N to make one)");
    const Light light = opt.light.resolve();
    scene.globalTermMode = *kGlobalTermModeNames.parse(opt.mode); // CLI11 checked the choice
    if (opt.rays)
        scene.exact.rays = *opt.rays;
    if (opt.radius)
        scene.exact.radius = *opt.radius;
    scene.validate();
    const std::vector<GlobalTermQuery> points = readProbePoints(opt.points);

    const auto start = std::chrono::steady_clock::now();
    PipelineOptions options;
    options.threads = opt.threads;
    // A grid-mode cache costs a fixed ~0.1–1 s per light; a march ~20–40 µs per
    // point (transmittance_bench): below ~20,000 points marching is faster.
    const bool march =
        opt.evaluation == "march" || (opt.evaluation == "auto" && points.size() < 20'000);
    options.grid.evaluation = march ? GridEvaluation::March : GridEvaluation::Cache;
    const std::unique_ptr<SceneAssets> assets = loadSceneAssets(scene, options);
    const auto evaluateStart = std::chrono::steady_clock::now();
    const std::vector<GlobalTerm> terms = evaluateGlobalTerm(*assets->globalTerm, light, points);
    const auto end = std::chrono::steady_clock::now();
    writeProbeResults(opt.output, points, terms);

    double meanV = 0, meanN = 0;
    for (const GlobalTerm& g : terms) {
        meanV += double(g.V) / double(terms.size());
        meanN += double(g.n) / double(terms.size());
    }
    std::printf("wrote %s: %zu points, %s mode, mean n = %.4g, mean V = %.4g\n", opt.output.c_str(),
                points.size(), toString(scene.globalTermMode), meanN, meanV);
    std::printf("time: prepare %.3f s, evaluate %.3f s\n",
                std::chrono::duration<double>(evaluateStart - start).count(),
                std::chrono::duration<double>(end - evaluateStart).count());
}

} // namespace

void addProbeCommand(CLI::App& app) {
    auto opt = std::make_shared<ProbeOptions>();
    CLI::App* cmd = app.add_subcommand(
        "probe", "Global term (n, V, P, T_s, sigma_f^2) toward one light at points on fibers");
    opt->input.add(cmd);
    CLI::Option* points =
        cmd->add_option("--points", opt->points, "Input CSV x,y,z,tx,ty,tz[,strand]");
    cmd->add_option("--sample-points", opt->samplePoints,
                    "Instead: write N random points on the fibers to -o")
        ->check(CLI::Range(std::size_t(1), std::size_t(100'000'000)))
        ->excludes(points);
    cmd->add_option("--seed", opt->seed, "Seed of --sample-points")->capture_default_str();
    opt->light.add(cmd);
    cmd->add_option("--mode", opt->mode, "Global-term mode")
        ->capture_default_str()
        ->check(CLI::IsMember(kGlobalTermModeNames.names()));
    cmd->add_option("--evaluation", opt->evaluation,
                    "Grid/approx: per-light cache or one march per point (auto: march below "
                    "20,000 points)")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "cache", "march"}));
    cmd->add_option("--rays", opt->rays, "Exact mode: rays per point K [1, 65536]");
    cmd->add_option("--radius", opt->radius,
                    "Exact mode: ray origins spread over a disk of this radius");
    cmd->add_option("--threads", opt->threads, "Threads (0: all cores)")
        ->check(CLI::Range(0, 1024));
    cmd->add_option("-o,--output", opt->output, "Output CSV")->required();
    cmd->callback([opt] { runProbe(*opt); });
}

} // namespace hairvox::cli
