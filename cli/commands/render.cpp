// hairvox render [SCENE.json ...] [--exr OUT.exr] [--png OUT.png] [-o OUT.exr|OUT.png]
//                [--integrator dual_scattering|path|volumetric] [--mode exact|grid|approx]
//                [--shading-rate fragment|vertex] [--exr-compression rle|zips|zip|none]
//                [--spp N] [--paths N]
//                [--time-limit S] [--seed S] [--continue] [--width W] [--height H]
//                [--voxel-size V] [--max-memory GIB] [--threads N] [--quiet]
//                [--frames F] [--force] [--cache DIR]
// Renders a scene (or the embedded default scene) to EXR + PNG and prints the
// time per stage. Outputs given on the command line replace the scene's
// (exactly those are written); two outputs never go to the same file, nor over
// the scene or groom file. A path trace stopped by Ctrl-C writes the whole
// passes it finished and exits with 130.
//
// Several scenes (the frames of a sequence) render one after another in one
// process: every scene is read and checked, and every output checked against
// every other output and input, before the first render; a scene that fails
// while rendering is reported and the batch goes on; the exit code says the
// worst that happened (1 an internal error, 2 bad input), and Ctrl-C stops
// the batch. Each scene writes the outputs its JSON names. A frame takes the
// fiber grid and the lights' preparation from the frame before where what
// they are made of is unchanged (FrameReuse, pipeline/pipeline.h).
//
// hairvox render SHOT.json [--frames F] [--force] [--cache DIR]: a shot's
// frames (a scene with "frames"; shots/shot_render.h, docs/farm.md), a line
// per frame, skipping the frames done unless --force. --cache DIR shares the
// fiber grid and the lights' preparation with other processes (a farm's tasks).
#include "../commands.h"

#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/core/progress.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/shots/frame_set.h>
#include <hairvox/shots/shot.h>
#include <hairvox/shots/shot_render.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sys/stat.h>
#include <vector>

namespace hairvox::cli {

namespace {

struct RenderCommandOptions {
    std::vector<std::string> scenes;
    std::string output, exr, png;
    std::string mode, integrator, shadingRate, exrCompression, layers;
    std::optional<std::uint32_t> spp;
    std::optional<std::uint64_t> paths;
    std::optional<double> timeLimit;
    std::optional<std::uint64_t> seed;
    bool continueRun = false;
    std::optional<std::uint32_t> width, height;
    std::optional<float> voxelSize, shadingTolerance, tailTransmittance;
    std::optional<double> maxMemoryGiB;
    int threads = 0;
    bool quiet = false;
    std::string frames;   ///< a shot's frames (shots/frame_set.h); empty: all
    bool force = false;   ///< a shot's frames that are done rendered again
    std::string cacheDir; ///< the shared disk cache (PipelineOptions::diskCache)
};

std::string lowerExtension(const std::filesystem::path& p) {
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

/// The outputs: those of the command line (--exr, --png, -o by its extension)
/// replace the scene's. Checks that something is written, that no two outputs
/// share a file and that no output overwrites the scene or groom file.
void resolveOutputs(const RenderCommandOptions& opt, const std::string& scenePath, Scene& scene) {
    struct Output {
        std::filesystem::path path;
        std::string from; ///< the flag or scene field that set it, for messages
    };
    Output exr{scene.output.exr, "the scene's output.exr"};
    Output png{scene.output.png, "the scene's output.png"};
    if (!opt.output.empty() || !opt.exr.empty() || !opt.png.empty()) {
        exr = {opt.exr, "--exr"};
        png = {opt.png, "--png"};
        if (!opt.output.empty()) {
            const std::string ext = lowerExtension(opt.output);
            Output& target = ext == ".exr" ? exr : png;
            if (ext != ".exr" && ext != ".png")
                throw InputError(strCat("-o ", opt.output,
                                        ": the extension must be .exr or .png (it chooses the "
                                        "output); or give --exr PATH and/or --png PATH"));
            if (!target.path.empty())
                throw InputError(strCat("-o ", opt.output, " and ", target.from, " ",
                                        target.path.string(), " both set the ",
                                        ext == ".exr" ? "EXR" : "PNG", " output; give one"));
            target = {opt.output, "-o"};
        }
    }
    if (exr.path.empty() && png.path.empty())
        throw InputError(strCat(scene.name,
                                ": output.exr and output.png are both null; nothing would be "
                                "written (give --exr PATH or --png PATH)"));
    if (!exr.path.empty() && !png.path.empty() && sameFile(exr.path, png.path))
        throw InputError(strCat(exr.from, " ", exr.path.string(), " and ", png.from, " ",
                                png.path.string(),
                                " are the same file; the EXR and the PNG need different paths"));
    for (const Output* o : {&exr, &png}) {
        if (o->path.empty())
            continue;
        if (!scenePath.empty() && sameFile(o->path, scenePath))
            throw InputError(strCat(o->from, " ", o->path.string(),
                                    " is the scene file; it would be overwritten"));
        if (!scene.groom.isProcedural() && sameFile(o->path, scene.groom.file))
            throw InputError(strCat(o->from, " ", o->path.string(), " is the groom file ",
                                    scene.groom.file.string(), "; it would be overwritten"));
    }
    scene.output.exr = exr.path;
    scene.output.png = png.path;
}

/// --width or --height alone keeps the aspect ratio of the scene's camera
/// (the other side rounded, at least 1 pixel).
void resolveResolution(const RenderCommandOptions& opt, CameraParams& camera) {
    const double aspect = double(camera.width) / double(camera.height);
    if (opt.width && opt.height) {
        camera.width = *opt.width;
        camera.height = *opt.height;
    } else if (opt.width) {
        camera.width = *opt.width;
        camera.height =
            static_cast<std::uint32_t>(std::max(1.0, std::round(double(*opt.width) / aspect)));
    } else if (opt.height) {
        camera.height = *opt.height;
        camera.width =
            static_cast<std::uint32_t>(std::max(1.0, std::round(double(*opt.height) * aspect)));
    }
    if (camera.width > kMaxResolution || camera.height > kMaxResolution)
        throw InputError(strCat(camera.width, " x ", camera.height,
                                " (keeping the scene camera's aspect ratio): expected at most ",
                                kMaxResolution, " pixels a side; give both --width and --height"));
}

/// The command line's choices applied to a scene read from `path`, checked.
void applyOverrides(const RenderCommandOptions& opt, const std::string& path, Scene& scene) {
    if (!opt.mode.empty())
        scene.globalTermMode = *kGlobalTermModeNames.parse(opt.mode); // CLI11 checked the choice
    if (!opt.integrator.empty())
        scene.integrator = *kIntegratorNames.parse(opt.integrator);
    if (!opt.shadingRate.empty())
        scene.shadingRate = *kShadingRateNames.parse(opt.shadingRate);
    if (opt.shadingTolerance) {
        if (scene.shadingRate != ShadingRate::Adaptive)
            throw InputError("--shading-tolerance applies to the adaptive shading rate "
                             "(--shading-rate adaptive)");
        scene.shadingTolerance = *opt.shadingTolerance;
    }
    if (opt.tailTransmittance) {
        if (scene.shadingRate == ShadingRate::Vertex)
            throw InputError("--tail-transmittance applies to the fragment and adaptive shading "
                             "rates (the vertex rate interpolates all the hair)");
        scene.tailTransmittance = *opt.tailTransmittance;
    }
    if (!opt.exrCompression.empty())
        scene.output.exrCompression = *kExrCompressionNames.parse(opt.exrCompression);
    if (opt.layers == "all") {
        scene.output.layers.reset();
    } else if (opt.layers == "none") {
        scene.output.layers.emplace();
    } else if (!opt.layers.empty()) {
        scene.output.layers.emplace();
        for (std::size_t begin = 0; begin <= opt.layers.size();) {
            const std::size_t end = std::min(opt.layers.find(',', begin), opt.layers.size());
            scene.output.layers->push_back(opt.layers.substr(begin, end - begin));
            begin = end + 1;
        }
    }
    if ((opt.spp || opt.timeLimit || opt.continueRun) && scene.integrator != Integrator::Path)
        throw InputError("--spp, --time-limit and --continue apply to the path integrator "
                         "(--integrator path)");
    if (opt.paths && scene.integrator != Integrator::Volumetric)
        throw InputError("--paths applies to the volumetric integrator (--integrator volumetric)");
    if (opt.seed && scene.integrator == Integrator::DualScattering)
        throw InputError("--seed applies to the path and volumetric integrators (--integrator "
                         "path|volumetric)");
    if (opt.spp)
        scene.pathTrace.spp = *opt.spp;
    if (opt.timeLimit)
        scene.pathTrace.timeLimit = *opt.timeLimit;
    if (opt.seed)
        (scene.integrator == Integrator::Path ? scene.pathTrace.seed : scene.volumetric.seed) =
            *opt.seed;
    if (opt.paths)
        scene.volumetric.paths = *opt.paths;
    resolveResolution(opt, scene.camera);
    if (opt.voxelSize)
        scene.voxelSize = *opt.voxelSize;
    resolveOutputs(opt, path, scene);
    scene.validate();
}

/// The scene at `path` (empty: the embedded default scene) with the command
/// line's choices applied, checked.
Scene prepareScene(const RenderCommandOptions& opt, const std::string& path) {
    Scene scene = path.empty() ? defaultScene() : loadScene(path);
    applyOverrides(opt, path, scene);
    return scene;
}

PipelineOptions pipelineOptions(const RenderCommandOptions& opt) {
    PipelineOptions options;
    if (opt.maxMemoryGiB)
        options.maxMemoryBytes =
            static_cast<std::uint64_t>(std::max(1.0, *opt.maxMemoryGiB * double(1ull << 30)));
    options.threads = opt.threads;
    options.progress = !opt.quiet && stderrIsTerminal();
    options.continuePathTrace = opt.continueRun;
    if (!opt.cacheDir.empty())
        options.diskCache = std::make_shared<const DiskCache>(opt.cacheDir);
    return options;
}

/// Renders one prepared scene and says what it wrote.
void renderOne(const RenderCommandOptions& opt, const Scene& scene, FrameReuse* reuse = nullptr) {
    const SceneRender render = renderScene(scene, pipelineOptions(opt), true, reuse);
    for (const std::string& warning : render.warnings)
        std::cerr << "hairvox: warning: " << warning << "\n";
    if (!opt.quiet)
        printTimingReport(std::cout, scene, render);
    for (const auto& path : render.written)
        std::cout << "wrote " << path.string() << "\n";
    if (render.pathTrace && render.pathTrace->interrupted)
        throw Interrupted(
            strCat("interrupted after ", render.pathTrace->spp, " samples per pixel; ",
                   render.written.empty() ? "no output was written"
                                          : "the image holds them (add samples with --continue)"));
}

/// One line per frame of a shot (and the render's report unless --quiet).
void printFrameReport(std::ostream& os, const RenderCommandOptions& opt,
                      const shots::FrameReport& r) {
    char line[256];
    const char* what = r.outcome == shots::FrameReport::Outcome::Rendered   ? "rendered"
                       : r.outcome == shots::FrameReport::Outcome::UpToDate ? "up to date"
                                                                            : "FAILED";
    std::snprintf(line, sizeof(line), "frame %d (%zu of %zu): %s in %.2f s", r.frame, r.index,
                  r.count, what, r.seconds);
    os << line;
    if (r.render) {
        std::size_t reusedLights = 0;
        for (const LightReport& l : r.render->lights)
            reusedLights += l.reused ? 1 : 0;
        if (r.render->gridReused || reusedLights > 0)
            os << "; the frame before's " << (r.render->gridReused ? "grid" : "")
               << (r.render->gridReused && reusedLights > 0 ? " and " : "")
               << (reusedLights > 0 ? strCat(reusedLights, " light(s)") : std::string());
    }
    if (r.cache.hits + r.cache.stored > 0)
        os << "; cache: " << r.cache.hits << " read, " << r.cache.stored << " written";
    if (r.cache.corrupt > 0)
        os << ", " << r.cache.corrupt << " corrupt entr" << (r.cache.corrupt == 1 ? "y" : "ies")
           << " rebuilt";
    if (r.outcome == shots::FrameReport::Outcome::UpToDate)
        os << " ("
           << (r.scene->output.exr.empty() ? r.scene->output.png : r.scene->output.exr).string()
           << " records this frame's digest)";
    os << "\n";
    if (r.outcome == shots::FrameReport::Outcome::Failed)
        std::cerr << "hairvox: " << (r.internalError ? "internal error: " : "error: ") << "frame "
                  << r.frame << ": " << r.error << "\n";
    if (r.render) {
        for (const std::string& warning : r.render->warnings)
            std::cerr << "hairvox: warning: frame " << r.frame << ": " << warning << "\n";
        if (!opt.quiet)
            printTimingReport(os, *r.scene, *r.render);
        for (const auto& path : r.render->written)
            os << "wrote " << path.string() << "\n";
    }
    os << std::flush;
}

/// What identifies a file across spellings: device and inode where it
/// exists (hard and symbolic links), else its absolute normal path.
std::string fileKey(const std::filesystem::path& p) {
    struct stat st {};
    if (::stat(p.c_str(), &st) == 0)
        return strCat("inode ", st.st_dev, ":", st.st_ino);
    std::error_code ec;
    return std::filesystem::weakly_canonical(std::filesystem::absolute(p, ec), ec).string();
}

/// A batch's files: no output is written twice or over another scene's
/// scene or groom file (each scene's own were checked by resolveOutputs()).
void checkBatchFiles(const std::vector<std::string>& paths, const std::vector<Scene>& scenes) {
    std::map<std::string, std::string> inputs, outputs; // file key → what it is
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        inputs.emplace(fileKey(paths[i]), strCat("the scene file ", paths[i]));
        if (!scenes[i].groom.isProcedural())
            inputs.emplace(fileKey(scenes[i].groom.file),
                           strCat(paths[i], "'s groom file ", scenes[i].groom.file.string()));
    }
    for (std::size_t i = 0; i < scenes.size(); ++i)
        for (const auto& [file, field] : {std::pair{&scenes[i].output.exr, "output.exr"},
                                          std::pair{&scenes[i].output.png, "output.png"}}) {
            if (file->empty())
                continue;
            const std::string what = strCat(paths[i], "'s ", field, " ", file->string());
            const std::string key = fileKey(*file);
            if (const auto in = inputs.find(key); in != inputs.end())
                throw InputError(strCat(what, " is ", in->second, "; it would be overwritten"));
            if (const auto [out, added] = outputs.emplace(key, what); !added)
                throw InputError(strCat(what, " and ", out->second,
                                        " are the same file; one would overwrite the other"));
        }
}

/// A shot's frames (shot_render.h), each line saying what became of it.
void runShot(const RenderCommandOptions& opt) {
    if (opt.scenes.size() != 1)
        throw InputError(strCat("--frames renders the frames of one shot; ", opt.scenes.size(),
                                " scene files given"));
    if (!opt.output.empty() || !opt.exr.empty() || !opt.png.empty())
        throw InputError("a shot writes the outputs its frames name (output.exr and output.png "
                         "with a frame number); --exr, --png and -o name one file");
    if (opt.continueRun)
        throw InputError("--continue applies to one path-traced scene, not to a shot's frames");
    const std::string& path = opt.scenes[0];
    const shots::Shot shot = shots::Shot::load(path);
    const shots::FrameSet frames =
        opt.frames.empty() ? shot.frames() : shot.select(shots::FrameSet::parse(opt.frames));
    shots::ShotRenderOptions options;
    options.pipeline = pipelineOptions(opt);
    options.force = opt.force;
    options.adjust = [&](Scene& scene) {
        applyOverrides(opt, path, scene);
    };
    std::cout << "hairvox: " << path << ": " << frames.size() << " frame(s) " << frames.toString()
              << " of " << shot.start() << "-" << shot.end() << "\n"
              << std::flush;
    const shots::ShotRenderSummary summary =
        shots::renderShot(shot, frames, options, [&](const shots::FrameReport& r) {
            printFrameReport(std::cout, opt, r);
        });
    char line[200];
    std::snprintf(line, sizeof(line),
                  "hairvox: %zu of %zu frames rendered, %zu up to date, %zu failed in %.2f s "
                  "(%.2f s a rendered frame)\n",
                  summary.rendered, frames.size(), summary.upToDate, summary.failed.size(),
                  summary.seconds,
                  summary.rendered > 0 ? summary.seconds / double(summary.rendered) : 0.0);
    std::cout << line << std::flush;
    if (summary.failed.empty())
        return;
    const std::string message = strCat(summary.failed.size(), " of ", frames.size(),
                                       " frames failed: ", summary.failed.toString());
    if (summary.internalError)
        throw std::runtime_error(message);
    throw InputError(message);
}

void runRender(const RenderCommandOptions& opt) {
    if (!opt.frames.empty() || (opt.scenes.size() == 1 && shots::isShotFile(opt.scenes[0]))) {
        runShot(opt);
        return;
    }
    if (opt.force)
        throw InputError("--force applies to a shot's frames (a scene with \"frames\")");
    if (opt.scenes.size() <= 1) {
        renderOne(opt, prepareScene(opt, opt.scenes.empty() ? std::string() : opt.scenes[0]));
        return;
    }
    if (!opt.output.empty() || !opt.exr.empty() || !opt.png.empty())
        throw InputError(strCat(opt.scenes.size(),
                                " scenes: --exr, --png and -o name one file; with several "
                                "scenes each writes the outputs its JSON names"));
    // Every scene is read and checked before the first render: a batch left
    // to run overnight does not stop at a typo in its last scene.
    std::vector<Scene> scenes;
    std::vector<std::string> bad;
    for (const std::string& path : opt.scenes) {
        try {
            scenes.push_back(prepareScene(opt, path));
        } catch (const InputError& e) {
            bad.push_back(strCat(path, ": ", e.what()));
        }
    }
    if (!bad.empty()) {
        std::string message = strCat(bad.size(), " of ", opt.scenes.size(),
                                     " scenes cannot be rendered; nothing was rendered:");
        for (const std::string& b : bad)
            message += "\n  " + b;
        throw InputError(message);
    }
    checkBatchFiles(opt.scenes, scenes);

    const auto start = std::chrono::steady_clock::now();
    std::vector<std::string> failed;
    bool internal = false;
    FrameReuse reuse; // the grid and lights' caches that frames share
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        try {
            renderOne(opt, scenes[i], &reuse);
        } catch (const Interrupted& e) {
            throw Interrupted(strCat(e.what(), "; scene ", i + 1, " of ", scenes.size(), " (",
                                     opt.scenes[i], "), the rest not rendered"));
        } catch (const std::exception& e) {
            const bool bug = dynamic_cast<const InputError*>(&e) == nullptr;
            internal = internal || bug;
            std::cerr << "hairvox: " << (bug ? "internal error: " : "error: ") << opt.scenes[i]
                      << ": " << e.what() << "\n";
            failed.push_back(opt.scenes[i]);
        }
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::size_t rendered = scenes.size() - failed.size();
    if (!opt.quiet) {
        char line[160];
        std::snprintf(line, sizeof(line),
                      "hairvox: %zu of %zu scenes rendered in %.2f s (%.2f s a scene)\n", rendered,
                      scenes.size(), seconds, seconds / double(scenes.size()));
        std::cout << line;
    }
    if (failed.empty())
        return;
    std::string message = strCat(failed.size(), " of ", scenes.size(), " scenes failed:");
    for (const std::string& f : failed)
        message += " " + f;
    if (internal)
        throw std::runtime_error(message);
    throw InputError(message);
}

} // namespace

void addRenderCommand(CLI::App& app) {
    auto opt = std::make_shared<RenderCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render",
        "Render a scene (default: the embedded default scene) to EXR with AOVs and a PNG");
    cmd->add_option("scene", opt->scenes,
                    "Scene JSON file(s) (docs/scene.md); omit for the default scene. Several "
                    "render one after another in one process, each to the outputs it names, "
                    "sharing the fiber grid and the lights' preparation where unchanged");
    cmd->add_option("--exr", opt->exr,
                    "Output EXR (beauty and AOVs). Outputs given on the command line replace "
                    "the scene's: only they are written");
    cmd->add_option("--png", opt->png, "Output PNG preview (tone-mapped)");
    cmd->add_option("-o,--output", opt->output,
                    "Output file whose extension (.exr or .png) says which output it is");
    cmd->add_option("--integrator", opt->integrator,
                    "dual_scattering (default), volumetric (multiple scattering solved on the "
                    "fiber grid) or path (the unbiased reference)")
        ->check(CLI::IsMember(kIntegratorNames.names()));
    cmd->add_option("--mode", opt->mode, "Global-term mode (dual scattering)")
        ->check(CLI::IsMember(kGlobalTermModeNames.names()));
    cmd->add_option("--shading-rate", opt->shadingRate,
                    "Where the dual-scattering shader is evaluated: fragment, vertex or "
                    "adaptive (docs/scene.md)")
        ->check(CLI::IsMember(kShadingRateNames.names()));
    cmd->add_option("--shading-tolerance", opt->shadingTolerance,
                    "Adaptive rate: a segment is interpolated when its midpoint is within this "
                    "fraction of its mean radiance from the ends' interpolation [0, 1]")
        ->check(CLI::Range(0.0f, 1.0f));
    cmd->add_option("--tail-transmittance", opt->tailTransmittance,
                    "Fragment and adaptive rates: hair seen through less than this transmittance "
                    "interpolates strand-vertex results instead of being shaded; 0: none "
                    "(default 1/16, docs/scene.md) [0, 1]")
        ->check(CLI::Range(0.0f, 1.0f));
    cmd->add_option("--exr-compression", opt->exrCompression,
                    "EXR compression: rle (default), zips, zip or none; overrides the scene's "
                    "(sizes and times in docs/scene.md)")
        ->check(CLI::IsMember(kExrCompressionNames.names()));
    cmd->add_option("--layers", opt->layers,
                    "EXR layers besides the beauty and A: all (default), none, or names "
                    "separated by commas (e.g. Z,hair.A,key.V); overrides the scene's "
                    "output.layers (docs/scene.md)")
        ->check([](const std::string& list) {
            return list.empty() ? std::string("expected all, none or layer names") : std::string();
        });
    cmd->add_option("--spp", opt->spp, "Path tracing: samples per pixel [1, 1000000]");
    cmd->add_option("--time-limit", opt->timeLimit,
                    "Path tracing: stop after this many seconds (whole passes) [0, 1e7]");
    cmd->add_option("--seed", opt->seed, "Path tracing and volumetric: random seed");
    cmd->add_option("--paths", opt->paths,
                    strCat("Volumetric: light paths traced through the fiber grid (default: "
                           "the scene's, or ", VolumetricSettings{}.pathsPerCell,
                           " per cache cell) [1, 2^40]"))
        ->check(CLI::Range(std::uint64_t(1), std::uint64_t(1) << 40));
    cmd->add_flag("--continue", opt->continueRun,
                  "Path tracing: add samples to the output EXR of an earlier run of this scene");
    cmd->add_option("--width", opt->width,
                    "Image width in pixels; alone, the height follows the scene camera's aspect")
        ->check(CLI::Range(1u, 8192u));
    cmd->add_option("--height", opt->height,
                    "Image height in pixels; alone, the width follows the scene camera's aspect")
        ->check(CLI::Range(1u, 8192u));
    cmd->add_option("--max-memory", opt->maxMemoryGiB,
                    "Refuse a render estimated to need more than this many GiB (default: 3/4 of "
                    "the physical memory)")
        ->check(CLI::Range(0.01, 1e6));
    cmd->add_option("--voxel-size", opt->voxelSize, "Fiber grid voxel size (scene units)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--threads", opt->threads, "Worker threads (0: all cores)")
        ->check(CLI::Range(0, 1024));
    cmd->add_option("--frames", opt->frames,
                    "A shot's frames to render: 1-240, 1-240x2 (every other), 7, or lists "
                    "1-10,20; default: all. Frames already done are skipped (docs/farm.md)");
    cmd->add_flag("--force", opt->force, "Shot: render the frames that are done too");
    cmd->add_option("--cache", opt->cacheDir,
                    "Directory of fiber grids, lights' preparations and tables shared by "
                    "renders on many machines (a farm's tasks; docs/farm.md)");
    cmd->add_flag("--quiet", opt->quiet, "No progress bar and no timing report");
    cmd->callback([opt] { runRender(*opt); });
}

} // namespace hairvox::cli
