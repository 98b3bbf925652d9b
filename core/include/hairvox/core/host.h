// hairvox core: the machine a figure was measured on — its CPU model and
// logical core count, and a short calibration of its ceilings — so that
// timings from different hosts (the farm draws from several CPU types) can be
// told apart and compared. The SIMD target the kernels dispatch to is the
// shading library's (shading/simd.h); bench/host joins the two for the
// benchmark programs and `hairvox bench`.
//
// The calibration is a fraction of a second of bench/machine_bench.cpp's
// ceilings (docs/DESIGN.md §7's roofline): the STREAM triad a[i] = b[i] + s·c[i]
// over arrays three times the last-level cache (DRAM bandwidth, one
// thread), a pointer chase through cache lines of an array as large in a
// scattered order (the latency of one miss, TLB misses included), and independent double
// multiply-adds as the x86-64 baseline compiles them (SSE2, no FMA: the raster's arithmetic; the
// SIMD kernels' FMA peak is shading/simd.h's). It is short, so it is a few percent noisier than
// machine_bench, and a busy machine lowers it: it names the host, it does not replace
// machine_bench.
#pragma once

#include <ostream>
#include <string>

namespace hairvox {

/// The CPU model and logical cores of this machine.
struct HostInfo {
    /// /proc/cpuinfo's "model name" (or "CPU" on Arm); "unknown CPU" when absent.
    std::string cpuModel;
    /// Logical cores this process may run on (its affinity mask; the machine's
    /// when that cannot be read): what "all cores" means to TBB here.
    unsigned logicalCores = 1;

    static HostInfo current();
};

/// The measured ceilings (one thread each).
struct MachineCalibration {
    double dramBytesPerSecond = 0; ///< STREAM triad: 2 arrays read, 1 written
    double missLatencyNs = 0;      ///< one dependent load to a random line of DRAM
    double baselineFlopsPerSecond =
        0;                      ///< double multiply + add, unfused, as the baseline compiles it
    std::size_t arrayBytes = 0; ///< the triad's three arrays together
    double seconds = 0;         ///< what the calibration took, allocation included
};

/// Measures the ceilings above in about 0.2–0.4 s on a quiet machine (arrays
/// of 3× the L3 cache, between 96 and 384 MiB, mapped and unmapped here), then
/// resets this process's peak resident memory (resetPeakResidentMemory) so
/// that a peak measured after it is the program's own, not the calibration's.
MachineCalibration calibrateMachine();

/// This process's resident memory in bytes (Linux /proc/self/status; 0 where
/// unreadable): now (VmRSS), and its peak (VmHWM) since the program started or
/// since resetPeakResidentMemory(). The peak is this address space's own: a
/// program started by another does not inherit its parent's, as getrusage's
/// ru_maxrss does across execve (a benchmark's workers would each report at
/// least their parent's peak).
double residentBytes();
double peakResidentBytes();
/// Makes the peak the current resident set (5 into /proc/self/clear_refs;
/// Linux ≥ 4.0, elsewhere the peak stays).
void resetPeakResidentMemory();

std::ostream& operator<<(std::ostream& os, const HostInfo& h);
std::ostream& operator<<(std::ostream& os, const MachineCalibration& c);

} // namespace hairvox
