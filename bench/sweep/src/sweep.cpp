#include "job.h"
#include "measure.h"
#include "plots.h"
#include "report.h"
#include "text.h"

#include <hairvox/bench/sweep.h>
#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

namespace hairvox {

using namespace bench;
using nlohmann::json;

namespace {

using Clock = std::chrono::steady_clock;

/// The output directory's working files, removed however the sweep ends.
class WorkDir {
public:
    explicit WorkDir(std::filesystem::path path)
        : path_(std::move(path)) {
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_ / "scratch");
    }
    ~WorkDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    WorkDir(const WorkDir&) = delete;
    WorkDir& operator=(const WorkDir&) = delete;
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

/// Writes results.csv, results.md, scaling_fits.csv, host.json and the plots.
std::vector<std::filesystem::path> writeSweepOutputs(const SweepOptions& o, SweepResult& result,
                                                     const RunInfo& info,
                                                     const std::filesystem::path& workDir) {
    result.fits = fitScaling(result.rows);
    std::vector<std::filesystem::path> written;
    const auto writeText = [&](const std::filesystem::path& path, const std::string& text) {
        writeTextFile(path, text);
        written.push_back(path);
    };
    writeText(o.outDir / "results.csv", csvText(result.rows));
    writeText(o.outDir / "results.md", markdownText(o, result, info));
    writeText(o.outDir / "scaling_fits.csv", fitsCsvText(result.fits));
    writeText(o.outDir / "host.json", hostJsonText(info));
    const PlotResult plots = drawPlots(o.outDir, workDir);
    if (!plots.problem.empty() && o.log)
        *o.log << "bench: warning: no plots drawn: " << plots.problem << std::endl;
    written.insert(written.end(), plots.written.begin(), plots.written.end());
    return written;
}

} // namespace

Scene BenchScene::build() const {
    Scene scene = file.empty() ? defaultScene() : loadScene(file);
    if (style && !scene.groom.isProcedural())
        throw InputError(strCat(label, ": a groom style swap applies to procedural grooms only"));
    if (style) {
        scene.groom.procedural.style = *style;
        scene.groom.procedural.pointsPerStrand = pointsPerStrand;
    }
    if ((strands > 0 || pointsPerStrand > 0) && !scene.groom.isProcedural())
        throw InputError(
            strCat(label, ": strand and point counts apply to procedural grooms only"));
    if (strands > 0)
        scene.groom.procedural.strands = strands;
    if (pointsPerStrand > 0)
        scene.groom.procedural.pointsPerStrand = pointsPerStrand;
    if (width > 0)
        scene.camera.width = width;
    if (height > 0)
        scene.camera.height = height;
    if (voxelSize)
        scene.voxelSize = static_cast<float>(*voxelSize);
    if (eumelanin)
        scene.fiber.sigma_a = FiberParams::sigmaFromMelanin(*eumelanin, 0.0f);
    scene.name = label;
    scene.output.exr.clear();
    scene.output.png.clear();
    scene.validate();
    return scene;
}

BenchScene BenchScene::atWidth(std::uint32_t w) const {
    BenchScene s = *this;
    s.width = s.height = 0;
    const Scene scene = s.build();
    s.width = w;
    s.height = std::max<std::uint32_t>(
        1, std::uint32_t(std::lround(double(w) * scene.camera.height / scene.camera.width)));
    return s;
}

std::string BenchConfig::method() const {
    return integrator == Integrator::DualScattering ? toString(mode) : toString(integrator);
}

std::string BenchConfig::label() const {
    if (integrator == Integrator::Volumetric)
        return pathsPerCell > 0 ? strCat(method(), " ", scaleText(pathsPerCell), " paths/cell")
                                : method();
    if (integrator == Integrator::Path)
        return strCat(method(), " ", spp, " spp");
    if (mode == GlobalTermMode::Exact)
        return strCat("exact K=", rays);
    return strCat(toString(mode), " x", scaleText(voxelScale));
}

std::optional<PowerLawFit> fitPowerLaw(std::span<const double> x, std::span<const double> y) {
    if (x.size() != y.size())
        throw InputError(
            strCat("fitPowerLaw: ", x.size(), " x values but ", y.size(), " y values"));
    std::vector<double> lx, ly;
    for (std::size_t i = 0; i < x.size(); ++i)
        if (x[i] > 0 && y[i] > 0 && std::isfinite(x[i]) && std::isfinite(y[i])) {
            lx.push_back(std::log(x[i]));
            ly.push_back(std::log(y[i]));
        }
    const double n = double(lx.size());
    if (lx.size() < 2)
        return std::nullopt;
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < lx.size(); ++i) {
        mx += lx[i] / n;
        my += ly[i] / n;
    }
    double sxx = 0, sxy = 0, syy = 0;
    for (std::size_t i = 0; i < lx.size(); ++i) {
        sxx += (lx[i] - mx) * (lx[i] - mx);
        sxy += (lx[i] - mx) * (ly[i] - my);
        syy += (ly[i] - my) * (ly[i] - my);
    }
    if (!(sxx > 1e-24))
        return std::nullopt;
    PowerLawFit fit;
    fit.exponent = sxy / sxx;
    const double intercept = my - fit.exponent * mx;
    fit.coefficient = std::exp(intercept);
    double residual = 0;
    for (std::size_t i = 0; i < lx.size(); ++i) {
        const double r = ly[i] - (intercept + fit.exponent * lx[i]);
        residual += r * r;
    }
    fit.r2 = syy > 0 ? 1.0 - residual / syy : 1.0;
    return fit;
}

namespace {

/// The model sweep's scenes: the default look under its key and back lights,
/// the curly close-up and Ratboy at `size` pixels wide (the scenes' own aspect).
std::vector<BenchScene> modelScenes(const std::filesystem::path& scenesDir, std::uint32_t size,
                                    bool withRatboy) {
    std::vector<BenchScene> scenes;
    const auto add = [&](const char* label, std::filesystem::path file) {
        BenchScene s;
        s.label = label;
        s.file = std::move(file);
        // A missing file is named by validate(), before any work starts.
        scenes.push_back(std::filesystem::exists(s.file) || s.file.empty() ? s.atWidth(size) : s);
    };
    add("wavy (key + back)", scenesDir / "key_back.json");
    add("curly close-up", scenesDir / "curly_closeup.json");
    if (withRatboy)
        add("Ratboy mohawk", scenesDir / "ratboy_mohawk.json");
    return scenes;
}

/// `scene` at each voxel size (metres), labelled with it. A missing scene
/// file is left for validate() to name.
std::vector<BenchScene> voxelScenes(const BenchScene& scene, std::initializer_list<double> sizes) {
    std::vector<BenchScene> scenes;
    for (const double h : sizes) {
        BenchScene s = scene;
        s.label = strCat(scene.label, " ", format("%g", h * 1e3), " mm");
        s.voxelSize = h;
        scenes.push_back(s);
    }
    return scenes;
}

} // namespace

SweepOptions SweepOptions::full(const std::filesystem::path& scenesDir) {
    SweepOptions o;
    const std::filesystem::path ratboyScene = scenesDir / "ratboy_mohawk.json";
    const std::filesystem::path keyBack = scenesDir / "key_back.json";
    const auto style = [&](const char* label, GroomStyle s) {
        BenchScene b;
        b.label = label;
        b.file = keyBack;
        b.style = s;
        return b;
    };
    BenchScene wavy;
    wavy.label = "wavy (key + back)";
    wavy.file = keyBack;
    BenchScene ratboy;
    ratboy.label = "Ratboy mohawk";
    ratboy.file = ratboyScene;
    BenchScene head;
    head.label = "wavy head 1.4M";
    head.file = keyBack;
    head.strands = 50000;
    head.pointsPerStrand = 29;
    head.width = 1920;
    head.height = 1080;
    BenchScene bear;
    bear.label = "TressFX bear";
    bear.file = scenesDir / "bear.json";
    o.scenes = {style("straight", GroomStyle::Straight),
                wavy,
                style("curly", GroomStyle::Curly),
                ratboy,
                bear,
                head};
    o.voxelScales = {4, 2, 1.4, 1, 0.7};
    o.exactRays = {1, 4};
    o.referenceRays = 16;
    // 10k … 1.4M segments: 28 segments per strand.
    for (const std::uint32_t strands : {357u, 1071u, 3571u, 10714u, 25000u, 50000u}) {
        BenchScene s = head;
        s.label = strCat("wavy ", strands, " strands");
        s.strands = strands;
        o.segmentScaling.push_back(s);
    }
    for (const std::uint32_t size : {256u, 512u, 1024u, 2048u}) {
        BenchScene s;
        s.label = strCat("key + back ", size, "^2");
        s.file = keyBack;
        s.width = s.height = size;
        o.pixelScaling.push_back(s);
    }
    o.voxelScaling =
        voxelScenes(std::filesystem::exists(ratboy.file) ? ratboy.atWidth(1280) : ratboy,
                    {0.002, 0.001, 0.0007, 0.0005});
    o.model.scenes = modelScenes(scenesDir, 256, true);
    o.model.spp = 1024;
    o.model.block = 8;
    o.model.frontierPathsPerCell = {3, 48};
    o.model.frontierSpp = {4, 16, 64, 256};
    return o;
}

SweepOptions SweepOptions::quick(const std::filesystem::path& scenesDir) {
    SweepOptions o;
    const std::filesystem::path keyBack = scenesDir / "key_back.json";
    BenchScene wavy;
    wavy.label = "wavy (key + back) 512^2";
    wavy.file = keyBack;
    wavy.width = wavy.height = 512;
    BenchScene curly = wavy;
    curly.label = "curly 512^2";
    curly.style = GroomStyle::Curly;
    o.scenes = {wavy, curly};
    o.voxelScales = {4, 2, 1};
    o.exactRays = {1};
    o.referenceRays = 4;
    o.shadingRates = {ShadingRate::Fragment};
    o.probePoints = 500;
    o.runs = 1;
    for (const std::uint32_t strands : {357u, 3571u, 14286u}) {
        BenchScene s;
        s.label = strCat("wavy ", strands, " strands");
        s.file = keyBack;
        s.strands = strands;
        s.pointsPerStrand = 29;
        s.width = 960;
        s.height = 540;
        o.segmentScaling.push_back(s);
    }
    for (const std::uint32_t size : {256u, 512u, 1024u}) {
        BenchScene s;
        s.label = strCat("key + back ", size, "^2");
        s.file = keyBack;
        s.width = s.height = size;
        o.pixelScaling.push_back(s);
    }
    BenchScene ratboy;
    ratboy.label = "Ratboy mohawk";
    ratboy.file = scenesDir / "ratboy_mohawk.json";
    o.voxelScaling =
        voxelScenes(std::filesystem::exists(ratboy.file) ? ratboy.atWidth(640) : ratboy,
                    {0.002, 0.001, 0.0005});
    o.model.scenes = modelScenes(scenesDir, 128, false);
    o.model.spp = 64;
    o.model.block = 4;
    o.model.frontierPathsPerCell = {4};
    o.model.frontierSpp = {4, 16};
    return o;
}

std::size_t ModelSweepOptions::jobsPerCell() const {
    return 1 + modes.size() + (volumetric ? 1 : 0) + frontierPathsPerCell.size() +
           frontierSpp.size();
}

void SweepOptions::validate() const {
    if (scenes.empty() && segmentScaling.empty() && pixelScaling.empty() && voxelScaling.empty() &&
        model.scenes.empty())
        throw InputError("bench: nothing to measure (no scenes and no scaling sweep)");
    // The model sweep's rows are labelled "<scene>, <hair>": its scenes may
    // share labels with the accuracy sweep's, not among themselves.
    std::set<std::string> labels, modelLabels;
    for (const auto* list : {&scenes, &segmentScaling, &pixelScaling, &voxelScaling, &model.scenes})
        for (const BenchScene& s : *list) {
            if (s.voxelSize && !(*s.voxelSize > 0 && std::isfinite(*s.voxelSize)))
                throw InputError(strCat("bench: ", s.label, ": voxel size ", *s.voxelSize,
                                        " should be a positive number of metres"));
            auto& used = list == &model.scenes ? modelLabels : labels;
            if (!s.file.empty() && !std::filesystem::exists(s.file))
                throw InputError(strCat(s.file.string(),
                                        ": no such scene file (the default sweep "
                                        "reads data/scenes/ under the working directory: run it "
                                        "from the repository root, or pass --scene)"));
            if (!used.insert(s.label).second)
                throw InputError(strCat("bench: two scenes are labelled \"", s.label, "\""));
        }
    if (!scenes.empty() && (voxelScales.empty() || shadingRates.empty()))
        throw InputError("bench: give at least one voxel size and one shading rate");
    for (const double s : voxelScales)
        if (!(s >= 1.0 / 64 && s <= 64))
            throw InputError(strCat("bench: voxel scale ", s, " outside [1/64, 64]"));
    for (const std::uint32_t k : exactRays)
        if (k < 1 || k > 65536)
            throw InputError(strCat("bench: exact rays ", k, " outside [1, 65536]"));
    if (referenceRays < 1 || referenceRays > 65536 || probeRays < 1 || probeRays > 65536)
        throw InputError("bench: reference and probe rays must be in [1, 65536]");
    if (runs < 1 || runs > 100)
        throw InputError(strCat("bench: runs ", runs, " outside [1, 100]"));
    if (!(singleRunAbove >= 0))
        throw InputError(strCat("bench: singleRunAbove ", singleRunAbove, " should be ≥ 0"));
    if (outDir.empty())
        throw InputError("bench: empty output directory");
    if (!model.scenes.empty()) {
        if (model.melanins.empty() || model.modes.empty())
            throw InputError("bench: the model sweep needs at least one melanin and one mode");
        for (const auto& [name, eumelanin] : model.melanins)
            if (name.empty() || !(eumelanin >= 0 && eumelanin <= 50))
                throw InputError(strCat("bench: model melanin \"", name, "\" = ", eumelanin,
                                        " should be named and in [0, 50]"));
        if (model.spp < 2 || model.spp > 1000000)
            throw InputError(strCat("bench: model spp ", model.spp, " outside [2, 10^6]"));
        if (!(model.timeLimit >= 0))
            throw InputError(strCat("bench: model time limit ", model.timeLimit, " should be ≥ 0"));
        if (model.block < 1 || model.block > 64)
            throw InputError(strCat("bench: model block ", model.block, " outside [1, 64]"));
        for (const float n : model.frontierPathsPerCell)
            if (!(n > 0 && n <= 1e4f))
                throw InputError(
                    strCat("bench: frontier paths per cell ", n, " outside (0, 10^4]"));
        for (const std::uint32_t n : model.frontierSpp)
            if (n < 2 || n >= model.spp)
                throw InputError(strCat("bench: frontier spp ", n, " outside [2, ", model.spp,
                                        "): the path tracer is measured against a reference of ",
                                        model.spp, " spp"));
    }
}

void runBenchJobFile(const std::filesystem::path& jobFile) {
    BenchJob job;
    try {
        job = jobFromJson(readJsonFile(jobFile));
    } catch (const json::exception& e) {
        throw InputError(strCat(jobFile.string(), ": not a benchmark job: ", e.what()));
    }
    writeJsonFile(job.result, measurementToJson(runJob(job)));
}

SweepResult runSweep(const SweepOptions& o) {
    o.validate();
    for (const auto* list :
         {&o.scenes, &o.segmentScaling, &o.pixelScaling, &o.voxelScaling, &o.model.scenes})
        for (const BenchScene& s : *list)
            s.build(); // every scene is valid before hours of work start
    std::filesystem::create_directories(o.outDir);
    const WorkDir work(o.outDir / ".work");
    RunInfo info = RunInfo::now();

    std::vector<double> probeScales = o.voxelScales;
    if (std::find(probeScales.begin(), probeScales.end(), 1.0) == probeScales.end())
        probeScales.push_back(1.0); // the exact configurations' footprint
    const std::size_t perScene =
        1 + o.shadingRates.size() * (o.exactRays.size() + 2 * o.voxelScales.size());
    const std::size_t jobCount =
        o.scenes.size() * perScene + o.segmentScaling.size() + o.pixelScaling.size() +
        o.voxelScaling.size() +
        o.model.scenes.size() * o.model.melanins.size() * o.model.jobsPerCell();
    std::size_t jobIndex = 0;
    const auto start = Clock::now();

    SweepResult result;
    const auto run = [&](BenchJob job, BenchSweepKind kind) {
        throwIfInterrupted();
        const double load = loadAverage();
        info.loadMax = std::max(info.loadMax, load);
        // References and the model sweep (whose figure is an error): one run.
        job.runs = kind == BenchSweepKind::Reference || kind == BenchSweepKind::PathReference ||
                           kind == BenchSweepKind::Model
                       ? 1
                       : o.runs;
        job.singleRunAbove = o.singleRunAbove;
        job.threads = o.threads;
        job.isolated = !o.workerCommand.empty();
        job.scratch = work.path() / "scratch";
        const std::filesystem::path jobFile = work.path() / strCat("job-", jobIndex, ".json");
        job.result = work.path() / strCat("job-", jobIndex, ".result.json");
        ++jobIndex;
        writeJsonFile(jobFile, jobToJson(job));
        if (o.workerCommand.empty())
            runBenchJobFile(jobFile);
        else
            runWorker(o.workerCommand, jobFile);
        BenchRow row;
        row.kind = kind;
        row.scene = job.scene.label;
        row.eumelanin = job.scene.eumelanin;
        row.config = job.config;
        const Scene scene = job.scene.build();
        if (row.config.integrator == Integrator::Volumetric && row.config.pathsPerCell == 0)
            row.config.pathsPerCell = scene.volumetric.pathsPerCell; // the budget it ran at
        row.width = scene.camera.width;
        row.height = scene.camera.height;
        row.block = kind == BenchSweepKind::Accuracy ? kAccuracyBlock
                    : kind == BenchSweepKind::Model  ? job.block
                                                     : 0;
        row.m = measurementFromJson(readJsonFile(job.result));
        if (o.log) {
            const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
            std::string line = strCat("[", jobIndex, "/", jobCount, " ", int(elapsed) / 60, ":",
                                      format("%02.0f", std::fmod(std::floor(elapsed), 60.0)), "] ",
                                      row.scene, ", ", configText(row));
            if (kind == BenchSweepKind::Accuracy)
                line += strCat(", ", toString(row.config.shadingRate));
            line += strCat(": ", seconds(row.m.totalSeconds), " s (global term ",
                           seconds(row.m.times.globalTerm), " s)");
            if (row.m.peakMiB)
                line += strCat(", ", format("%.0f", *row.m.peakMiB), " MiB");
            if (row.m.pathTrace)
                line += strCat(", ", row.m.pathTrace->spp, " spp, ",
                               format("%.2f", row.m.pathTrace->raysPerSecond() * 1e-6), " Mrays/s");
            if (row.m.image)
                line += strCat(", rel L1 ", format("%.4f", row.m.image->relL1));
            if (row.m.image && row.m.image->noiseFloorL1 > 0)
                line += strCat(" (noise floor ", format("%.4f", row.m.image->noiseFloorL1),
                               ", removed ", format("%.4f", row.m.image->relL1NoiseRemoved),
                               ", bias ", format("%+.4f", row.m.image->relBias), ")");
            if (row.m.probe)
                line += strCat(", MAE(V) ", format("%.4f", row.m.probe->maeV), ", MAE(T_s) ",
                               format("%.4f", row.m.probe->maeT_s));
            *o.log << line << "   [load " << format("%.1f", load) << "]" << std::endl;
        }
        result.rows.push_back(row);
        return row.m;
    };

    for (std::size_t si = 0; si < o.scenes.size(); ++si) {
        const BenchScene& scene = o.scenes[si];
        BenchJob ref;
        ref.reference = true;
        ref.scene = scene;
        ref.config = {GlobalTermMode::Exact, 1.0, o.referenceRays, ShadingRate::Fragment};
        ref.referenceImage = work.path() / strCat("scene-", si, "-reference.bin");
        ref.probePoints = o.probePoints;
        ref.probeSeed = o.probeSeed;
        ref.probeRays = o.probeRays;
        ref.probeScales = probeScales;
        for (std::size_t i = 0; i < probeScales.size(); ++i)
            ref.probeFiles.push_back(work.path() / strCat("scene-", si, "-probe-", i, ".bin"));
        const double h0 = run(ref, BenchSweepKind::Reference).defaultVoxelSize;

        std::vector<BenchConfig> configs;
        for (const std::uint32_t k : o.exactRays)
            configs.push_back({GlobalTermMode::Exact, 1.0, k, ShadingRate::Fragment});
        for (const GlobalTermMode mode : {GlobalTermMode::Grid, GlobalTermMode::Approx})
            for (const double s : o.voxelScales)
                configs.push_back({mode, s, 1, ShadingRate::Fragment});
        for (const BenchConfig& base : configs) {
            std::optional<ProbeError> probe; // independent of the shading rate: measured once
            for (const ShadingRate rate : o.shadingRates) {
                BenchJob job;
                job.scene = scene;
                job.config = base;
                job.config.shadingRate = rate;
                job.voxelSize = base.voxelScale * h0;
                job.referenceImage = ref.referenceImage;
                if (!probe && o.probePoints > 0) {
                    job.probePoints = o.probePoints;
                    job.probeSeed = o.probeSeed;
                    const auto at =
                        std::find(probeScales.begin(), probeScales.end(), base.voxelScale);
                    job.probeFiles = {ref.probeFiles[std::size_t(at - probeScales.begin())]};
                }
                const BenchMeasurement m = run(job, BenchSweepKind::Accuracy);
                if (m.probe)
                    probe = m.probe;
                else
                    result.rows.back().m.probe = probe;
            }
        }
        info.loadEnd = loadAverage(); // so far: the outputs are complete up to this scene
        result.written = writeSweepOutputs(o, result, info, work.path());
    }

    for (std::size_t si = 0; si < o.model.scenes.size(); ++si) {
        for (std::size_t mi = 0; mi < o.model.melanins.size(); ++mi) {
            BenchScene scene = o.model.scenes[si];
            scene.label = strCat(scene.label, ", ", o.model.melanins[mi].first);
            scene.eumelanin = o.model.melanins[mi].second;
            BenchJob ref;
            ref.pathReference = true;
            ref.scene = scene;
            ref.spp = o.model.spp;
            ref.timeLimit = o.model.timeLimit;
            ref.referenceImage = work.path() / strCat("model-", si, "-", mi, "-reference.bin");
            run(ref, BenchSweepKind::PathReference);
            const auto measure = [&](BenchConfig config) {
                BenchJob job;
                job.scene = scene;
                job.config = config;
                job.referenceImage = ref.referenceImage;
                job.block = o.model.block;
                run(job, BenchSweepKind::Model);
            };
            for (const GlobalTermMode mode : o.model.modes)
                measure({mode, 1.0, 1, ShadingRate::Fragment});
            BenchConfig volumetric{GlobalTermMode::Grid, 1.0, 1, ShadingRate::Fragment,
                                   Integrator::Volumetric};
            if (o.model.volumetric)
                measure(volumetric);
            for (const float n : o.model.frontierPathsPerCell) {
                volumetric.pathsPerCell = n;
                measure(volumetric);
            }
            for (const std::uint32_t n : o.model.frontierSpp) {
                BenchConfig path{GlobalTermMode::Grid, 1.0, 1, ShadingRate::Fragment,
                                 Integrator::Path};
                path.spp = n;
                measure(path);
            }
        }
        info.loadEnd = loadAverage();
        result.written = writeSweepOutputs(o, result, info, work.path());
    }

    for (const auto& [list, kind] : {std::pair{&o.segmentScaling, BenchSweepKind::Segments},
                                     std::pair{&o.pixelScaling, BenchSweepKind::Pixels},
                                     std::pair{&o.voxelScaling, BenchSweepKind::Voxels}})
        for (const BenchScene& scene : *list) {
            BenchJob job;
            job.scene = scene;
            job.config = {GlobalTermMode::Grid, 1.0, 1, ShadingRate::Fragment};
            run(job, kind);
        }
    info.loadEnd = loadAverage();
    info.loadMax = std::max(info.loadMax, info.loadEnd);
    result.written = writeSweepOutputs(o, result, info, work.path());
    return result;
}

} // namespace hairvox
