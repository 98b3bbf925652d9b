// hairvox film: writing a film to image files, and reading EXR back.
//
// EXR: every layer of the film (film.h) as half channels — as float where a
// value exceeds half's range, or where the layer asks for full precision
// (depth) — ZIPS-compressed, with the string attributes and the camera's
// world-to-camera matrix given by the caller (OpenEXR's standard
// `worldToCamera` attribute). Written through writeFileAtomically().
//
// PNG: an 8-bit sRGB preview of the beauty: linear · 2^exposure, tone mapped
// (`clamp`, or `filmic`: Narkowicz's 2015 fit of the ACES curve, per
// channel), then the sRGB transfer function, rounded. The alpha channel is not
// written (the background is part of the beauty).
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/film/film.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace hairvox {

/// Preview tone map of the PNG.
enum class ToneMap { Clamp, Filmic };

inline constexpr EnumNames<ToneMap, 2> kToneMapNames{{{
    {ToneMap::Filmic, "filmic"},
    {ToneMap::Clamp, "clamp"},
}}};
inline const char* toString(ToneMap t) {
    return kToneMapNames.name(t);
}

/// Row-major 4×4 matrix, OpenEXR's convention (row vectors).
using Matrix44 = std::array<std::array<float, 4>, 4>;

/// The EXR's zlib level unless a scene says otherwise (measured: ExrHeader).
inline constexpr int kDefaultExrZipLevel = 1;

/// How the EXR's pixels are compressed (OpenEXR's lossless schemes; the names
/// are OpenEXR's). rle is the default: the 1080p head's 43 channels in
/// 0.11 s for 27.6 MB, against 0.34–0.36 s for 21.3 MB with zips (zlib
/// level 1) and 0.24–0.29 s for 182 MB with none (the write stage, 2
/// threads; docs/scene.md "Output" has the table).
enum class ExrCompression { Zips, Zip, Rle, None };

inline constexpr EnumNames<ExrCompression, 4> kExrCompressionNames{{{
    {ExrCompression::Zips, "zips"},
    {ExrCompression::Zip, "zip"},
    {ExrCompression::Rle, "rle"},
    {ExrCompression::None, "none"},
}}};
inline const char* toString(ExrCompression c) {
    return kExrCompressionNames.name(c);
}

struct ExrHeader {
    std::optional<Matrix44> worldToCamera;
    std::map<std::string, std::string> attributes; ///< e.g. "hairvox:globalTermMode" → "grid"
    /// zlib level of the zip and zips compressions, [1, 9]. Measured on the
    /// 1080p head with zips (43 channels, 2 cores, `hairvox render`'s write
    /// stage, three runs): level 1 0.34–0.36 s for 21.3 MB, level 4
    /// (OpenEXR's default) 0.49–0.50 s for 20.2 MB.
    int zipLevel = kDefaultExrZipLevel;
    ExrCompression compression = ExrCompression::Rle;
};

/// Writes every layer of the film as one multi-layer EXR, atomically.
/// InputError if header.zipLevel is outside [1, 9].
void writeExr(const std::filesystem::path& path, const Film& film, const ExrHeader& header = {});

/// An EXR file read back: every channel as float, row-major, and the string
/// attributes (tests, reference images, image comparisons).
struct ExrImage {
    int width = 0, height = 0;
    std::map<std::string, std::vector<float>> channels;
    std::map<std::string, std::string> attributes;
};

/// Throws InputError naming the file if it cannot be read.
ExrImage readExr(const std::filesystem::path& path);

/// What an EXR file's header says, its pixels not read: the size of the data
/// window, the channels, the string attributes, and whether every chunk of
/// the data window is in the file (OpenEXR's isComplete(): false for a file
/// cut short).
struct ExrInfo {
    std::int64_t width = 0, height = 0; ///< of the data window
    std::vector<std::string> channels;  ///< their names, in the file's order
    std::map<std::string, std::string> attributes;
    bool complete = false;
};

/// Where an EXR is read from: a file, or an EXR file's bytes in memory (a map
/// built into the program), with the name messages give it.
struct ExrSource {
    std::filesystem::path path;           ///< read when `bytes` is empty
    std::span<const unsigned char> bytes; ///< a whole EXR file, outliving the reads
    std::string name;                     ///< what messages call it

    static ExrSource file(const std::filesystem::path& path) { return {path, {}, path.string()}; }
    static ExrSource memory(std::string name, std::span<const unsigned char> bytes) {
        return {{}, bytes, std::move(name)};
    }
};

/// Throws InputError naming the file if it is not a readable EXR.
ExrInfo readExrInfo(const std::filesystem::path& path);
/// The same of a source in memory or on disk (in memory: complete when
/// OpenEXR's offset table says so).
ExrInfo readExrInfo(const ExrSource& source);

/// An EXR's colour: its R, G and B channels as floats.
struct ExrRgbImage {
    int width = 0, height = 0;
    std::vector<float> rgb; ///< row-major, 3 floats a pixel (R, G, B)
};

/// Reads the R, G and B channels of an EXR file (half, float or uint; any
/// compression OpenEXR reads, DWA included; scanline or tiled; the first part
/// of a multi-part file); an alpha or any other channel is ignored. Checks its
/// header first: InputError naming the file if it cannot be read, lacks one
/// of R, G, B (the message lists its channels) or holds more than maxPixels
/// pixels (nothing is allocated for it then).
ExrRgbImage readExrRgb(const ExrSource& source, std::uint64_t maxPixels);

/// The film an EXR image holds: channels R, G, B as the beauty layer "",
/// X.R, X.G, X.B as the RGB layer X, any other channel as a scalar layer of its
/// name; every layer full precision. (writeExr's inverse, up to half rounding.)
Film filmFromExr(const ExrImage& image);

/// The tone-mapped 8-bit sRGB preview of the film's beauty, row-major RGB.
std::vector<std::uint8_t> previewPixels(const Film& film, float exposure, ToneMap toneMap);

/// Writes 8-bit RGB pixels (row-major, 3 bytes a pixel) as a PNG, atomically:
/// writeEncodedPng(path, encodePng(width, height, rgb)).
void writePng(const std::filesystem::path& path, int width, int height,
              const std::vector<std::uint8_t>& rgb);
/// The PNG file's bytes for 8-bit RGB pixels (the expensive half: deflate).
std::vector<std::uint8_t> encodePng(int width, int height, const std::vector<std::uint8_t>& rgb);
/// Writes encoded PNG bytes atomically.
void writeEncodedPng(const std::filesystem::path& path, const std::vector<std::uint8_t>& png);

} // namespace hairvox
