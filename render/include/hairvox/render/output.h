// hairvox render: writing the film — OpenEXR with AOV layers, and a PNG preview.
//
// EXR (one scanline file, ZIPS compression, written atomically):
//   R G B A                       beauty (= the sum of the radiance layers) and alpha
//   direct_R.{R,G,B}  direct_TT.*  direct_TRT.*   single scattering per lobe
//   back_direct.*                 f_back^direct: local multiple scattering
//   scatter.*                     F_scatter: global multiple scattering
//   head.*  background.*          the head sphere, the background seen through
//   hair.A                        hair coverage
//   Z                             camera depth (32-bit float)
//   <light>.V  <light>.n  <light>.T_s.{R,G,B}  <light>.sigma_f.{R,G,B}   per light
// Channels are 16-bit half floats (32-bit float for Z, and for any channel
// holding a value beyond half's range, so that nothing overflows to Inf).
// Header attributes: worldToCamera, software, and the caller's strings.
//
// PNG: 8-bit sRGB of the beauty: linear · 2^exposure, tone mapped (`clamp`, or
// `filmic`: Narkowicz's 2015 fit of the ACES curve per channel), then the sRGB
// transfer function, rounded. The alpha channel is not written (the
// background is part of the beauty).
#pragma once

#include <hairvox/render/camera.h>
#include <hairvox/render/film.h>
#include <hairvox/render/scene.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace hairvox {

/// Writes the film as a multi-layer EXR. `attributes` become string header
/// attributes (e.g. "hairvox:mode" → "grid").
void writeExr(const std::filesystem::path& path, const Film& film, const Camera& camera,
              const std::map<std::string, std::string>& attributes = {});

/// An EXR file read back: every channel as float, row-major, and the string
/// attributes (tests, the reference-image comparison and image-level benchmarks).
struct ExrImage {
    int width = 0, height = 0;
    std::map<std::string, std::vector<float>> channels;
    std::map<std::string, std::string> attributes;
};

/// Throws InputError naming the file if it cannot be read.
ExrImage readExr(const std::filesystem::path& path);

/// The tone-mapped 8-bit sRGB preview, row-major RGB (what writePng writes).
std::vector<std::uint8_t> previewPixels(const Film& film, float exposure, ToneMap toneMap);
void writePng(const std::filesystem::path& path, const Film& film, float exposure,
              ToneMap toneMap);

/// Writes the outputs the scene asks for (scene.output.exr and .png, each if
/// non-empty) and returns their paths. EXR attributes record the scene's name,
/// mode, voxel size and shading rate plus `attributes`.
std::vector<std::filesystem::path>
writeOutputs(const Film& film, const Scene& scene,
             const std::map<std::string, std::string>& attributes = {});

} // namespace hairvox
