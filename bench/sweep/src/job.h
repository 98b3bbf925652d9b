// hairvox bench (private): one job of a sweep — what to render and measure,
// as a JSON file a worker process reads — and the working files that jobs
// share (the scene's reference image and probe references).
//
// Isolation: with a worker command (the CLI passes `hairvox bench --one`),
// every job runs in its own child process, so its peak resident memory
// (its address space's VmHWM, core/host.h) is that job's alone;
// without one (tests) jobs run in the sweep's process and peak memory is not
// reported.
#pragma once

#include <hairvox/bench/sweep.h>

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace hairvox::bench {

struct BenchJob {
    bool reference = false; ///< render the exact reference and write the probe references
    /// Path trace the model sweep's reference (spp, timeLimit) and write its
    /// hair radiance to referenceImage.
    bool pathReference = false;
    std::uint32_t spp = 0;
    double timeLimit = 0;
    /// > 0: the model sweep — compare the hair's radiance with the path-traced
    /// reference as means over block × block pixels.
    int block = 0;
    BenchScene scene;
    BenchConfig config;
    double voxelSize = 0; ///< grid voxel size or exact footprint radius; 0: h0
    int runs = 1;
    double singleRunAbove = 0; ///< seconds; a first run longer than this is the only one
    int threads = 0;
    bool isolated = false;         ///< in its own process: its peak memory is its own
    std::filesystem::path scratch; ///< where the renders write their outputs
    /// Reference: written; configuration: compared against (empty: no image error).
    std::filesystem::path referenceImage;
    std::size_t probePoints = 0;
    std::uint64_t probeSeed = 1;
    std::uint32_t probeRays = 256;
    std::vector<double> probeScales; ///< reference: footprints (× h0) of the probe references
    /// Reference: one per scale (written); configuration: [0] is compared against.
    std::vector<std::filesystem::path> probeFiles;
    std::filesystem::path result;
};

nlohmann::json jobToJson(const BenchJob& job);
BenchJob jobFromJson(const nlohmann::json& j);
nlohmann::json measurementToJson(const BenchMeasurement& m);
BenchMeasurement measurementFromJson(const nlohmann::json& j);

void writeJsonFile(const std::filesystem::path& path, const nlohmann::json& j);
nlohmann::json readJsonFile(const std::filesystem::path& path);

/// A reference image in the sweep's working directory (float, not half: it is compared against).
void writeComparedImage(const std::filesystem::path& path, const ComparedImage& image);
ComparedImage readComparedImage(const std::filesystem::path& path);

/// Global terms per light (outer) and probe point (inner).
void writeProbeTerms(const std::filesystem::path& path,
                     const std::vector<std::vector<GlobalTerm>>& terms);
std::vector<std::vector<GlobalTerm>> readProbeTerms(const std::filesystem::path& path);

/// Runs `command... jobFile` in a child process and waits for it; rethrows
/// its failure (InputError for its exit code 2, Interrupted for 130 or SIGINT).
void runWorker(const std::vector<std::string>& command, const std::filesystem::path& jobFile);

} // namespace hairvox::bench
