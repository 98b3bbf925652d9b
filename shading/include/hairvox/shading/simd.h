// hairvox shading: the SIMD instruction set the shading kernels run on, and
// its peak multiply-add rate. Highway compiles the kernels once per target
// (foreach_target.h) and dispatches each call to the best target this CPU
// supports: on the farm's AVX-512 hosts "AVX3", on AVX2-only ones "AVX2".
// A figure measured on one is not a figure for the other (issue 40): the
// benchmarks print this beside their timings (bench/host).
#pragma once

#include <string>

namespace hairvox {

/// The target the shading kernels dispatch to on this CPU: hwy::TargetName
/// of the code that runs ("AVX3" for AVX-512, "AVX2", "SSE4", "SSE2",
/// "NEON", "EMU128", ...).
std::string simdTarget();

/// The peak multiply-add rate of the target the shading library dispatches to.
struct SimdFmaPeak {
    std::string target;        ///< the target the loop ran on: simdTarget()'s
    double flopsPerSecond = 0; ///< 2 a lane and FMA, one thread
};

/// Independent float FMA chains at the dispatched target's full vector
/// width, one thread, the best of three short passes (a few milliseconds with
/// AVX-512, ~0.1 s at most on the baseline).
SimdFmaPeak simdFmaPeak();

} // namespace hairvox
