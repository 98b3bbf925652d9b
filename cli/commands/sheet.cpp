// hairvox sheet SHOT.json [--frames F] [--movie PATH|-] [--sheet PATH|-] [--gif PATH]
//               [--fps N] [--columns N] [--thumb-width N] [--max-thumbs N] [--gif-width N]
// A shot's frames as a movie, a contact sheet and an animated GIF (shots/sheet.h).
#include "../commands.h"

#include <hairvox/shots/sheet.h>
#include <hairvox/shots/shot.h>

#include <iostream>
#include <memory>

namespace hairvox::cli {

namespace {

struct SheetCommandOptions {
    std::string shot, frames, movie, sheet, gif;
    shots::SheetOptions options;
};

void runSheet(const SheetCommandOptions& opt) {
    const shots::Shot shot = shots::Shot::load(opt.shot);
    shots::SheetOptions options = opt.options;
    if (!opt.frames.empty())
        options.frames = shots::FrameSet::parse(opt.frames);
    options.movie = opt.movie;
    options.sheet = opt.sheet;
    options.gif = opt.gif;
    const shots::SheetResult result = shots::makeSheet(shot, options);
    for (const std::string& w : result.warnings)
        std::cerr << "hairvox: warning: " << w << "\n";
    for (const auto& path : result.written)
        std::cout << "wrote " << path.string() << "\n";
}

} // namespace

void addSheetCommand(CLI::App& app) {
    auto opt = std::make_shared<SheetCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "sheet", "A shot's frames (their PNGs) as an MP4 movie, a contact sheet and a GIF, "
                 "through ffmpeg");
    cmd->add_option("shot", opt->shot, "Shot file: a scene with \"frames\"")->required();
    cmd->add_option("--frames", opt->frames, "Frames (default: the shot's)");
    cmd->add_option("--movie", opt->movie,
                    "MP4 to write (default: <shot>.mp4 beside the PNGs; - for none)");
    cmd->add_option("--sheet", opt->sheet,
                    "Contact sheet PNG (default: <shot>.sheet.png beside the PNGs; - for none)");
    cmd->add_option("--gif", opt->gif, "Also an animated GIF, looping (e.g. for a README)");
    cmd->add_option("--fps", opt->options.fps, "Frames per second of the movie and GIF (24)");
    cmd->add_option("--columns", opt->options.columns, "Thumbnails per row of the sheet (8)");
    cmd->add_option("--thumb-width", opt->options.thumbWidth, "Thumbnail width in pixels (192)");
    cmd->add_option("--max-thumbs", opt->options.maxThumbs,
                    "Thumbnails on the sheet at most, evenly spaced (48)");
    cmd->add_option("--gif-width", opt->options.gifWidth, "GIF width in pixels (256)");
    cmd->add_option("--crf", opt->options.crf, "H.264 quality, 0 (lossless) to 51 (18)");
    cmd->callback([opt] { runSheet(*opt); });
}

} // namespace hairvox::cli
