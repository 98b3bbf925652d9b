// hairvox bench (private): the sweep's plots, drawn by matplotlib.
//
// The plotting script (bench/sweep/plot_sweep.py, compiled into the library)
// reads results.csv and scaling_fits.csv from the output directory and writes
// runtime_vs_error.png and scaling.png there. It runs under /usr/bin/python3,
// the interpreter Debian's python3-matplotlib belongs to.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace hairvox::bench {

struct PlotResult {
    std::vector<std::filesystem::path> written;
    std::string problem; ///< why no plot was drawn (empty when they were)
};

/// Writes the script to `workDir` and runs it on `outDir`.
PlotResult drawPlots(const std::filesystem::path& outDir, const std::filesystem::path& workDir);

} // namespace hairvox::bench
