// The EXR chunk codec (film/exr_codec.h) against OpenEXR's own byte loops:
// the same predicted bytes and the same run-length code, byte for byte, on
// inputs made to hit every branch of the parse (runs of 1 to 300, literals
// cut at 127, ends inside a run of two) and on every small size — with every
// SIMD target this CPU runs (AVX-512, AVX2, SSE4, the portable baseline).
#include "test_util.h"

#include <hairvox/core/rng.h>
#include <hairvox/film/exr_codec.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace hairvox {
namespace {

using Bytes = std::vector<std::uint8_t>;

// OpenEXR 3.1.5, src/lib/OpenEXRCore/internal_rle.c (BSD-3-Clause, Copyright
// Contributors to the OpenEXR Project): reorder_and_predict and
// internal_rle_compress, as they are but for the early stop on a full buffer.
Bytes openexrPredict(const Bytes& packed) {
    Bytes t(packed.size());
    std::size_t t1 = 0, t2 = (packed.size() + 1) / 2;
    for (std::size_t in = 0; in < packed.size();) {
        t[t1++] = packed[in++];
        if (in < packed.size())
            t[t2++] = packed[in++];
    }
    if (t.empty())
        return t;
    int p = t[0];
    for (std::size_t i = 1; i < t.size(); ++i) {
        const int d = int(t[i]) - p + (128 + 256);
        p = t[i];
        t[i] = static_cast<std::uint8_t>(d);
    }
    return t;
}

Bytes openexrRle(const Bytes& src) {
    constexpr int kMinRunLength = 3, kMaxRunLength = 127;
    Bytes out;
    if (src.empty()) // (OpenEXR never calls it so: no pointer arithmetic on null)
        return out;
    const auto* runs = reinterpret_cast<const std::int8_t*>(src.data());
    const std::int8_t* end = runs + src.size();
    const std::int8_t* rune = runs + 1;
    while (runs < end) {
        std::uint8_t curcount = 0;
        while (rune < end && *runs == *rune && curcount < kMaxRunLength) {
            ++rune;
            ++curcount;
        }
        if (curcount >= kMinRunLength - 1) {
            out.push_back(curcount);
            out.push_back(static_cast<std::uint8_t>(*runs));
            runs = rune;
        } else {
            ++curcount;
            while (rune < end &&
                   ((rune + 1 >= end || *rune != *(rune + 1)) ||
                    (rune + 2 >= end || *(rune + 1) != *(rune + 2))) &&
                   curcount < kMaxRunLength) {
                ++curcount;
                ++rune;
            }
            out.push_back(static_cast<std::uint8_t>(-int(curcount)));
            while (runs < rune)
                out.push_back(static_cast<std::uint8_t>(*runs++));
        }
        ++rune;
    }
    return out;
}

/// The run-length code of `predicted` against OpenEXR's.
void expectOpenExrRle(const Bytes& predicted, const std::string& what) {
    const std::size_t n = predicted.size();
    Bytes code(detail::rleCapacity(n));
    std::vector<std::uint64_t> scratch(detail::rleScratchWords(n));
    const std::size_t size = detail::rleCompress(predicted.data(), n, scratch.data(), code.data());
    const Bytes expected = openexrRle(predicted);
    if (expected.size() >= n) { // stored raw: only "not shorter" has to agree
        EXPECT_GE(size, n) << what << ", " << n << " bytes";
        return;
    }
    ASSERT_EQ(size, expected.size()) << what << ", " << n << " bytes";
    code.resize(size);
    ASSERT_EQ(code, expected) << what << ", " << n << " bytes";
}

/// Both steps against OpenEXR's on one packed chunk.
void expectOpenExrBytes(const Bytes& packed, const std::string& what) {
    Bytes predicted(packed.size());
    detail::reorderAndPredict(packed.data(), packed.size(), predicted.data());
    ASSERT_EQ(predicted, openexrPredict(packed)) << what << ", " << packed.size() << " bytes";
    expectOpenExrRle(predicted, what);
}

/// A uniform integer in [0, n).
std::uint32_t below(Pcg32& rng, std::uint32_t n) {
    return rng.nextU32() % n;
}

/// Runs of random lengths in [1, maxRun] of values drawn from `values`
/// symbols: short runs and few symbols give runs of two, three and more.
Bytes runs(std::size_t n, std::uint32_t maxRun, std::uint32_t values, Pcg32& rng) {
    Bytes b;
    while (b.size() < n) {
        const std::uint32_t length = 1 + below(rng, maxRun);
        const auto value = static_cast<std::uint8_t>(below(rng, values));
        b.insert(b.end(), std::min<std::size_t>(length, n - b.size()), value);
    }
    return b;
}

TEST(ExrCodec, EverySmallSizeGivesOpenExrsBytes) {
    test::forEachSimdTarget([] {
        Pcg32 rng(3);
        for (std::size_t n = 0; n <= 300; ++n) {
            expectOpenExrBytes(runs(n, 5, 3, rng), "short runs");
            expectOpenExrRle(runs(n, 5, 3, rng), "short runs");
            expectOpenExrBytes(Bytes(n, 7), "one value");
            expectOpenExrRle(Bytes(n, 7), "one value");
            Bytes noise(n);
            for (std::uint8_t& b : noise)
                b = static_cast<std::uint8_t>(below(rng, 256));
            expectOpenExrBytes(noise, "noise");
        }
    });
}

TEST(ExrCodec, EveryRunAndLiteralLengthGivesOpenExrsBytes) {
    test::forEachSimdTarget([] {
        Pcg32 rng(5);
        for (std::uint32_t k = 1; k <= 260; ++k) {
            // Runs of exactly k equal bytes between literals of k bytes: the
            // caps at 128 (runs) and 127 (literals) and the runs of two inside
            // literals.
            Bytes code;
            for (int block = 0; block < 6; ++block)
                for (std::uint32_t i = 0; i < k; ++i)
                    code.push_back(block % 2 == 0 ? std::uint8_t(block) : std::uint8_t(below(rng, 256)));
            expectOpenExrRle(code, "runs and literals of " + std::to_string(k));
            // Packed halves constant over k pixels: runs of 128s after the predictor.
            Bytes packed;
            for (const std::uint8_t v : code) {
                packed.push_back(v);
                packed.push_back(std::uint8_t(v ^ 0x55));
            }
            expectOpenExrBytes(packed, "halves constant over " + std::to_string(k));
        }
        for (const std::uint32_t maxRun : {2u, 3u, 4u, 130u, 300u})
            for (const std::uint32_t values : {2u, 4u, 256u}) {
                const std::string what =
                    "runs up to " + std::to_string(maxRun) + " of " + std::to_string(values) + " values";
                expectOpenExrRle(runs(100'003, maxRun, values, rng), what);
                expectOpenExrBytes(runs(100'003, maxRun, values, rng), what);
            }
    });
}

TEST(ExrCodec, ARenderLikeScanlineGivesOpenExrsBytes) {
    test::forEachSimdTarget([] {
        // Halves of a smooth ramp over flat background (what renders are), with
        // noise in the low bits: a scanline of 1920 pixels × 43 channels.
        Pcg32 rng(11);
        Bytes packed;
        for (int channel = 0; channel < 43; ++channel)
            for (int x = 0; x < 1920; ++x) {
                const bool hair = x > 600 && x < 1400;
                const auto half = static_cast<std::uint16_t>(
                    hair ? 0x3800 + (x % 97) * 3 + int(below(rng, 4)) : channel % 3 == 0 ? 0 : 0x2e66);
                packed.push_back(std::uint8_t(half & 0xff));
                packed.push_back(std::uint8_t(half >> 8));
            }
        expectOpenExrBytes(packed, "render-like scanline");
    });
}

} // namespace
} // namespace hairvox
