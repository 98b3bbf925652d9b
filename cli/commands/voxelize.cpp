// hairvox voxelize HAIRFILE -o grid.vdb [--voxel-size V | --voxels-across N] [--diameter D]
//                  [--density-scale K] [--orientation-tensor] [--threads N] [--memory-budget GIB]
#include "../commands.h"

#include <hairvox/core/error.h>
#include <hairvox/core/format.h>
#include <hairvox/core/parallel.h>
#include <hairvox/core/progress.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace hairvox::cli {

namespace {

/// Bytes in GiB, to 3 significant digits.
std::string gib(std::uint64_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", double(bytes) / double(1ull << 30));
    return text;
}

struct VoxelizeOptions {
    std::string input;
    std::string output;
    double voxelSize = 0;
    int voxelsAcross = kDefaultVoxelsAcross;
    FiberScale fiberScale;
    bool tensor = false;
    int threads = 0;
    double memoryBudgetGiB = double(SplatOptions{}.memoryBudgetBytes) / double(1ull << 30);
};

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void runVoxelize(const VoxelizeOptions& opt) {
    const ThreadLimit threadLimit(opt.threads);
    auto start = std::chrono::steady_clock::now();
    const LoadedGroom loaded = readGroom(opt.input);
    const double readSeconds = secondsSince(start);
    std::vector<std::string> warnings = loaded.warnings;
    if (loaded.sanitized.droppedSegments > 0)
        warnings.push_back(
            strCat("dropped ", loaded.sanitized.droppedSegments, " zero-length segment(s)"));
    if (loaded.sanitized.droppedStrands > 0)
        warnings.push_back(
            strCat("dropped ", loaded.sanitized.droppedStrands, " strand(s) of coincident points"));
    for (const std::string& w : warnings)
        std::fprintf(stderr, "hairvox: warning: %s: %s\n", opt.input.c_str(), w.c_str());

    SplatOptions splat;
    splat.voxelSize =
        opt.voxelSize > 0 ? opt.voxelSize : defaultVoxelSize(loaded.groom, opt.voxelsAcross);
    splat.fiberScale = opt.fiberScale;
    splat.storeOrientationTensor = opt.tensor;
    splat.memoryBudgetBytes = static_cast<std::uint64_t>(opt.memoryBudgetGiB * double(1ull << 30));
    splat.forVdbFile = true;
    splat.sourceFile = opt.input;
    splat.showProgress = stderrIsTerminal();
    start = std::chrono::steady_clock::now();
    const FiberGrid grid = splatStrands(loaded.groom, splat);
    const double splatSeconds = secondsSince(start);
    for (const std::string& w : grid.warnings)
        std::fprintf(stderr, "hairvox: warning: %s: %s\n", opt.input.c_str(), w.c_str());

    // The file is OpenVDB's grids, whose dense leaves the packed grid does
    // not have. The splat refused what its estimate of them could not fit;
    // now that the blocks are counted, refuse before building them what the
    // budget cannot hold.
    const std::uint64_t vdbBytes = vdbMemoryBytes(grid);
    if (grid.memoryBytes() + vdbBytes > splat.memoryBudgetBytes)
        throw InputError(strCat(opt.output, ": writing the fiber grid needs its OpenVDB leaves, ",
                                gib(vdbBytes), " GiB beside the grid's ", gib(grid.memoryBytes()),
                                " GiB, over the memory budget of ", opt.memoryBudgetGiB,
                                " GiB; use a larger voxel size or --memory-budget"));
    start = std::chrono::steady_clock::now();
    writeFiberGrid(opt.output, grid);
    const double writeSeconds = secondsSince(start);

    const Vec3f extent = loaded.groom.bounds().extent();
    const double longest = double(std::max({extent.x, extent.y, extent.z}));
    std::printf("wrote %s\n", opt.output.c_str());
    std::printf("voxel size:     %.6g (%.0f voxels across the groom)\n", grid.info.voxelSize,
                longest > 0 ? std::ceil(longest / grid.info.voxelSize) : 0.0);
    std::printf("active voxels:  %s\n", thousands(grid.activeVoxelCount()).c_str());
    std::printf("memory:         %.1f MiB (%s), %.1f MiB as the file's OpenVDB grids\n",
                double(grid.memoryBytes()) / double(1 << 20),
                grid.hasTensor() ? "density, orientation, orientation tensor"
                                 : "density, orientation",
                double(vdbBytes) / double(1 << 20));
    std::printf("fiber length:   %.6g in %s strands, %s segments\n", grid.info.totalLength,
                thousands(grid.info.strands).c_str(), thousands(grid.info.segments).c_str());
    std::printf("time:           read %.3f s, voxelize %.3f s (%d threads), write %.3f s\n",
                readSeconds, splatSeconds, activeThreadCount(), writeSeconds);
}

} // namespace

void addVoxelizeCommand(CLI::App& app) {
    auto opt = std::make_shared<VoxelizeOptions>();
    CLI::App* cmd =
        app.add_subcommand("voxelize", "Splat a groom into an OpenVDB fiber grid (.vdb)");
    cmd->add_option("file", opt->input, "Groom file (.hair, .tfx, .obj)")->required();
    cmd->add_option("-o,--output", opt->output, "Output .vdb file")->required();
    CLI::Option* size = cmd->add_option("--voxel-size", opt->voxelSize,
                                        "Voxel size in the groom's units (default: from "
                                        "--voxels-across)")
                            ->check(CLI::PositiveNumber);
    CLI::Option* across =
        cmd->add_option("--voxels-across", opt->voxelsAcross,
                        "Voxels across the longest side of the groom's bounding box")
            ->capture_default_str()
            ->check(CLI::Range(1, 1 << 20));
    size->excludes(across);
    cmd->add_option("--diameter", opt->fiberScale.diameter,
                    "Fiber diameter D (scene units), recorded in the grid (0, 1000]")
        ->capture_default_str();
    cmd->add_option("--density-multiplier", opt->fiberScale.densityMultiplier,
                    "Real hairs per modeled strand, recorded in the grid [0.01, 10000]")
        ->capture_default_str();
    cmd->add_flag("--orientation-tensor", opt->tensor,
                  "Also store the second moment E[u u^T] of the fiber directions");
    cmd->add_option("--threads", opt->threads, "Threads (0: all cores)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1024));
    cmd->add_option("--memory-budget", opt->memoryBudgetGiB,
                    "Refuse voxel sizes estimated to need more memory than this (GiB)")
        ->capture_default_str()
        ->check(CLI::Range(0.001, 1e6));
    cmd->callback([opt] { runVoxelize(*opt); });
}

} // namespace hairvox::cli
