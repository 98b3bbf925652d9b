// hairvox film (internal): hairvox/film/exr_codec.h for every SIMD target (Highway's
// foreach_target.h re-includes this file once per target).
#ifndef HWY_DISABLED_TARGETS
#define HWY_DISABLED_TARGETS (HWY_SSSE3 | HWY_SVE | HWY_SVE2 | HWY_SVE_256 | HWY_SVE2_128 | HWY_RVV)
#endif

// Highway's order: the target list, then this file once per target.
// clang-format off
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "film/src/exr_codec.cpp"
#include <hwy/foreach_target.h> // IWYU pragma: keep
#include <hwy/highway.h>
// clang-format on

#include <hairvox/film/exr_codec.h>

#include <algorithm>
#include <bit>
#include <cstring>

HWY_BEFORE_NAMESPACE();
namespace hairvox::detail::HWY_NAMESPACE {

namespace hn = hwy::HWY_NAMESPACE;
using D8 = hn::ScalableTag<std::uint8_t>;

void ReorderAndPredict(const std::uint8_t* packed, std::size_t bytes, std::uint8_t* out);
void EqualNeighbours(const std::uint8_t* in, std::size_t bytes, std::uint64_t* bits);

void ReorderAndPredict(const std::uint8_t* packed, std::size_t bytes, std::uint8_t* out) {
    if (bytes == 0)
        return;
    const D8 d;
    const std::size_t lanes = hn::Lanes(d);
    // Reorder: byte 2i to i, byte 2i + 1 to half + i.
    const std::size_t half = (bytes + 1) / 2, pairs = bytes / 2;
    std::size_t i = 0;
    for (; i + lanes <= pairs; i += lanes) {
        hn::Vec<D8> even, odd;
        hn::LoadInterleaved2(d, packed + 2 * i, even, odd);
        hn::StoreU(even, d, out + i);
        hn::StoreU(odd, d, out + half + i);
    }
    for (; i < pairs; ++i) {
        out[i] = packed[2 * i];
        out[half + i] = packed[2 * i + 1];
    }
    if (bytes % 2 != 0)
        out[half - 1] = packed[bytes - 1];
    // Predict, in place from the end: byte i becomes t[i] − t[i − 1] + 128
    // while t[i − 1] is still unchanged.
    const hn::Vec<D8> bias = hn::Set(d, std::uint8_t(128));
    std::size_t end = bytes;
    for (; end >= lanes + 1; end -= lanes) {
        const hn::Vec<D8> t = hn::LoadU(d, out + end - lanes);
        const hn::Vec<D8> previous = hn::LoadU(d, out + end - lanes - 1);
        hn::StoreU(hn::Add(hn::Sub(t, previous), bias), d, out + end - lanes);
    }
    for (std::size_t j = end; j-- > 1;)
        out[j] = std::uint8_t(out[j] - out[j - 1] + 128u);
}

/// Bit i of `bits` (little-endian words, bytes / 64 + 1 of them): whether
/// in[i] == in[i + 1]; 0 for the last byte and beyond.
void EqualNeighbours(const std::uint8_t* in, std::size_t bytes, std::uint64_t* bits) {
    const std::size_t words = bytes / 64 + 1;
    std::fill_n(bits, words, 0);
    const D8 d;
    const std::size_t lanes = hn::Lanes(d);
    std::size_t i = 0;
    if (lanes % 8 == 0) { // whole bytes of mask bits per vector
        auto* bitBytes = reinterpret_cast<std::uint8_t*>(bits);
        for (; i + lanes + 1 <= bytes; i += lanes)
            hn::StoreMaskBits(d, hn::Eq(hn::LoadU(d, in + i), hn::LoadU(d, in + i + 1)),
                              bitBytes + i / 8);
    }
    for (; i + 1 < bytes; ++i)
        bits[i / 64] |= std::uint64_t(in[i] == in[i + 1]) << (i % 64);
}

} // namespace hairvox::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace hairvox::detail {

static_assert(std::endian::native == std::endian::little,
              "mask bits are read back as little-endian words");

HWY_EXPORT(ReorderAndPredict);
HWY_EXPORT(EqualNeighbours);

void reorderAndPredict(const std::uint8_t* packed, std::size_t bytes, std::uint8_t* out) {
    HWY_DYNAMIC_DISPATCH(ReorderAndPredict)(packed, bytes, out);
}

namespace {

/// OpenEXR's longest run (128 bytes, coded as 127) and longest literal.
constexpr std::size_t kMaxCount = 127;

/// How many bits are set from bit `from` on, counting at most `limit`.
std::size_t onesFrom(const std::uint64_t* bits, std::size_t from, std::size_t limit) {
    std::size_t count = 0;
    while (count < limit) {
        const std::size_t i = from + count;
        const std::size_t left = 64 - i % 64; // bits of this word from i on
        const auto ones = std::size_t(std::countr_one(bits[i / 64] >> (i % 64)));
        count += std::min(ones, left);
        if (ones < left)
            break;
    }
    return std::min(count, limit);
}

/// The first set bit in [from, to), or `to`.
std::size_t nextSet(const std::uint64_t* bits, std::size_t from, std::size_t to) {
    for (std::size_t i = from; i < to; i = (i | 63) + 1)
        if (const std::uint64_t word = bits[i / 64] >> (i % 64); word != 0)
            return std::min(to, i + std::size_t(std::countr_zero(word)));
    return to;
}

} // namespace

std::size_t rleCompress(const std::uint8_t* in, std::size_t bytes, std::uint64_t* scratch,
                        std::uint8_t* out) {
    // equal: in[i] == in[i + 1]; run3: a run of three equal bytes starts at i.
    const std::size_t words = bytes / 64 + 1;
    std::uint64_t* equal = scratch;
    std::uint64_t* run3 = scratch + words + 1;
    HWY_DYNAMIC_DISPATCH(EqualNeighbours)(in, bytes, equal);
    equal[words] = 0;
    for (std::size_t w = 0; w < words; ++w)
        run3[w] = equal[w] & ((equal[w] >> 1) | (equal[w + 1] << 63));

    // OpenEXR's greedy parse (internal_rle_compress), a run or literal a step.
    std::size_t s = 0, o = 0;
    while (s < bytes && o < bytes) {
        const std::size_t repeats = onesFrom(equal, s, kMaxCount); // bytes equal to in[s] after it
        if (repeats >= 2) {
            out[o++] = static_cast<std::uint8_t>(repeats);
            out[o++] = in[s];
            s += repeats + 1;
            continue;
        }
        // A literal up to the next run of three, at most 127 bytes.
        const std::size_t end = nextSet(run3, s + repeats + 1, std::min(bytes, s + kMaxCount));
        const std::size_t length = end - s;
        out[o++] = static_cast<std::uint8_t>(-static_cast<int>(length));
        std::memcpy(out + o, in + s, length);
        o += length;
        s = end;
    }
    return o;
}

} // namespace hairvox::detail
#endif
