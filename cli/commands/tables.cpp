// hairvox tables [fiber options] -o tables.csv: the dual-scattering tables of
// a hair fiber as CSV, one row per incident inclination θ (shading/
// dual_scattering_tables.h), for plotting a hair colour. Angles are degrees
// on the command line, radians in the CSV.
#include "../commands.h"

#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/shading/dual_scattering_tables.h>
#include <hairvox/shading/fiber_params.h>

#include <chrono>
#include <iostream>
#include <memory>
#include <vector>

namespace hairvox::cli {

namespace {

struct TablesOptions {
    std::string output;
    std::string cacheDir;
    std::vector<float> sigmaA; ///< r,g,b
    std::vector<float> melanin; ///< eumelanin,pheomelanin
    float eta = FiberParams{}.eta;
    float alphaRDeg = degrees(FiberParams{}.alpha_R);
    float betaRDeg = degrees(FiberParams{}.beta_R);
    float eccentricity = FiberParams{}.eccentricity;
    float causticWidthDeg = degrees(FiberParams{}.causticWidth);
    float causticGain = FiberParams{}.causticGain;
    float causticFade = FiberParams{}.causticFade;
    float causticMaxWidth = FiberParams{}.causticMaxWidth;
    float d_b = TableBuildOptions{}.d_b;
    int samples = TableBuildOptions{}.thetaSamples;
};

void runTables(const TablesOptions& opt) {
    FiberParams params;
    params.eta = opt.eta;
    if (!opt.sigmaA.empty())
        params.sigma_a = Rgb(opt.sigmaA[0], opt.sigmaA[1], opt.sigmaA[2]);
    if (!opt.melanin.empty())
        params.sigma_a = FiberParams::sigmaFromMelanin(opt.melanin[0], opt.melanin[1]);
    params.alpha_R = radians(opt.alphaRDeg);
    params.beta_R = radians(opt.betaRDeg);
    params.eccentricity = opt.eccentricity;
    params.causticWidth = radians(opt.causticWidthDeg);
    params.causticGain = opt.causticGain;
    params.causticFade = opt.causticFade;
    params.causticMaxWidth = opt.causticMaxWidth;
    params.validate();

    TableBuildOptions options;
    options.thetaSamples = opt.samples;
    options.d_b = opt.d_b;
    options.validate();

    const auto start = std::chrono::steady_clock::now();
    const std::filesystem::path cacheDir =
        opt.cacheDir.empty() ? defaultTableCacheDir() : std::filesystem::path(opt.cacheDir);
    const DualScatteringTables tables = DualScatteringTables::loadOrBuild(params, cacheDir, options);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    tables.writeCsv(opt.output);

    const std::string cacheFile = DualScatteringTables::cacheFile(cacheDir, params, options).string();
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
    cmd->add_option("--eta", opt->eta, "Index of refraction [1.1, 2.5]")->capture_default_str();
    CLI::Option* sigma = cmd->add_option("--sigma-a", opt->sigmaA,
                                         "Absorption per unit fiber radius r,g,b, each in [0, 50] "
                                         "(default 0.2,0.3,0.5)")
                             ->delimiter(',')
                             ->expected(3);
    cmd->add_option("--melanin", opt->melanin,
                    "Eumelanin,pheomelanin concentrations, each in [0, 20] (sets sigma_a)")
        ->delimiter(',')
        ->expected(2)
        ->excludes(sigma);
    cmd->add_option("--alpha-r", opt->alphaRDeg, "R-lobe shift (deg) [-20, 20]")
        ->capture_default_str();
    cmd->add_option("--beta-r", opt->betaRDeg, "R-lobe width (deg) [0.5, 45]")->capture_default_str();
    cmd->add_option("--eccentricity", opt->eccentricity, "Cross-section eccentricity [0.5, 1]")
        ->capture_default_str();
    cmd->add_option("--caustic-width", opt->causticWidthDeg, "TRT caustic width w_c (deg) [1, 45]")
        ->capture_default_str();
    cmd->add_option("--caustic-gain", opt->causticGain, "TRT caustic gain k_G [0, 10]")
        ->capture_default_str();
    cmd->add_option("--caustic-fade", opt->causticFade, "Caustic fade-out range [0.01, 1]")
        ->capture_default_str();
    cmd->add_option("--caustic-max-width", opt->causticMaxWidth,
                    "Maximum caustic h-interval [0.01, 2]")
        ->capture_default_str();
    cmd->add_option("--d-b", opt->d_b, "Backward density factor in sigma2b [0, 1]")
        ->capture_default_str();
    cmd->add_option("--samples", opt->samples, "Theta samples over [-90, 90] deg [3, 10001]")
        ->capture_default_str();
    cmd->add_option("--cache-dir", opt->cacheDir,
                    "Table cache directory (default $HAIRVOX_CACHE_DIR, $XDG_CACHE_HOME/hairvox "
                    "or ~/.cache/hairvox)");
    cmd->callback([opt] { runTables(*opt); });
}

} // namespace hairvox::cli
