// Voxelize benchmark: splatting speed (segments/s) and peak memory for
// procedural wavy grooms of 10k to 1.4M segments at the default voxel size.
// The 1.4M case (50,000 strands × 29 points) is the head of Zinke et al. 2008,
// Fig. 1; the target on a 2-core machine is ≤ 0.5 s for it.
//
//   build/<dir>/bench/voxelize_bench --benchmark_counters_tabular=true
//
// Counters: segments_per_s; voxels (active); grid_MiB (FiberGrid::memoryBytes);
// peak_MiB (resident-set high-water mark during the splat, above the RSS
// before it: the splat's transient memory plus the grid).
#include <hairvox/core/host.h>
#include <hairvox/core/parallel.h>
#include <hairvox/strands/procedural.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <benchmark/benchmark.h>

#include <cstdio>
#include <malloc.h>
#include <map>
#include <string>

namespace hairvox {
namespace {

const Groom& wavyGroom(std::uint32_t strands) {
    static std::map<std::uint32_t, Groom> cache;
    auto it = cache.find(strands);
    if (it == cache.end()) {
        ProceduralGroomParams p;
        p.style = GroomStyle::Wavy;
        p.strands = strands;
        p.pointsPerStrand = 29;
        p.seed = 1;
        it = cache.emplace(strands, generateGroom(p)).first;
    }
    return it->second;
}

/// Returns freed heap to the system, then makes the peak resident set the
/// current one (core/host.h), so that the next peak is this splat's own.
void resetPeakRss() {
    ::malloc_trim(0);
    resetPeakResidentMemory();
}

void splat(benchmark::State& state, bool tensor, int threads) {
    const Groom& groom = wavyGroom(static_cast<std::uint32_t>(state.range(0)));
    const ThreadLimit limit(threads);
    SplatOptions options;
    options.storeOrientationTensor = tensor;
    double peakMiB = 0;
    std::uint64_t voxels = 0, gridBytes = 0;
    for (auto _ : state) {
        state.PauseTiming();
        resetPeakRss();
        const double before = residentBytes();
        state.ResumeTiming();
        const FiberGrid grid = splatStrands(groom, options);
        state.PauseTiming();
        peakMiB = std::max(peakMiB, (peakResidentBytes() - before) / double(1 << 20));
        voxels = grid.activeVoxelCount();
        gridBytes = grid.memoryBytes();
        state.ResumeTiming();
    }
    const auto segments = static_cast<double>(groom.segmentCount());
    state.counters["segments"] = segments;
    state.counters["segments_per_s"] =
        benchmark::Counter(segments, benchmark::Counter::kIsIterationInvariantRate);
    state.counters["voxels"] = static_cast<double>(voxels);
    state.counters["grid_MiB"] = static_cast<double>(gridBytes) / (1 << 20);
    state.counters["peak_MiB"] = peakMiB;
    state.counters["voxel_size_mm"] = defaultVoxelSize(groom) * 1e3;
    state.counters["threads"] = activeThreadCount();
}

void BM_SplatWavy(benchmark::State& state) {
    splat(state, false, 0);
}
void BM_SplatWavyOneThread(benchmark::State& state) {
    splat(state, false, 1);
}
void BM_SplatWavyTensor(benchmark::State& state) {
    splat(state, true, 0);
}

// 358, 3,572, 17,858 and 50,000 strands of 28 segments: 10k, 100k, 500k, 1.4M segments.
BENCHMARK(BM_SplatWavy)
    ->Arg(358)
    ->Arg(3572)
    ->Arg(17858)
    ->Arg(50000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_SplatWavyOneThread)
    ->Arg(3572)
    ->Arg(50000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_SplatWavyTensor)->Arg(50000)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
} // namespace hairvox
