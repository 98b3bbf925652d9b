#include "process.h"

#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/shots/sheet.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>

namespace hairvox::shots {

namespace fs = std::filesystem;

namespace {

/// A directory of symbolic links 000001.png, 000002.png, ... to the given
/// files, removed with the object (ffmpeg's image2 reads numbered names).
class LinkDir {
public:
    explicit LinkDir(const std::vector<fs::path>& files) {
        std::string pattern = (fs::temp_directory_path() / "hairvox-sheet-XXXXXX").string();
        if (!::mkdtemp(pattern.data()))
            throw InputError(strCat(pattern, ": cannot create a temporary directory"));
        dir_ = pattern;
        for (std::size_t i = 0; i < files.size(); ++i) {
            std::error_code ec;
            fs::create_symlink(fs::absolute(files[i]), dir_ / numbered(i + 1), ec);
            if (ec)
                throw InputError(
                    strCat(dir_.string(), ": cannot link ", files[i].string(), ": ", ec.message()));
        }
    }
    ~LinkDir() {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    LinkDir(const LinkDir&) = delete;
    LinkDir& operator=(const LinkDir&) = delete;

    std::string input() const { return (dir_ / "%06d.png").string(); }

private:
    static std::string numbered(std::size_t i) {
        char name[32];
        std::snprintf(name, sizeof name, "%06zu.png", i);
        return name;
    }
    fs::path dir_;
};

/// Runs ffmpeg writing `path` through writeFileAtomically (`format` names
/// the muxer: the temporary's name has no extension to guess it from).
void runFfmpeg(std::vector<std::string> args, const fs::path& path, const std::string& format) {
    writeFileAtomically(path, [&](const fs::path& tmp) {
        std::vector<std::string> argv = {"ffmpeg",    "-nostdin", "-hide_banner",
                                         "-loglevel", "error",    "-y"};
        argv.insert(argv.end(), args.begin(), args.end());
        argv.insert(argv.end(), {"-f", format, tmp.string()});
        const detail::ProcessResult r = detail::runProcess(argv);
        if (r.exitCode != 0) {
            std::string command;
            for (const std::string& a : argv)
                command += (command.empty() ? "" : " ") + a;
            throw InputError(strCat(path.string(), ": ffmpeg failed (exit ", r.exitCode,
                                    "): ", r.errors, "\n  command: ", command));
        }
    });
}

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

/// A font file for the sheet's labels (fontconfig's name when none is found).
std::string fontOption() {
    for (const char* f : {"/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
                          "/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf"})
        if (fs::exists(f))
            return strCat("fontfile=", f);
    return "font=Sans";
}

} // namespace

void SheetOptions::validate() const {
    const auto check = [](bool ok, const std::string& what) {
        if (!ok)
            throw InputError(what);
    };
    check(fps >= 1 && fps <= 240, strCat("--fps ", fps, ": expected [1, 240]"));
    check(columns >= 1 && columns <= 64, strCat("--columns ", columns, ": expected [1, 64]"));
    check(thumbWidth >= 16 && thumbWidth <= 4096,
          strCat("--thumb-width ", thumbWidth, ": expected [16, 4096]"));
    check(maxThumbs >= 1 && maxThumbs <= 1024,
          strCat("--max-thumbs ", maxThumbs, ": expected [1, 1024]"));
    check(gifWidth >= 16 && gifWidth <= 4096,
          strCat("--gif-width ", gifWidth, ": expected [16, 4096]"));
    check(crf >= 0 && crf <= 51, strCat("--crf ", crf, ": expected [0, 51]"));
}

SheetResult makeSheet(const Shot& shot, const SheetOptions& o) {
    o.validate();
    const FrameSet frames = o.frames ? shot.select(*o.frames) : shot.frames();
    std::vector<fs::path> pngs;
    std::vector<int> missing;
    for (int f : frames.frames()) {
        const Scene scene = shot.frame(f);
        if (scene.output.png.empty())
            throw InputError(strCat(shot.name(),
                                    ": output.png is null; the movie and sheet are made from "
                                    "the frames' PNGs"));
        std::error_code ec;
        if (!fs::is_regular_file(scene.output.png, ec))
            missing.push_back(f);
        pngs.push_back(scene.output.png);
    }
    if (!missing.empty())
        throw InputError(strCat(shot.name(), ": ", missing.size(), " of ", frames.size(),
                                " frames have no PNG (", FrameSet::of(missing).toString(),
                                "): render them first (hairvox status lists them), or choose "
                                "frames with --frames"));
    if (!detail::findProgram("ffmpeg"))
        throw InputError("ffmpeg is not on the PATH (Debian: apt-get install ffmpeg)");

    const std::string stem = fs::path(shot.name()).stem().string();
    const fs::path beside = pngs.front().parent_path();
    const fs::path movie = o.movie.empty() ? beside / (stem + ".mp4") : o.movie;
    const fs::path sheet = o.sheet.empty() ? beside / (stem + ".sheet.png") : o.sheet;
    SheetResult result;
    const LinkDir all(pngs);
    const std::string fps = number(o.fps);

    if (movie != "-") {
        // yuv420p (what players read) needs even sides.
        runFfmpeg({"-framerate", fps, "-i", all.input(), "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                   "-c:v", "libx264", "-preset", "medium", "-crf", std::to_string(o.crf),
                   "-pix_fmt", "yuv420p", "-movflags", "+faststart"},
                  movie, "mp4");
        result.written.push_back(movie);
    }

    if (sheet != "-") {
        // Evenly spaced frames: every k-th, so that a frame set with one step
        // labels each thumbnail by arithmetic (drawtext's n: the thumbnail's index).
        const std::size_t n = frames.size();
        const std::size_t k = (n + std::size_t(o.maxThumbs) - 1) / std::size_t(o.maxThumbs);
        std::vector<fs::path> thumbs;
        for (std::size_t i = 0; i < n; i += k)
            thumbs.push_back(pngs[i]);
        const std::size_t columns = std::min<std::size_t>(std::size_t(o.columns), thumbs.size());
        const std::size_t rows = (thumbs.size() + columns - 1) / columns;
        const auto& fr = frames.frames();
        bool evenly = true;
        for (std::size_t i = 2; i < fr.size(); ++i)
            evenly = evenly && fr[i] - fr[i - 1] == fr[1] - fr[0];
        const long step = fr.size() > 1 ? long(fr[1] - fr[0]) * long(k) : 1;
        const std::string scale = strCat("scale=", o.thumbWidth, ":-2");
        const std::string tile =
            strCat("tile=", columns, "x", rows, ":padding=4:margin=4:color=0x202020");
        const std::string label =
            strCat("drawtext=", fontOption(), ":text='%{eif\\:n*", step, "+", fr.front(),
                   "\\:d}':x=6:y=h-th-6:fontsize=", std::max(10, o.thumbWidth / 12),
                   ":fontcolor=white:box=1:boxcolor=black@0.5:boxborderw=3");
        const LinkDir chosen(thumbs);
        const auto make = [&](bool labels) {
            runFfmpeg({"-framerate", "1", "-i", chosen.input(), "-vf",
                       strCat(scale, labels ? "," + label : std::string(), ",", tile), "-frames:v",
                       "1", "-c:v", "png"},
                      sheet, "image2");
        };
        if (evenly) {
            try {
                make(true);
            } catch (const InputError& e) {
                result.warnings.push_back(strCat(
                    "contact sheet without frame numbers (drawtext failed: ", e.what(), ")"));
                make(false);
            }
        } else {
            make(false);
        }
        result.written.push_back(sheet);
    }

    if (!o.gif.empty()) {
        // One palette for the whole loop (palettegen over every frame).
        runFfmpeg({"-framerate", fps, "-i", all.input(), "-vf",
                   strCat("scale=", o.gifWidth,
                          ":-2:flags=lanczos,split[a][b];[a]palettegen=stats_mode=full[p];"
                          "[b][p]paletteuse=dither=sierra2_4a"),
                   "-loop", "0"},
                  o.gif, "gif");
        result.written.push_back(o.gif);
    }
    return result;
}

} // namespace hairvox::shots
