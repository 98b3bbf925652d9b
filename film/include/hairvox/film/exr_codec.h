// hairvox film (internal; public for its tests): the byte transforms of
// OpenEXR's lossless chunk compressions, written for speed and producing
// OpenEXR's bytes exactly.
//
// OpenEXR 3.1 (OpenEXRCore/internal_rle.c, internal_zip.c) compresses a
// chunk — its scanlines' channels packed one after another — in two steps:
//   1. the predictor: the even bytes, then the odd ones (low and high bytes of
//      the halves apart), then every byte but the first replaced by its
//      difference from the one before, plus 128 (mod 256);
//   2. RLE: runs of 3 to 128 equal bytes as (length − 1, byte), everything
//      else as literals of at most 127 bytes (−length, bytes...); ZIP: zlib.
// A chunk whose code is not shorter than its bytes is stored raw. OpenEXR
// does both steps a byte at a time, and its RLE was most of the 1080p
// write (docs/DESIGN.md §7, "Writing"); here the predictor runs across
// SIMD lanes and RLE finds its runs from bit masks of equal neighbours, a
// whole run or literal per step. tests/film/exr_codec_test.cpp checks the
// bytes against OpenEXR's own code.
#pragma once

#include <cstddef>
#include <cstdint>

namespace hairvox::detail {

/// OpenEXR's predictor (step 1) of `bytes` packed bytes into `out`.
void reorderAndPredict(const std::uint8_t* packed, std::size_t bytes, std::uint8_t* out);

/// Capacity of rleCompress's `out` for `bytes` input bytes.
constexpr std::size_t rleCapacity(std::size_t bytes) {
    return bytes + 2 * 128;
}

/// Words of rleCompress's `scratch` for `bytes` input bytes.
constexpr std::size_t rleScratchWords(std::size_t bytes) {
    return 2 * (bytes / 64 + 2);
}

/// OpenEXR's run-length code (step 2) of `bytes` predicted bytes into `out`.
/// Returns its size, or a size ≥ `bytes` (the code stopped early) when it
/// would not be shorter than the bytes: the chunk is then stored raw.
std::size_t rleCompress(const std::uint8_t* in, std::size_t bytes, std::uint64_t* scratch,
                        std::uint8_t* out);

} // namespace hairvox::detail
