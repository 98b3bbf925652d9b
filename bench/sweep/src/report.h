// hairvox bench (private): the sweep's reports — results.csv (one row per
// measured configuration, columns kBenchCsvColumns), results.md (the summary,
// one table per scene, the scaling tables with their fitted exponents),
// scaling_fits.csv (what the plots draw the fits from) and host.json (the
// machine: bench/host's HostReport, and the load while the sweep ran).
#pragma once

#include <hairvox/bench/host_report.h>
#include <hairvox/bench/sweep.h>

#include <string>
#include <vector>

namespace hairvox::bench {

/// Where and when a sweep ran (recorded in results.md and host.json).
struct RunInfo {
    std::string started;
    HostReport host;
    double loadStart = 0, loadMax = 0, loadEnd = 0;

    /// The start time and this machine now (HostReport::measure(): ≈ 0.3 s).
    static RunInfo now();
};

/// 1-minute load average.
double loadAverage();

/// "exact K=16 (reference)", "grid x1.4", ...
std::string configText(const BenchRow& r);

std::string csvText(const std::vector<BenchRow>& rows);
std::string markdownText(const SweepOptions& o, const SweepResult& result, const RunInfo& info);
/// host.json: HostReport's figures (numbers as numbers), the start time and the load.
std::string hostJsonText(const RunInfo& info);
std::vector<ScalingFit> fitScaling(const std::vector<BenchRow>& rows);
/// kind,stage,exponent,coefficient,r2 per fitted stage.
std::string fitsCsvText(const std::vector<ScalingFit>& fits);

} // namespace hairvox::bench
