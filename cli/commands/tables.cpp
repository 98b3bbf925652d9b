// hairvox tables [--scene FILE | fiber options] -o tables.csv: the dual-
// scattering tables of a hair fiber as CSV, one row per incident inclination θ
// (shading/dual_scattering_tables.h), for plotting a hair colour. Angles are
// degrees on the command line, radians in the CSV.
#include "../commands.h"
#include "../scene_input.h"

#include <hairvox/pipeline/scene.h>
#include <hairvox/shading/dual_scattering_tables.h>

#include <chrono>
#include <iostream>
#include <memory>

namespace hairvox::cli {

namespace {

struct TablesOptions {
    std::string output;
    std::string sceneFile;
    std::string cacheDir;
    FiberOptions fiber;
    float d_b = TableBuildOptions{}.d_b;
    int samples = TableBuildOptions{}.thetaSamples;
};

void runTables(const TablesOptions& opt) {
    TableBuildOptions options;
    options.thetaSamples = opt.samples;
    FiberParams params;
    if (!opt.sceneFile.empty()) {
        const Scene scene = loadScene(opt.sceneFile);
        params = scene.fiber;
        options.d_b = scene.dualScattering.d_b;
    } else {
        params = opt.fiber.apply(FiberParams{});
        options.d_b = opt.d_b;
    }
    options.validate();

    const auto start = std::chrono::steady_clock::now();
    const std::filesystem::path cacheDir =
        opt.cacheDir.empty() ? defaultTableCacheDir() : std::filesystem::path(opt.cacheDir);
    const DualScatteringTables tables =
        DualScatteringTables::loadOrBuild(params, cacheDir, options);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    tables.writeCsv(opt.output);

    const std::string cacheFile =
        DualScatteringTables::cacheFile(cacheDir, params, options).string();
    std::cout << "wrote " << opt.output << ": " << tables.size()
              << " theta samples over [-90, 90] deg for " << params << "\n";
    if (tables.loadedFromCache())
        std::cout << "tables loaded from the cache " << cacheFile << "\n";
    else
        std::cout << "tables built in " << seconds << " s, cached as " << cacheFile << "\n";
}

} // namespace

void addTablesCommand(CLI::App& app) {
    auto opt = std::make_shared<TablesOptions>();
    CLI::App* cmd = app.add_subcommand(
        "tables", "Write the dual-scattering tables of a hair fiber as CSV (one row per theta)");
    cmd->add_option("-o,--output", opt->output, "Output CSV file")->required();
    CLI::Option* scene = cmd->add_option("--scene", opt->sceneFile,
                                         "Take the fiber optics and d_b from a scene file");
    for (CLI::Option* o : opt->fiber.add(cmd))
        o->excludes(scene);
    cmd->add_option("--d-b", opt->d_b, "Backward density factor in sigma2b [0, 1]")
        ->capture_default_str()
        ->excludes(scene);
    cmd->add_option("--samples", opt->samples, "Theta samples over [-90, 90] deg [3, 10001]")
        ->capture_default_str();
    cmd->add_option("--cache-dir", opt->cacheDir,
                    "Table cache directory (default $HAIRVOX_CACHE_DIR, $XDG_CACHE_HOME/hairvox "
                    "or ~/.cache/hairvox)");
    cmd->callback([opt] { runTables(*opt); });
}

} // namespace hairvox::cli
