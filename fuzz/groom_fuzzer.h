// hairvox fuzzing: the oracle shared by the groom reader fuzzers.
//
// A reader given arbitrary bytes either throws InputError or returns a groom
// that every later stage may rely on (strands/groom.h): strand offsets that
// partition the points, at least 2 points per strand, finite coordinates,
// optional attributes with one value per point. Anything else — a crash, a
// sanitizer report, another exception type, a broken invariant — is a finding.
#pragma once

#include <hairvox/core/error.h>
#include <hairvox/strands/groom_io.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <string>

namespace hairvox::fuzz {

/// Reports a broken invariant and aborts (libFuzzer saves the input).
[[noreturn]] inline void violated(const char* what) {
    std::fprintf(stderr, "hairvox fuzz: invariant violated: %s\n", what);
    std::abort();
}

inline void checkGroom(const Groom& g) {
    const std::size_t n = g.pointCount();
    if (g.strandStart.empty()) {
        if (n != 0)
            violated("points without strands");
        return;
    }
    if (g.strandStart.front() != 0 || g.strandStart.back() != n)
        violated("strand offsets do not span the points");
    for (std::size_t s = 0; s < g.strandCount(); ++s) {
        if (g.strandStart[s + 1] < g.strandStart[s] + 2)
            violated("a strand with fewer than 2 points");
        for (const Vec3f& p : g.strand(s))
            if (!isFinite(p))
                violated("a non-finite point");
    }
    for (std::size_t size : {g.thickness.size(), g.transparency.size(), g.color.size()})
        if (size != 0 && size != n)
            violated("an attribute array without one value per point");
    (void)computeStats(g);
    (void)contentHash(g);
}

/// The body of LLVMFuzzerTestOneInput for one reader.
template <typename Parse>
int fuzzGroomReader(Parse parse, const std::uint8_t* data, std::size_t size) {
    GroomReadOptions options;
    // Keep allocations far below libFuzzer's -rss_limit_mb: a file of a few
    // kB must not ask for more (the limit is part of what is tested).
    options.maxPoints = std::uint64_t(1) << 20;
    try {
        const LoadedGroom loaded = parse(std::span<const unsigned char>(data, size),
                                         std::string("fuzz-input"), options);
        checkGroom(loaded.groom);
    } catch (const InputError&) {
        // The expected outcome for malformed input.
    }
    return 0;
}

} // namespace hairvox::fuzz
