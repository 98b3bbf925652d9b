// What this machine can do at most: the ceilings of the roofline estimate in
// docs/DESIGN.md §7, measured here rather than taken from a data sheet (a
// cloud VM's clock, memory and vector units are whatever the host gives it).
//
// Printed figures (never asserted):
//   BM_StreamTriad        a[i] = b[i] + s·c[i] over arrays far larger than the
//                         caches, 1 and 2 threads: DRAM bandwidth (bytes_per_second)
//   BM_DependentLoad      a pointer chase through a random cycle of 256 MiB: the
//                         latency of one cache miss (ns_per_load), 1 chain and
//                         8 independent chains (what overlapping misses buys)
//   BM_FirstTouch         mapping 256 MiB on huge pages and writing a byte per
//                         4 KiB page (the kernel zeroes each page as it is first
//                         written), then unmapping it: bytes_per_second of first
//                         touch. arg 0: back to back, the pages the last
//                         iteration freed; arg 1: 5 s apart, so that a guest
//                         whose balloon reports free pages to its host has
//                         given them back (DESIGN §7: 14 against 0.63 GB/s here)
//   BM_PeakFma            independent multiply-adds: scalar double, unfused (the
//                         x86-64 baseline the raster is compiled for), and 16-wide
//                         float FMA (AVX-512, the shader's dispatch): FLOP/s
//                         (flops_per_second)
//
//   machine_bench                      # everything (≈ 40 s)
#include <benchmark/benchmark.h>

#include <immintrin.h>
#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <numeric>
#include <random>
#include <thread>
#include <vector>

namespace {

constexpr std::size_t kStreamFloats = std::size_t(1) << 25;

/// Three arrays per thread of 128 MiB each: 12× the last-level cache together.
void BM_StreamTriad(benchmark::State& state) {
    std::vector<float> a(kStreamFloats, 0.0f), b(kStreamFloats, 1.0f), c(kStreamFloats, 2.0f);
    const float s = 0.5f;
    for (auto _ : state) {
        float* __restrict pa = a.data();
        const float* __restrict pb = b.data();
        const float* __restrict pc = c.data();
        for (std::size_t i = 0; i < kStreamFloats; ++i)
            pa[i] = pb[i] + s * pc[i];
        benchmark::DoNotOptimize(a.data());
        benchmark::ClobberMemory();
    }
    // Two arrays read and one written (its cache lines also read first: not counted).
    state.SetBytesProcessed(state.iterations() * 3 * std::int64_t(kStreamFloats) *
                            std::int64_t(sizeof(float)));
}
BENCHMARK(BM_StreamTriad)->Threads(1)->Threads(2)->UseRealTime()->Unit(benchmark::kMillisecond);

/// A random single cycle through `n` slots (Sattolo's algorithm): every load
/// depends on the one before and lands on an unpredictable cache line.
std::vector<std::uint32_t> randomCycle(std::size_t n) {
    std::vector<std::uint32_t> next(n);
    std::iota(next.begin(), next.end(), 0u);
    std::mt19937_64 rng(1);
    for (std::size_t i = n - 1; i > 0; --i) {
        std::uniform_int_distribution<std::size_t> pick(0, i - 1);
        std::swap(next[i], next[pick(rng)]);
    }
    return next;
}

/// arg: independent chains walked together (1: pure latency; 8: the misses
/// an out-of-order core overlaps).
void BM_DependentLoad(benchmark::State& state) {
    constexpr std::size_t kSlots = std::size_t(1) << 26; // 256 MiB of uint32
    static const std::vector<std::uint32_t> next = randomCycle(kSlots);
    const auto chains = static_cast<std::size_t>(state.range(0));
    constexpr std::size_t kSteps = 1 << 20;
    std::vector<std::uint32_t> at(chains);
    for (std::size_t c = 0; c < chains; ++c)
        at[c] = static_cast<std::uint32_t>(c * (kSlots / chains));
    double seconds = 0;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        for (std::size_t step = 0; step < kSteps; ++step)
            for (std::size_t c = 0; c < chains; ++c)
                at[c] = next[at[c]];
        benchmark::DoNotOptimize(at.data());
        seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    const double loads = double(state.iterations()) * double(kSteps) * double(chains);
    state.counters["ns_per_load"] = 1e9 * seconds / loads;
}
BENCHMARK(BM_DependentLoad)->Arg(1)->Arg(8)->UseRealTime()->Unit(benchmark::kMillisecond);

/// Maps 256 MiB on huge pages, writes a byte per 4 KiB page, unmaps it; false
/// if the mapping failed.
bool touchFreshMemory() {
    constexpr std::size_t kBytes = std::size_t(256) << 20, kHuge = std::size_t(2) << 20;
    void* mapped =
        ::mmap(nullptr, kBytes + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapped == MAP_FAILED)
        return false;
    const auto aligned = (reinterpret_cast<std::uintptr_t>(mapped) + kHuge - 1) & ~(kHuge - 1);
    ::madvise(reinterpret_cast<void*>(aligned), kBytes, MADV_HUGEPAGE);
    auto* p = reinterpret_cast<volatile char*>(aligned);
    for (std::size_t i = 0; i < kBytes; i += 4096)
        p[i] = 1;
    ::munmap(mapped, kBytes + kHuge);
    return true;
}

/// arg 0: the pages just freed again (after one untimed round); arg 1: after
/// 5 s idle each time (see the header).
void BM_FirstTouch(benchmark::State& state) {
    const bool idle = state.range(0) == 1;
    if (!idle && !touchFreshMemory())
        state.SkipWithError("mmap failed");
    for (auto _ : state) {
        if (idle) {
            state.PauseTiming();
            std::this_thread::sleep_for(std::chrono::seconds(5));
            state.ResumeTiming();
        }
        if (!touchFreshMemory()) {
            state.SkipWithError("mmap failed");
            return;
        }
    }
    state.SetBytesProcessed(state.iterations() * (std::int64_t(256) << 20));
}
BENCHMARK(BM_FirstTouch)->Arg(0)->Iterations(10)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FirstTouch)->Arg(1)->Iterations(3)->UseRealTime()->Unit(benchmark::kMillisecond);

constexpr int kFmaChains = 16; // independent accumulators: more than latency × issue width
constexpr int kFmaSteps = 1 << 22;

/// Scalar double multiply-add (the x86-64 baseline has no FMA: two flops, two
/// instructions), as the raster's clipping does its arithmetic.
double scalarMulAdd(double x) {
    double acc[kFmaChains];
    for (int k = 0; k < kFmaChains; ++k)
        acc[k] = x + k;
    const double m = 0.999999, a = 1e-7;
    for (int step = 0; step < kFmaSteps; ++step)
        for (int k = 0; k < kFmaChains; ++k)
            acc[k] = acc[k] * m + a;
    return std::accumulate(acc, acc + kFmaChains, 0.0);
}

/// 16-wide float FMA, compiled for AVX-512 (the shading library's widest
/// dispatch target).
__attribute__((target("avx512f"))) float vectorFma(float x) {
    __m512 acc[kFmaChains];
    for (int k = 0; k < kFmaChains; ++k)
        acc[k] = _mm512_set1_ps(x + float(k));
    const __m512 m = _mm512_set1_ps(0.999999f), a = _mm512_set1_ps(1e-7f);
    for (int step = 0; step < kFmaSteps; ++step)
        for (int k = 0; k < kFmaChains; ++k)
            acc[k] = _mm512_fmadd_ps(acc[k], m, a);
    float lanes[16];
    float sum = 0;
    for (int k = 0; k < kFmaChains; ++k) {
        _mm512_storeu_ps(lanes, acc[k]);
        sum = std::accumulate(lanes, lanes + 16, sum);
    }
    return sum;
}

/// arg 0: scalar double mul+add; 1: 16-wide float FMA (skipped without AVX-512).
void BM_PeakFma(benchmark::State& state) {
    const bool vector = state.range(0) == 1;
    if (vector && !__builtin_cpu_supports("avx512f")) {
        state.SkipWithError("no AVX-512 on this CPU");
        return;
    }
    double flops = 0;
    for (auto _ : state) {
        if (vector)
            benchmark::DoNotOptimize(vectorFma(1.0f));
        else
            benchmark::DoNotOptimize(scalarMulAdd(1.0));
        flops += 2.0 * double(kFmaSteps) * double(kFmaChains) * (vector ? 16.0 : 1.0);
    }
    state.counters["flops_per_second"] = benchmark::Counter(flops, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PeakFma)->Arg(0)->Arg(1)->Threads(1)->Threads(2)->UseRealTime()->Unit(
    benchmark::kMillisecond);

} // namespace
