// hairvox bench (private): the sweep's reports — results.csv (one row per
// measured configuration, columns kBenchCsvColumns), results.md (the summary,
// one table per scene, the scaling tables with their fitted exponents) and
// scaling_fits.csv (what the plots draw the fits from).
#pragma once

#include <hairvox/bench/sweep.h>

#include <string>
#include <vector>

namespace hairvox::bench {

/// Where and when a sweep ran (recorded in results.md).
struct RunInfo {
    std::string started, cpu;
    unsigned cores = 0;
    double loadStart = 0, loadMax = 0, loadEnd = 0;

    /// The start time, CPU model and core count of this machine now.
    static RunInfo now();
};

/// 1-minute load average.
double loadAverage();

/// "exact K=16 (reference)", "grid x1.4", ...
std::string configText(const BenchRow& r);

std::string csvText(const std::vector<BenchRow>& rows);
std::string markdownText(const SweepOptions& o, const SweepResult& result, const RunInfo& info);
std::vector<ScalingFit> fitScaling(const std::vector<BenchRow>& rows);
/// kind,stage,exponent,coefficient,r2 per fitted stage.
std::string fitsCsvText(const std::vector<ScalingFit>& fits);

} // namespace hairvox::bench
