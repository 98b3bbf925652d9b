// The main() of every Google Benchmark program in bench/: Google Benchmark's
// own (BENCHMARK_MAIN), with the host the figures come from in the context
// block it prints and in --benchmark_format=json's "context" (bench/host:
// CPU model, logical cores, SIMD target, a short calibration), measured before
// the benchmarks run.
#include <hairvox/bench/host_report.h>

#include <benchmark/benchmark.h>

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv))
        return 1;
    for (const auto& [key, value] : hairvox::bench::HostReport::measure().entries())
        benchmark::AddCustomContext("host_" + key, value);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
