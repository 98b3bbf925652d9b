// hairvox shots: frame numbers in file names. A pattern holds the frame
// number as printf writes it — "%04d" (padded to 4 digits), "%d" — or as
// Nuke and Houdini write it, a run of '#' padded to its length ("####" is
// "%04d", "#" is "%d"). "%%" is a literal '%'. Negative frames keep their
// sign before the padding ("%04d" of −5 is "-005", as printf writes it; a
// run of '#' writes the same).
#pragma once

#include <string>
#include <string_view>

namespace hairvox::shots {

/// Whether `pattern` holds a frame number ("%0Nd", "%d" or a run of '#').
bool hasFramePattern(std::string_view pattern);

/// `pattern` with each frame number written for `frame`. InputError naming
/// `what` (e.g. "/output/exr") for a '%' that starts no "%d", "%0Nd" (N in
/// [1, 9]) or "%%".
std::string expandFramePattern(std::string_view pattern, int frame, std::string_view what);

/// The pattern as ffmpeg's image2 demuxer reads it: every '#' run as
/// "%0Nd" (printf's form kept; a literal '%' doubled).
std::string printfFramePattern(std::string_view pattern, std::string_view what);

} // namespace hairvox::shots
