// hairvox shots: seeing a shot — its frames' PNGs as a movie (H.264 MP4), a
// contact sheet (one PNG of thumbnails labelled with their frame numbers)
// and, on request, an animated GIF (a README's turntable), all made by
// ffmpeg (Debian's, found on the PATH). Every file is written atomically.
#pragma once

#include <hairvox/shots/frame_set.h>
#include <hairvox/shots/shot.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hairvox::shots {

struct SheetOptions {
    std::optional<FrameSet> frames; ///< the shot's (Shot::select); nullopt: all
    /// Empty: beside the first frame's PNG, named after the shot:
    /// <stem>.mp4 and <stem>.sheet.png. "-": not made.
    std::filesystem::path movie, sheet;
    std::filesystem::path gif; ///< empty: none
    double fps = 24;           ///< movie and GIF, [1, 240]
    int columns = 8;           ///< of the contact sheet, [1, 64]
    int thumbWidth = 192;      ///< pixels, [16, 4096]
    int maxThumbs = 48;        ///< frames on the sheet, evenly spaced, [1, 1024]
    int gifWidth = 256;        ///< pixels, [16, 4096]
    int crf = 18;              ///< libx264 quality (0 lossless .. 51), [0, 51]

    /// InputError naming the option and its range.
    void validate() const;
};

/// What was made.
struct SheetResult {
    std::vector<std::filesystem::path> written;
    std::vector<std::string> warnings;
};

/// Makes the movie, sheet and GIF from the frames' PNGs. InputError when the
/// shot writes no PNG, when a frame's PNG is missing (naming the frames), or
/// when ffmpeg is missing or fails (with its message).
SheetResult makeSheet(const Shot& shot, const SheetOptions& options);

} // namespace hairvox::shots
