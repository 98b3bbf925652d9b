// hairvox bench: the host a benchmark ran on, as every benchmark program and
// `hairvox bench` print it, so that figures from the farm's different hosts
// (AVX-512 and AVX2-only EPYCs, issue 40) are never compared unawares:
// the CPU model and logical cores (core/host.h), the SIMD target the shading
// kernels dispatch to and its FMA peak (shading/simd.h), and a calibration of
// the machine's ceilings (core/host.h: DRAM bandwidth, miss latency, baseline
// double FLOP/s; bench/machine_bench.cpp measures them at length).
//
// Here, not in core: the report joins core's host with shading's SIMD target,
// and core cannot link shading (docs/DESIGN.md §1). Google Benchmark programs
// get it through bench/benchmark_main.cpp (benchmark::AddCustomContext: the
// context block and --benchmark_format=json's "context"); the sweep writes it
// to results.md and host.json.
#pragma once

#include <hairvox/core/host.h>

#include <string>
#include <utility>
#include <vector>

namespace hairvox::bench {

struct HostReport {
    HostInfo host;
    std::string simdTarget;           ///< shading/simd.h simdTarget()
    double simdFmaFlopsPerSecond = 0; ///< at that target's width, one thread
    MachineCalibration calibration;

    /// Measures this machine now (≈ 0.3 s: the calibration).
    static HostReport measure();

    /// (key, value) pairs, values as text, keys in snake_case with units:
    /// cpu_model, logical_cores, simd_target, simd_fma_gflops, dram_gb_per_s,
    /// miss_latency_ns, baseline_gflops, calibration_s.
    std::vector<std::pair<std::string, std::string>> entries() const;

    /// One line for a report's header: "AMD EPYC, 2 logical cores, SIMD AVX3
    /// (FMA 98.1 GFLOP/s); DRAM 11.2 GB/s (triad, 1 thread), miss 98 ns, ...".
    std::string line() const;
};

std::ostream& operator<<(std::ostream& os, const HostReport& r);

} // namespace hairvox::bench
