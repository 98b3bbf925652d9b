#include <hairvox/render/bench_sweep.h>

#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/parallel.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <nlohmann/json.hpp>
#include <png.h>

#include <algorithm>
#include <cerrno>
#include <cstdarg>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <functional>
#include <set>
#include <thread>

#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace hairvox {

using nlohmann::json;

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
    if (v.empty())
        return 0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Peak resident memory of this process so far (ru_maxrss is in KiB on Linux).
double peakResidentMiB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;
}

double loadAverage() {
    double load[3] = {0, 0, 0};
    return getloadavg(load, 3) >= 1 ? load[0] : 0.0;
}

[[gnu::format(printf, 1, 2)]] std::string format(const char* fmt, ...) {
    char buf[128];
    va_list args;
    va_start(args, fmt);
    std::vsnprintf(buf, sizeof(buf), fmt, args);
    va_end(args);
    return buf;
}

/// A voxel scale as written in labels: 1.4, 0.7, 2.
std::string scaleText(double scale) { return format("%g", scale); }

// --- Binary working files (references shared between job processes) ---------
//
// "HVXBENCH", u64 header count, u64 float count, u64 header[], f32 data[]
// (native byte order: written and read by the same executable on one machine).

constexpr char kFloatFileMagic[8] = {'H', 'V', 'X', 'B', 'E', 'N', 'C', 'H'};

struct FloatFile {
    std::vector<std::uint64_t> header;
    std::vector<float> data;
};

void writeFloatFile(const std::filesystem::path& path, const FloatFile& file) {
    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        const std::uint64_t counts[2] = {file.header.size(), file.data.size()};
        out.write(kFloatFileMagic, sizeof(kFloatFileMagic));
        out.write(reinterpret_cast<const char*>(counts), sizeof(counts));
        out.write(reinterpret_cast<const char*>(file.header.data()),
                  static_cast<std::streamsize>(file.header.size() * sizeof(std::uint64_t)));
        out.write(reinterpret_cast<const char*>(file.data.data()),
                  static_cast<std::streamsize>(file.data.size() * sizeof(float)));
        if (!out)
            throw InputError(strCat(path.string(), ": cannot write"));
    });
}

FloatFile readFloatFile(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    char magic[8] = {};
    std::uint64_t counts[2] = {0, 0};
    in.read(magic, sizeof(magic));
    in.read(reinterpret_cast<char*>(counts), sizeof(counts));
    std::error_code ec;
    const std::uint64_t size = std::filesystem::file_size(path, ec);
    if (!in || ec || std::memcmp(magic, kFloatFileMagic, sizeof(magic)) != 0 || counts[0] > 64 ||
        size != sizeof(magic) + sizeof(counts) + counts[0] * 8 + counts[1] * 4)
        throw InputError(strCat(path.string(), ": not a benchmark working file of this version"));
    FloatFile file;
    file.header.resize(counts[0]);
    file.data.resize(counts[1]);
    in.read(reinterpret_cast<char*>(file.header.data()),
            static_cast<std::streamsize>(file.header.size() * sizeof(std::uint64_t)));
    in.read(reinterpret_cast<char*>(file.data.data()),
            static_cast<std::streamsize>(file.data.size() * sizeof(float)));
    if (!in)
        throw InputError(strCat(path.string(), ": truncated"));
    return file;
}

void writeBeautyImage(const std::filesystem::path& path, const BeautyImage& image) {
    FloatFile file;
    file.header = {std::uint64_t(image.width), std::uint64_t(image.height)};
    file.data.reserve(image.beauty.size() * 4);
    for (const Rgb& c : image.beauty)
        file.data.insert(file.data.end(), {c.r, c.g, c.b});
    file.data.insert(file.data.end(), image.hairAlpha.begin(), image.hairAlpha.end());
    writeFloatFile(path, file);
}

BeautyImage readBeautyImage(const std::filesystem::path& path) {
    const FloatFile file = readFloatFile(path);
    if (file.header.size() != 2 || file.header[0] * file.header[1] * 4 != file.data.size())
        throw InputError(strCat(path.string(), ": not a reference image"));
    BeautyImage image;
    image.width = static_cast<int>(file.header[0]);
    image.height = static_cast<int>(file.header[1]);
    const std::size_t n = file.data.size() / 4;
    image.beauty.resize(n);
    for (std::size_t p = 0; p < n; ++p)
        image.beauty[p] = Rgb(file.data[3 * p], file.data[3 * p + 1], file.data[3 * p + 2]);
    image.hairAlpha.assign(file.data.begin() + std::ptrdiff_t(3 * n), file.data.end());
    return image;
}

constexpr std::size_t kTermFloats = 11; // n, V, P, T_s, σ_f²

/// Global terms per light (outer) and point (inner).
void writeProbeTerms(const std::filesystem::path& path,
                     const std::vector<std::vector<GlobalTerm>>& terms) {
    FloatFile file;
    file.header = {terms.size(), terms.empty() ? 0 : terms.front().size()};
    for (const auto& light : terms)
        for (const GlobalTerm& g : light)
            file.data.insert(file.data.end(), {g.n, g.V, g.P.r, g.P.g, g.P.b, g.T_s.r, g.T_s.g,
                                               g.T_s.b, g.sigma2_f.r, g.sigma2_f.g, g.sigma2_f.b});
    writeFloatFile(path, file);
}

std::vector<std::vector<GlobalTerm>> readProbeTerms(const std::filesystem::path& path) {
    const FloatFile file = readFloatFile(path);
    if (file.header.size() != 2 || file.header[0] * file.header[1] * kTermFloats != file.data.size())
        throw InputError(strCat(path.string(), ": not a probe reference"));
    std::vector<std::vector<GlobalTerm>> terms(file.header[0],
                                               std::vector<GlobalTerm>(file.header[1]));
    const float* f = file.data.data();
    for (auto& light : terms)
        for (GlobalTerm& g : light) {
            g = {f[0], f[1], Rgb(f[2], f[3], f[4]), Rgb(f[5], f[6], f[7]), Rgb(f[8], f[9], f[10])};
            f += kTermFloats;
        }
    return terms;
}

// --- Jobs --------------------------------------------------------------------

/// One job of a sweep, run in a child process (or in this one).
struct BenchJob {
    bool reference = false; ///< render the exact reference and write the probe references
    BenchScene scene;
    BenchConfig config;
    double voxelSize = 0; ///< grid voxel size or exact footprint radius; 0: h0
    int runs = 1;
    double singleRunAbove = 0; ///< seconds; a first run longer than this is the only one
    int threads = 0;
    bool isolated = false; ///< in its own process: its peak memory is its own
    std::filesystem::path scratch; ///< where the renders write their outputs
    /// Reference: written; configuration: compared against (empty: no image error).
    std::filesystem::path referenceImage;
    std::size_t probePoints = 0;
    std::uint64_t probeSeed = 1;
    std::uint32_t probeRays = 256;
    std::vector<double> probeScales; ///< reference: footprints (× h0) of the probe references
    /// Reference: one per scale (written); configuration: [0] is compared against.
    std::vector<std::filesystem::path> probeFiles;
    std::filesystem::path result;
};

json sceneToJson(const BenchScene& s) {
    return {{"label", s.label},
            {"file", s.file.string()},
            {"style", s.style ? json(toString(*s.style)) : json(nullptr)},
            {"strands", s.strands},
            {"points_per_strand", s.pointsPerStrand},
            {"width", s.width},
            {"height", s.height}};
}

BenchScene sceneFromJson(const json& j) {
    BenchScene s;
    s.label = j.at("label").get<std::string>();
    s.file = j.at("file").get<std::string>();
    if (!j.at("style").is_null())
        s.style = parseGroomStyle(j.at("style").get<std::string>());
    s.strands = j.at("strands").get<std::uint32_t>();
    s.pointsPerStrand = j.at("points_per_strand").get<std::uint32_t>();
    s.width = j.at("width").get<std::uint32_t>();
    s.height = j.at("height").get<std::uint32_t>();
    return s;
}

json jobToJson(const BenchJob& job) {
    json probeFiles = json::array();
    for (const auto& p : job.probeFiles)
        probeFiles.push_back(p.string());
    return {{"reference", job.reference},
            {"scene", sceneToJson(job.scene)},
            {"mode", toString(job.config.mode)},
            {"voxel_scale", job.config.voxelScale},
            {"rays", job.config.rays},
            {"shading_rate", toString(job.config.shadingRate)},
            {"voxel_size", job.voxelSize},
            {"runs", job.runs},
            {"single_run_above", job.singleRunAbove},
            {"threads", job.threads},
            {"isolated", job.isolated},
            {"scratch", job.scratch.string()},
            {"reference_image", job.referenceImage.string()},
            {"probe_points", job.probePoints},
            {"probe_seed", job.probeSeed},
            {"probe_rays", job.probeRays},
            {"probe_scales", job.probeScales},
            {"probe_files", probeFiles},
            {"result", job.result.string()}};
}

BenchJob jobFromJson(const json& j) {
    BenchJob job;
    job.reference = j.at("reference").get<bool>();
    job.scene = sceneFromJson(j.at("scene"));
    job.config.mode = parseGlobalTermMode(j.at("mode").get<std::string>()).value();
    job.config.voxelScale = j.at("voxel_scale").get<double>();
    job.config.rays = j.at("rays").get<std::uint32_t>();
    job.config.shadingRate = parseShadingRate(j.at("shading_rate").get<std::string>()).value();
    job.voxelSize = j.at("voxel_size").get<double>();
    job.runs = j.at("runs").get<int>();
    job.singleRunAbove = j.at("single_run_above").get<double>();
    job.threads = j.at("threads").get<int>();
    job.isolated = j.at("isolated").get<bool>();
    job.scratch = j.at("scratch").get<std::string>();
    job.referenceImage = j.at("reference_image").get<std::string>();
    job.probePoints = j.at("probe_points").get<std::size_t>();
    job.probeSeed = j.at("probe_seed").get<std::uint64_t>();
    job.probeRays = j.at("probe_rays").get<std::uint32_t>();
    job.probeScales = j.at("probe_scales").get<std::vector<double>>();
    for (const auto& p : j.at("probe_files"))
        job.probeFiles.emplace_back(p.get<std::string>());
    job.result = j.at("result").get<std::string>();
    return job;
}

json optionalJson(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

std::optional<double> optionalFromJson(const json& j) {
    return j.is_null() ? std::nullopt : std::optional<double>(j.get<double>());
}

json measurementToJson(const BenchMeasurement& m) {
    const StageTimes& t = m.times;
    json j = {{"times",
               {{"load", t.load},
                {"voxelize", t.voxelize},
                {"tables", t.tables},
                {"global_term", t.globalTerm},
                {"raster", t.raster},
                {"shade", t.shade},
                {"write", t.write}}},
              {"total", m.totalSeconds},
              {"runs", m.runs},
              {"peak_mib", optionalJson(m.peakMiB)},
              {"segments", m.segments},
              {"shading_points", m.shadingPoints},
              {"active_voxels", m.activeVoxels},
              {"voxel_size", m.voxelSize},
              {"default_voxel_size", m.defaultVoxelSize},
              {"image", nullptr},
              {"probe", nullptr}};
    if (m.image)
        j["image"] = {{"rel_l1", m.image->relL1},
                      {"rel_rmse", m.image->relRmse},
                      {"hair_pixels", m.image->hairPixels}};
    if (m.probe)
        j["probe"] = {{"mae_v", m.probe->maeV},
                      {"mae_ts", m.probe->maeT_s},
                      {"bias_n", m.probe->biasN},
                      {"mean_n_ref", m.probe->meanNRef}};
    return j;
}

BenchMeasurement measurementFromJson(const json& j) {
    BenchMeasurement m;
    const json& t = j.at("times");
    m.times.load = t.at("load").get<double>();
    m.times.voxelize = t.at("voxelize").get<double>();
    m.times.tables = t.at("tables").get<double>();
    m.times.globalTerm = t.at("global_term").get<double>();
    m.times.raster = t.at("raster").get<double>();
    m.times.shade = t.at("shade").get<double>();
    m.times.write = t.at("write").get<double>();
    m.totalSeconds = j.at("total").get<double>();
    m.runs = j.at("runs").get<int>();
    m.peakMiB = optionalFromJson(j.at("peak_mib"));
    m.segments = j.at("segments").get<std::uint64_t>();
    m.shadingPoints = j.at("shading_points").get<std::uint64_t>();
    m.activeVoxels = j.at("active_voxels").get<std::uint64_t>();
    m.voxelSize = j.at("voxel_size").get<double>();
    m.defaultVoxelSize = j.at("default_voxel_size").get<double>();
    if (const json& i = j.at("image"); !i.is_null())
        m.image = ImageError{i.at("rel_l1").get<double>(), i.at("rel_rmse").get<double>(),
                             i.at("hair_pixels").get<std::size_t>()};
    if (const json& p = j.at("probe"); !p.is_null())
        m.probe = ProbeError{p.at("mae_v").get<double>(), p.at("mae_ts").get<double>(),
                             p.at("bias_n").get<double>(), p.at("mean_n_ref").get<double>()};
    return m;
}

void writeJsonFile(const std::filesystem::path& path, const json& j) {
    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        std::ofstream out(tmp, std::ios::trunc);
        out << j.dump(1) << "\n";
        if (!out)
            throw InputError(strCat(path.string(), ": cannot write"));
    });
}

json readJsonFile(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in)
        throw InputError(strCat(path.string(), ": cannot open"));
    try {
        return json::parse(in);
    } catch (const json::exception& e) {
        throw InputError(strCat(path.string(), ": ", e.what()));
    }
}

/// The lights a render evaluates (the renderer skips dark ones).
std::vector<const Light*> litLights(const Scene& scene) {
    std::vector<const Light*> lights;
    for (const Light& l : scene.lights)
        if (l.intensity > 0 && !l.color.isBlack())
            lights.push_back(&l);
    return lights;
}

/// The global term of the scene's mode toward every lit light at `points`,
/// without the head (see the header comment).
std::vector<std::vector<GlobalTerm>> probeTerms(Scene scene, const PipelineOptions& options,
                                                const std::vector<GlobalTermQuery>& points) {
    scene.head.reset();
    const std::unique_ptr<SceneAssets> assets = loadSceneAssets(scene, options);
    std::vector<std::vector<GlobalTerm>> terms;
    for (const Light* light : litLights(scene))
        terms.push_back(evaluateGlobalTerm(*assets->globalTerm, *light, points));
    return terms;
}

std::vector<GlobalTermQuery> probePointsOf(const Scene& scene, const BenchJob& job, double* h0) {
    std::string warnings;
    const Groom groom = loadGroom(scene, warnings);
    if (h0)
        *h0 = scene.voxelSize ? double(*scene.voxelSize) : defaultVoxelSize(groom);
    return sampleFiberPoints(groom, job.probePoints, job.probeSeed);
}

ProbeError meanProbeError(const std::vector<std::vector<GlobalTerm>>& estimate,
                          const std::vector<std::vector<GlobalTerm>>& reference,
                          const std::filesystem::path& referenceFile) {
    if (estimate.size() != reference.size())
        throw InputError(strCat(referenceFile.string(), ": ", reference.size(),
                                " light(s), the scene has ", estimate.size()));
    ProbeError mean;
    for (std::size_t l = 0; l < estimate.size(); ++l) {
        if (estimate[l].size() != reference[l].size())
            throw InputError(strCat(referenceFile.string(), ": ", reference[l].size(),
                                    " probe points, expected ", estimate[l].size()));
        const ProbeError e = compareGlobalTerms(estimate[l], reference[l]);
        const double w = 1.0 / double(estimate.size());
        mean.maeV += w * e.maeV;
        mean.maeT_s += w * e.maeT_s;
        mean.biasN += w * e.biasN;
        mean.meanNRef += w * e.meanNRef;
    }
    return mean;
}

/// Renders the job's configuration `runs` times end to end (once if the first
/// run is longer than singleRunAbove) and takes medians.
BenchMeasurement timeRenders(const Scene& scene, const BenchJob& job,
                             const PipelineOptions& options, Film* lastFilm) {
    std::vector<double> load, voxelize, tables, globalTerm, raster, shade, write, total;
    BenchMeasurement m;
    int runs = job.runs;
    for (int r = 0; r < runs; ++r) {
        SceneRender render = renderScene(scene, options, true);
        const StageTimes& t = render.times;
        load.push_back(t.load);
        voxelize.push_back(t.voxelize);
        tables.push_back(t.tables);
        globalTerm.push_back(t.globalTerm);
        raster.push_back(t.raster);
        shade.push_back(t.shade);
        write.push_back(t.write);
        total.push_back(t.total());
        m.segments = render.image.stats.segments;
        m.shadingPoints = render.image.stats.shadingPoints;
        m.activeVoxels = render.activeVoxels;
        m.voxelSize = scene.globalTermMode == GlobalTermMode::Exact ? double(scene.exact.radius)
                                                                    : render.voxelSize;
        if (r == 0 && job.singleRunAbove > 0 && t.total() > job.singleRunAbove)
            runs = 1;
        // Only the last film is kept: holding one across renders would raise the peak.
        if (r + 1 == runs && lastFilm)
            *lastFilm = std::move(render.image.film);
    }
    m.times = {median(load),   median(voxelize), median(tables), median(globalTerm),
               median(raster), median(shade),    median(write)};
    m.totalSeconds = median(total);
    m.runs = runs;
    if (job.isolated)
        m.peakMiB = peakResidentMiB();
    return m;
}

BenchMeasurement runJob(const BenchJob& job) {
    const ThreadLimit threadLimit(job.threads);
    Scene scene = job.scene.build();
    scene.output.exr = job.scratch / "render.exr";
    scene.output.png = job.scratch / "render.png";
    scene.globalTermMode = job.config.mode;
    scene.shadingRate = job.config.shadingRate;
    PipelineOptions options;
    options.threads = job.threads;

    if (job.reference) {
        // h0 first: it is the reference's footprint. The render comes before
        // the probe references so that its peak memory is its own.
        double h0 = 0;
        const std::vector<GlobalTermQuery> points = probePointsOf(scene, job, &h0);
        scene.exact.rays = job.config.rays;
        scene.exact.radius = static_cast<float>(h0);
        Film film;
        BenchMeasurement m = timeRenders(scene, job, options, &film);
        m.defaultVoxelSize = h0;
        writeBeautyImage(job.referenceImage, BeautyImage::fromFilm(film));
        for (std::size_t i = 0; i < job.probeScales.size() && job.probePoints > 0; ++i) {
            Scene probe = scene;
            probe.exact.rays = job.probeRays;
            probe.exact.radius = static_cast<float>(job.probeScales[i] * h0);
            writeProbeTerms(job.probeFiles.at(i), probeTerms(probe, options, points));
        }
        return m;
    }

    if (job.config.mode == GlobalTermMode::Exact) {
        scene.exact.rays = job.config.rays;
        scene.exact.radius = static_cast<float>(job.voxelSize);
    } else if (job.voxelSize > 0) {
        scene.voxelSize = static_cast<float>(job.voxelSize);
    }
    scene.validate();
    Film film;
    BenchMeasurement m = timeRenders(scene, job, options, &film);
    m.defaultVoxelSize = m.voxelSize / job.config.voxelScale;
    if (!job.referenceImage.empty())
        m.image = compareImages(BeautyImage::fromFilm(film), readBeautyImage(job.referenceImage));
    film = Film();
    if (job.probePoints > 0 && !job.probeFiles.empty()) {
        const std::vector<GlobalTermQuery> points = probePointsOf(scene, job, nullptr);
        m.probe = meanProbeError(probeTerms(scene, options, points),
                                 readProbeTerms(job.probeFiles.front()), job.probeFiles.front());
    }
    return m;
}

/// Runs `command... jobFile` and waits for it.
void runWorker(const std::vector<std::string>& command, const std::filesystem::path& jobFile) {
    std::vector<std::string> args = command;
    args.push_back(jobFile.string());
    std::vector<char*> argv;
    for (std::string& a : args)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ);
    if (rc != 0)
        throw InputError(strCat("cannot start the benchmark worker ", args[0], ": ",
                                std::strerror(rc)));
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            throw std::runtime_error(strCat("waitpid: ", std::strerror(errno)));
    const bool interrupted = (WIFSIGNALED(status) && WTERMSIG(status) == SIGINT) ||
                             (WIFEXITED(status) && WEXITSTATUS(status) == 130);
    if (interrupted)
        throw Interrupted();
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
        return;
    const std::string how = WIFEXITED(status) ? strCat("exit code ", WEXITSTATUS(status))
                                              : strCat("signal ", WTERMSIG(status));
    const std::string message = strCat("benchmark job ", jobFile.string(), " failed (", how,
                                       "; its message is above)");
    if (WIFEXITED(status) && WEXITSTATUS(status) == 2)
        throw InputError(message);
    throw std::runtime_error(message);
}

// --- Machine and time stamps ---------------------------------------------------

std::string cpuModel() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) {
            const std::size_t colon = line.find(':');
            if (colon != std::string::npos)
                return line.substr(line.find_first_not_of(' ', colon + 1));
        }
    return "unknown CPU";
}

std::string utcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buf[64];
    std::strftime(buf, sizeof(buf), "%Y-%m-%d %H:%M UTC", &tm);
    return buf;
}

struct RunInfo {
    std::string started, cpu;
    unsigned cores = 0;
    double loadStart = 0, loadMax = 0, loadEnd = 0;
};

// --- Tables --------------------------------------------------------------------

std::string csvNumber(double v) { return format("%.6g", v); }
std::string csvOptional(const std::optional<double>& v) { return v ? csvNumber(*v) : ""; }

std::string csvText(const std::vector<BenchRow>& rows) {
    std::string out;
    for (std::size_t i = 0; i < kBenchCsvColumns.size(); ++i)
        out += std::string(i ? "," : "") + kBenchCsvColumns[i];
    out += "\n";
    for (const BenchRow& r : rows) {
        const BenchMeasurement& m = r.m;
        const StageTimes& t = m.times;
        const std::vector<std::string> cells = {
            toString(r.kind),
            r.scene,
            toString(r.config.mode),
            csvNumber(r.config.voxelScale),
            csvNumber(m.voxelSize),
            r.config.mode == GlobalTermMode::Exact ? std::to_string(r.config.rays) : "",
            toString(r.config.shadingRate),
            std::to_string(r.width),
            std::to_string(r.height),
            std::to_string(m.segments),
            std::to_string(m.runs),
            csvNumber(t.load),
            csvNumber(t.voxelize),
            csvNumber(t.tables),
            csvNumber(t.globalTerm),
            csvNumber(t.raster),
            csvNumber(t.shade),
            csvNumber(t.write),
            csvNumber(m.totalSeconds),
            csvOptional(m.peakMiB),
            std::to_string(m.shadingPoints),
            std::to_string(m.activeVoxels),
            csvOptional(m.image ? std::optional(m.image->relL1) : std::nullopt),
            csvOptional(m.image ? std::optional(m.image->relRmse) : std::nullopt),
            csvOptional(m.probe ? std::optional(m.probe->maeV) : std::nullopt),
            csvOptional(m.probe ? std::optional(m.probe->maeT_s) : std::nullopt)};
        for (std::size_t i = 0; i < cells.size(); ++i) {
            // Scene labels are the only free text: quote them if they need it.
            const bool quote = cells[i].find_first_of(",\"\n") != std::string::npos;
            std::string cell = cells[i];
            if (quote) {
                std::string escaped;
                for (char c : cell)
                    escaped += c == '"' ? std::string("\"\"") : std::string(1, c);
                cell = "\"" + escaped + "\"";
            }
            out += (i ? "," : "") + cell;
        }
        out += "\n";
    }
    return out;
}

/// Fixed-point with `digits` decimals, "–" when there is no value.
std::string mdOptional(const std::optional<double>& v, int digits) {
    return v ? format("%.*f", digits, *v) : "–";
}

std::string seconds(double s) { return format(s < 10 ? "%.2f" : "%.1f", s); }

std::string configText(const BenchRow& r) {
    if (r.kind == BenchSweepKind::Reference)
        return strCat("exact K=", r.config.rays, " (reference)");
    return r.config.label();
}

std::string thousands(std::uint64_t n) {
    std::string digits = std::to_string(n), out;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i > 0 && (digits.size() - i) % 3 == 0)
            out += ',';
        out += digits[i];
    }
    return out;
}

std::string imageSize(const BenchRow& r) { return strCat(r.width, "×", r.height); }

const BenchRow* findRow(const std::vector<BenchRow>& rows, const std::string& scene,
                        const std::function<bool(const BenchRow&)>& pred) {
    for (const BenchRow& r : rows)
        if (r.scene == scene && pred(r))
            return &r;
    return nullptr;
}

std::vector<std::string> sceneOrder(const std::vector<BenchRow>& rows, BenchSweepKind kind) {
    std::vector<std::string> order;
    for (const BenchRow& r : rows)
        if (r.kind == kind && std::find(order.begin(), order.end(), r.scene) == order.end())
            order.push_back(r.scene);
    return order;
}

const char* stageHeader() {
    return "| total s | load | voxelize | tables | global term | raster | shade | write | peak MiB |";
}

std::string stageCells(const BenchMeasurement& m) {
    const StageTimes& t = m.times;
    return strCat(" ", seconds(m.totalSeconds), " | ", seconds(t.load), " | ", seconds(t.voxelize),
                  " | ", seconds(t.tables), " | ", seconds(t.globalTerm), " | ", seconds(t.raster),
                  " | ", seconds(t.shade), " | ", seconds(t.write), " | ",
                  mdOptional(m.peakMiB, 0), " |");
}

std::string fitText(const char* what, const std::optional<PowerLawFit>& f) {
    if (!f)
        return strCat(what, " –");
    return strCat(what, " k = ", format("%.2f", f->exponent), " (R² ", format("%.3f", f->r2), ")");
}

std::string markdownText(const SweepOptions& o, const SweepResult& result, const RunInfo& info) {
    const std::vector<BenchRow>& rows = result.rows;
    std::string md = "# hairvox benchmark: run time against error, and how cost grows\n\n";
    md += strCat("Generated by `", o.commandLine.empty() ? std::string("hairvox bench") : o.commandLine,
                 "`, started ", info.started, ", on ", info.cpu, " (", info.cores,
                 " hardware threads), load average (1 min) ", format("%.1f", info.loadStart),
                 " at the start, at most ", format("%.1f", info.loadMax), ", ",
                 format("%.1f", info.loadEnd),
                 " at the end (the machine may be shared: times are wall clock).\n\n");
    md += strCat("Times are seconds, end to end through `renderScene()` including writing the EXR "
                 "and PNG; each stage is the median of ",
                 o.runs, o.runs == 1 ? " run" : " runs",
                 " and `total` the median of the totals (the exact reference: one run",
                 o.singleRunAbove > 0 && o.runs > 1
                     ? strCat("; a configuration whose first run takes over ",
                              format("%g", o.singleRunAbove), " s: one run")
                     : std::string(),
                 "). "
                 "Peak MiB is the resident peak of a process that ran that configuration alone. "
                 "Errors are against an exact-mode render with K rays per shading point spread "
                 "over a disk of one default voxel h0 (the scene's grid voxel size): relative L1 "
                 "and relative RMSE of the beauty over hair pixels; MAE(V) and MAE(T_s) at ",
                 o.probePoints, " points on the fibers toward each light, against exact mode with ",
                 o.probeRays,
                 " rays over a disk of the configuration's voxel size. `grid xS`/`approx xS`: "
                 "voxel size S·h0; `exact K=n`: n rays over the h0 disk. The image reference "
                 "is itself noisy (a few rays per shading point): its estimated share of the "
                 "rel L1, from the error of the exact configuration with the fewest rays "
                 "assuming variance ∝ 1/K, is the summary's last column — image errors near "
                 "it are at the reference's noise floor.\n\n");

    const std::vector<std::string> scenes = sceneOrder(rows, BenchSweepKind::Reference);
    if (!scenes.empty()) {
        const ShadingRate rate = o.shadingRates.front();
        const std::uint32_t fewestRays =
            o.exactRays.empty() ? 0 : *std::min_element(o.exactRays.begin(), o.exactRays.end());
        md += strCat("## Summary (", toString(rate), " shading)\n\n");
        md += strCat("| scene | segments | image | h0 | exact reference s | exact K=", fewestRays,
                     " s | grid x1 s | grid speed-up: global term, total | grid x1 rel L1 | "
                     "MAE(V) | MAE(T_s) | approx within grid's time | its rel L1 | reference "
                     "noise (est.) |\n");
        md += "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|\n";
        for (const std::string& s : scenes) {
            const BenchRow* ref = findRow(rows, s, [](const BenchRow& r) {
                return r.kind == BenchSweepKind::Reference;
            });
            const auto accuracy = [&](const BenchRow& r) {
                return r.kind == BenchSweepKind::Accuracy && r.config.shadingRate == rate;
            };
            const BenchRow* exact = findRow(rows, s, [&](const BenchRow& r) {
                return accuracy(r) && r.config.mode == GlobalTermMode::Exact &&
                       r.config.rays == fewestRays;
            });
            const BenchRow* grid = findRow(rows, s, [&](const BenchRow& r) {
                return accuracy(r) && r.config.mode == GlobalTermMode::Grid &&
                       r.config.voxelScale == 1.0;
            });
            std::string line = strCat("| ", s, " | ", ref ? thousands(ref->m.segments) : "–", " | ",
                                      ref ? imageSize(*ref) : "–", " | ",
                                      ref ? format("%.3g", ref->m.defaultVoxelSize) : "–", " | ",
                                      ref ? seconds(ref->m.totalSeconds) : "–", " | ",
                                      exact ? seconds(exact->m.totalSeconds) : "–", " | ",
                                      grid ? seconds(grid->m.totalSeconds) : "–", " | ");
            if (grid && exact && grid->m.times.globalTerm > 0 && grid->m.totalSeconds > 0)
                line += strCat(format("%.1f×", exact->m.times.globalTerm / grid->m.times.globalTerm),
                               ", ", format("%.1f×", exact->m.totalSeconds / grid->m.totalSeconds));
            else
                line += "–";
            const auto relL1 = [](const BenchRow* r) {
                return r && r->m.image ? std::optional(r->m.image->relL1) : std::nullopt;
            };
            line += strCat(" | ", mdOptional(relL1(grid), 4), " | ",
                           mdOptional(grid && grid->m.probe ? std::optional(grid->m.probe->maeV)
                                                            : std::nullopt,
                                      4),
                           " | ",
                           mdOptional(grid && grid->m.probe ? std::optional(grid->m.probe->maeT_s)
                                                            : std::nullopt,
                                      4),
                           " | ");
            // Approx at the grid's time budget: the most accurate approx
            // configuration no slower than grid x1 (else the fastest one).
            const BenchRow* approx = nullptr;
            bool withinBudget = false;
            for (const BenchRow& r : rows) {
                if (r.scene != s || !accuracy(r) || r.config.mode != GlobalTermMode::Approx ||
                    !r.m.image)
                    continue;
                const bool within = grid && r.m.totalSeconds <= grid->m.totalSeconds;
                if (within && (!withinBudget || r.m.image->relL1 < approx->m.image->relL1)) {
                    approx = &r;
                    withinBudget = true;
                } else if (!withinBudget &&
                           (!approx || r.m.totalSeconds < approx->m.totalSeconds)) {
                    approx = &r;
                }
            }
            line += approx ? strCat(approx->config.label(), " (", seconds(approx->m.totalSeconds),
                                    " s", withinBudget ? "" : ", none was as fast", ")")
                           : std::string("–");
            // The reference's own noise, from the error of exact K=a against it:
            // with independent rays, variance ∝ 1/K, so err² ≈ σ²(1/a + 1/K_ref)
            // and the reference's share is err·sqrt(a / (a + K_ref)).
            const std::optional<double> noise =
                relL1(exact) ? std::optional(*relL1(exact) *
                                             std::sqrt(double(fewestRays) /
                                                       double(fewestRays + o.referenceRays)))
                             : std::nullopt;
            line += strCat(" | ", mdOptional(relL1(approx), 4), " | ", mdOptional(noise, 4), " |\n");
            md += line;
        }
        md += "\n";
    }

    for (const std::string& s : scenes) {
        const BenchRow* ref = findRow(rows, s, [](const BenchRow& r) {
            return r.kind == BenchSweepKind::Reference;
        });
        md += strCat("## ", s, "\n\n");
        if (ref)
            md += strCat(thousands(ref->m.segments), " segments, ", imageSize(*ref),
                         ", h0 = ", format("%.4g", ref->m.defaultVoxelSize), "\n\n");
        md += strCat("| configuration | voxel or radius | shading ", stageHeader(),
                     " rel L1 | rel RMSE | MAE(V) | MAE(T_s) |\n");
        md += "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
        for (const BenchRow& r : rows) {
            if (r.scene != s ||
                (r.kind != BenchSweepKind::Reference && r.kind != BenchSweepKind::Accuracy))
                continue;
            const BenchMeasurement& m = r.m;
            md += strCat("| ", configText(r), " | ", format("%.3g", m.voxelSize), " | ",
                         toString(r.config.shadingRate), " |", stageCells(m), " ",
                         mdOptional(m.image ? std::optional(m.image->relL1) : std::nullopt, 4),
                         " | ",
                         mdOptional(m.image ? std::optional(m.image->relRmse) : std::nullopt, 4),
                         " | ",
                         mdOptional(m.probe ? std::optional(m.probe->maeV) : std::nullopt, 4),
                         " | ",
                         mdOptional(m.probe ? std::optional(m.probe->maeT_s) : std::nullopt, 4),
                         " |\n");
        }
        md += "\n";
    }

    for (const ScalingFit& fit : result.fits) {
        const bool segments = fit.kind == BenchSweepKind::Segments;
        md += strCat("## Scaling with ", segments ? "segment count" : "image size",
                     " (grid mode, default voxel size, fragment shading)\n\n");
        md += strCat("| scene | segments | image ", stageHeader(), "\n");
        md += "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
        for (const BenchRow& r : rows)
            if (r.kind == fit.kind)
                md += strCat("| ", r.scene, " | ", thousands(r.m.segments), " | ", imageSize(r), " |",
                             stageCells(r.m), "\n");
        const char* x = segments ? "segments" : "pixels";
        md += strCat("\nGrowth, least-squares fit of cost ∝ ", x, "^k: ",
                     fitText("total time", fit.total), "; ", fitText("voxelize", fit.voxelize), "; ",
                     fitText("global term", fit.globalTerm), "; ",
                     fitText("raster + shade", fit.rasterShade), "; ",
                     fitText("peak memory", fit.peakMemory), ".\n\n");
    }
    return md;
}

std::vector<ScalingFit> fitScaling(const std::vector<BenchRow>& rows) {
    std::vector<ScalingFit> fits;
    for (const BenchSweepKind kind : {BenchSweepKind::Segments, BenchSweepKind::Pixels}) {
        std::vector<double> x, total, voxelize, globalTerm, rasterShade, memX, memory;
        for (const BenchRow& r : rows) {
            if (r.kind != kind)
                continue;
            const double size = kind == BenchSweepKind::Segments
                                    ? double(r.m.segments)
                                    : double(r.width) * double(r.height);
            x.push_back(size);
            total.push_back(r.m.totalSeconds);
            voxelize.push_back(r.m.times.voxelize);
            globalTerm.push_back(r.m.times.globalTerm);
            rasterShade.push_back(r.m.times.raster + r.m.times.shade);
            if (r.m.peakMiB) {
                memX.push_back(size);
                memory.push_back(*r.m.peakMiB);
            }
        }
        if (x.empty())
            continue;
        ScalingFit fit;
        fit.kind = kind;
        fit.total = fitPowerLaw(x, total);
        fit.voxelize = fitPowerLaw(x, voxelize);
        fit.globalTerm = fitPowerLaw(x, globalTerm);
        fit.rasterShade = fitPowerLaw(x, rasterShade);
        fit.peakMemory = fitPowerLaw(memX, memory);
        fits.push_back(fit);
    }
    return fits;
}

// --- Plots: a small rasterizer with a built-in 5×7 bitmap font ----------------

struct Color8 {
    std::uint8_t r, g, b;
};

constexpr Color8 kWhite{255, 255, 255}, kBlack{30, 30, 30}, kGray{110, 110, 110},
    kGridGray{226, 226, 226};
constexpr Color8 kPalette[] = {{31, 119, 180}, {214, 39, 40},  {44, 160, 44},  {148, 103, 189},
                               {255, 127, 14}, {140, 86, 75},  {227, 119, 194}, {23, 190, 207}};

/// A 5×7 font with descenders (the classic LCD glyphs; g, j, p, q, y, comma and
/// semicolon reach an eighth row), ASCII 32–126: five columns per glyph, bit 0 at the top.
constexpr std::uint8_t kFont5x7[95][5] = {
    {0x00, 0x00, 0x00, 0x00, 0x00}, {0x00, 0x00, 0x5F, 0x00, 0x00}, {0x00, 0x07, 0x00, 0x07, 0x00},
    {0x14, 0x7F, 0x14, 0x7F, 0x14}, {0x24, 0x2A, 0x7F, 0x2A, 0x12}, {0x23, 0x13, 0x08, 0x64, 0x62},
    {0x36, 0x49, 0x55, 0x22, 0x50}, {0x00, 0x05, 0x03, 0x00, 0x00}, {0x00, 0x1C, 0x22, 0x41, 0x00},
    {0x00, 0x41, 0x22, 0x1C, 0x00}, {0x14, 0x08, 0x3E, 0x08, 0x14}, {0x08, 0x08, 0x3E, 0x08, 0x08},
    {0x00, 0xA0, 0x60, 0x00, 0x00}, {0x08, 0x08, 0x08, 0x08, 0x08}, {0x00, 0x60, 0x60, 0x00, 0x00},
    {0x20, 0x10, 0x08, 0x04, 0x02}, {0x3E, 0x51, 0x49, 0x45, 0x3E}, {0x00, 0x42, 0x7F, 0x40, 0x00},
    {0x42, 0x61, 0x51, 0x49, 0x46}, {0x21, 0x41, 0x45, 0x4B, 0x31}, {0x18, 0x14, 0x12, 0x7F, 0x10},
    {0x27, 0x45, 0x45, 0x45, 0x39}, {0x3C, 0x4A, 0x49, 0x49, 0x30}, {0x01, 0x71, 0x09, 0x05, 0x03},
    {0x36, 0x49, 0x49, 0x49, 0x36}, {0x06, 0x49, 0x49, 0x29, 0x1E}, {0x00, 0x36, 0x36, 0x00, 0x00},
    {0x00, 0xB6, 0x76, 0x00, 0x00}, {0x08, 0x14, 0x22, 0x41, 0x00}, {0x14, 0x14, 0x14, 0x14, 0x14},
    {0x00, 0x41, 0x22, 0x14, 0x08}, {0x02, 0x01, 0x51, 0x09, 0x06}, {0x32, 0x49, 0x79, 0x41, 0x3E},
    {0x7E, 0x11, 0x11, 0x11, 0x7E}, {0x7F, 0x49, 0x49, 0x49, 0x36}, {0x3E, 0x41, 0x41, 0x41, 0x22},
    {0x7F, 0x41, 0x41, 0x22, 0x1C}, {0x7F, 0x49, 0x49, 0x49, 0x41}, {0x7F, 0x09, 0x09, 0x09, 0x01},
    {0x3E, 0x41, 0x49, 0x49, 0x7A}, {0x7F, 0x08, 0x08, 0x08, 0x7F}, {0x00, 0x41, 0x7F, 0x41, 0x00},
    {0x20, 0x40, 0x41, 0x3F, 0x01}, {0x7F, 0x08, 0x14, 0x22, 0x41}, {0x7F, 0x40, 0x40, 0x40, 0x40},
    {0x7F, 0x02, 0x0C, 0x02, 0x7F}, {0x7F, 0x04, 0x08, 0x10, 0x7F}, {0x3E, 0x41, 0x41, 0x41, 0x3E},
    {0x7F, 0x09, 0x09, 0x09, 0x06}, {0x3E, 0x41, 0x51, 0x21, 0x5E}, {0x7F, 0x09, 0x19, 0x29, 0x46},
    {0x46, 0x49, 0x49, 0x49, 0x31}, {0x01, 0x01, 0x7F, 0x01, 0x01}, {0x3F, 0x40, 0x40, 0x40, 0x3F},
    {0x1F, 0x20, 0x40, 0x20, 0x1F}, {0x3F, 0x40, 0x38, 0x40, 0x3F}, {0x63, 0x14, 0x08, 0x14, 0x63},
    {0x07, 0x08, 0x70, 0x08, 0x07}, {0x61, 0x51, 0x49, 0x45, 0x43}, {0x00, 0x7F, 0x41, 0x41, 0x00},
    {0x02, 0x04, 0x08, 0x10, 0x20}, {0x00, 0x41, 0x41, 0x7F, 0x00}, {0x04, 0x02, 0x01, 0x02, 0x04},
    {0x40, 0x40, 0x40, 0x40, 0x40}, {0x00, 0x01, 0x02, 0x04, 0x00}, {0x20, 0x54, 0x54, 0x54, 0x78},
    {0x7F, 0x48, 0x44, 0x44, 0x38}, {0x38, 0x44, 0x44, 0x44, 0x20}, {0x38, 0x44, 0x44, 0x48, 0x7F},
    {0x38, 0x54, 0x54, 0x54, 0x18}, {0x08, 0x7E, 0x09, 0x01, 0x02}, {0x18, 0xA4, 0xA4, 0xA4, 0x7C},
    {0x7F, 0x08, 0x04, 0x04, 0x78}, {0x00, 0x44, 0x7D, 0x40, 0x00}, {0x40, 0x80, 0x80, 0x7D, 0x00},
    {0x7F, 0x10, 0x28, 0x44, 0x00}, {0x00, 0x41, 0x7F, 0x40, 0x00}, {0x7C, 0x04, 0x18, 0x04, 0x78},
    {0x7C, 0x08, 0x04, 0x04, 0x78}, {0x38, 0x44, 0x44, 0x44, 0x38}, {0xFC, 0x24, 0x24, 0x24, 0x18},
    {0x18, 0x24, 0x24, 0x24, 0xFC}, {0x7C, 0x08, 0x04, 0x04, 0x08}, {0x48, 0x54, 0x54, 0x54, 0x20},
    {0x04, 0x3F, 0x44, 0x40, 0x20}, {0x3C, 0x40, 0x40, 0x20, 0x7C}, {0x1C, 0x20, 0x40, 0x20, 0x1C},
    {0x3C, 0x40, 0x30, 0x40, 0x3C}, {0x44, 0x28, 0x10, 0x28, 0x44}, {0x1C, 0xA0, 0xA0, 0xA0, 0x7C},
    {0x44, 0x64, 0x54, 0x4C, 0x44}, {0x00, 0x08, 0x36, 0x41, 0x00}, {0x00, 0x00, 0x7F, 0x00, 0x00},
    {0x00, 0x41, 0x36, 0x08, 0x00}, {0x08, 0x04, 0x08, 0x10, 0x08}};

/// An RGB image drawn in output-pixel coordinates (floats, y down) and
/// supersampled kSuper² times per pixel, then box-filtered: anti-aliased
/// lines and markers without a graphics library.
class Canvas {
public:
    static constexpr int kSuper = 3;

    Canvas(int width, int height)
        : width_(width), height_(height),
          pixels_(std::size_t(width * kSuper) * std::size_t(height * kSuper), kWhite) {}

    int width() const { return width_; }
    int height() const { return height_; }

    /// Paints every sample whose centre satisfies inside(x, y) within the box.
    template <typename Inside>
    void paint(float x0, float y0, float x1, float y1, Color8 c, const Inside& inside) {
        const int W = width_ * kSuper, H = height_ * kSuper;
        const float s = float(kSuper);
        const int i0 = std::max(0, int(std::floor(x0 * s))), i1 = std::min(W - 1, int(std::ceil(x1 * s)));
        const int j0 = std::max(0, int(std::floor(y0 * s))), j1 = std::min(H - 1, int(std::ceil(y1 * s)));
        for (int j = j0; j <= j1; ++j)
            for (int i = i0; i <= i1; ++i)
                if (inside((float(i) + 0.5f) / s, (float(j) + 0.5f) / s))
                    pixels_[std::size_t(j) * std::size_t(W) + std::size_t(i)] = c;
    }

    void rect(float x0, float y0, float x1, float y1, Color8 c) {
        paint(x0, y0, x1, y1, c, [&](float x, float y) { return x >= x0 && x < x1 && y >= y0 && y < y1; });
    }

    void line(float ax, float ay, float bx, float by, float width, Color8 c) {
        const float r = 0.5f * width;
        const float dx = bx - ax, dy = by - ay, len2 = dx * dx + dy * dy;
        paint(std::min(ax, bx) - r, std::min(ay, by) - r, std::max(ax, bx) + r, std::max(ay, by) + r, c,
              [&](float x, float y) {
                  const float t = len2 > 0 ? std::clamp(((x - ax) * dx + (y - ay) * dy) / len2, 0.0f, 1.0f) : 0.0f;
                  const float ex = x - (ax + t * dx), ey = y - (ay + t * dy);
                  return ex * ex + ey * ey <= r * r;
              });
    }

    void disc(float cx, float cy, float radius, Color8 c) {
        paint(cx - radius, cy - radius, cx + radius, cy + radius, c, [&](float x, float y) {
            return (x - cx) * (x - cx) + (y - cy) * (y - cy) <= radius * radius;
        });
    }

    void ring(float cx, float cy, float radius, float width, Color8 c) {
        const float outer = radius + 0.5f * width, inner = radius - 0.5f * width;
        paint(cx - outer, cy - outer, cx + outer, cy + outer, c, [&](float x, float y) {
            const float d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
            return d2 <= outer * outer && d2 >= inner * inner;
        });
    }

    /// A filled triangle (any winding).
    void triangle(const float (&p)[3][2], Color8 c) {
        const auto edge = [](const float* a, const float* b, float x, float y) {
            return (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
        };
        paint(std::min({p[0][0], p[1][0], p[2][0]}), std::min({p[0][1], p[1][1], p[2][1]}),
              std::max({p[0][0], p[1][0], p[2][0]}), std::max({p[0][1], p[1][1], p[2][1]}), c,
              [&](float x, float y) {
                  const float e0 = edge(p[0], p[1], x, y), e1 = edge(p[1], p[2], x, y),
                              e2 = edge(p[2], p[0], x, y);
                  return (e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0);
              });
    }

    static float textWidth(std::string_view text, float scale) {
        return text.empty() ? 0.0f : (6.0f * float(text.size()) - 1.0f) * scale;
    }

    /// Text with its top-left corner at (x, y); a font pixel is `scale` output pixels.
    void text(float x, float y, std::string_view text, float scale, Color8 c) {
        for (const char ch : text) {
            const int code = static_cast<unsigned char>(ch);
            const std::uint8_t* glyph = kFont5x7[code >= 32 && code <= 126 ? code - 32 : '?' - 32];
            for (int col = 0; col < 5; ++col)
                for (int row = 0; row < 8; ++row)
                    if ((glyph[col] >> row) & 1)
                        rect(x + float(col) * scale, y + float(row) * scale,
                             x + float(col + 1) * scale, y + float(row + 1) * scale, c);
            x += 6.0f * scale;
        }
    }

    /// The box-filtered 8-bit RGB image, row-major.
    std::vector<std::uint8_t> resolve() const {
        std::vector<std::uint8_t> out(std::size_t(width_) * std::size_t(height_) * 3);
        const std::size_t W = std::size_t(width_ * kSuper);
        for (int y = 0; y < height_; ++y)
            for (int x = 0; x < width_; ++x) {
                int sum[3] = {0, 0, 0};
                for (int j = 0; j < kSuper; ++j)
                    for (int i = 0; i < kSuper; ++i) {
                        const Color8& c = pixels_[std::size_t(y * kSuper + j) * W + std::size_t(x * kSuper + i)];
                        sum[0] += c.r;
                        sum[1] += c.g;
                        sum[2] += c.b;
                    }
                for (int ch = 0; ch < 3; ++ch)
                    out[(std::size_t(y) * std::size_t(width_) + std::size_t(x)) * 3 + std::size_t(ch)] =
                        static_cast<std::uint8_t>((sum[ch] + kSuper * kSuper / 2) / (kSuper * kSuper));
            }
        return out;
    }

private:
    int width_, height_;
    std::vector<Color8> pixels_;
};

void writeCanvasPng(const std::filesystem::path& path, const Canvas& canvas) {
    const std::vector<std::uint8_t> pixels = canvas.resolve();
    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        png_image image{};
        image.version = PNG_IMAGE_VERSION;
        image.width = static_cast<png_uint_32>(canvas.width());
        image.height = static_cast<png_uint_32>(canvas.height());
        image.format = PNG_FORMAT_RGB;
        if (!png_image_write_to_file(&image, tmp.c_str(), 0, pixels.data(), 0, nullptr)) {
            const std::string message = image.message;
            png_image_free(&image);
            throw InputError(strCat(path.string(), ": cannot write PNG file: ", message));
        }
    });
}

enum class Marker { Circle, Square, Triangle };

void drawMarker(Canvas& c, Marker m, float x, float y, Color8 color, bool filled) {
    const float r = 4.5f, w = 1.6f;
    switch (m) {
    case Marker::Circle:
        filled ? c.disc(x, y, r, color) : c.ring(x, y, r - 0.5f * w, w, color);
        break;
    case Marker::Square: {
        const float h = r * 0.85f;
        if (filled) {
            c.rect(x - h, y - h, x + h, y + h, color);
        } else {
            c.rect(x - h, y - h, x + h, y - h + w, color);
            c.rect(x - h, y + h - w, x + h, y + h, color);
            c.rect(x - h, y - h, x - h + w, y + h, color);
            c.rect(x + h - w, y - h, x + h, y + h, color);
        }
        break;
    }
    case Marker::Triangle: {
        const float p[3][2] = {{x, y - 1.15f * r}, {x - r, y + 0.75f * r}, {x + r, y + 0.75f * r}};
        if (filled) {
            c.triangle(p, color);
        } else {
            for (int i = 0; i < 3; ++i)
                c.line(p[i][0], p[i][1], p[(i + 1) % 3][0], p[(i + 1) % 3][1], w, color);
        }
        break;
    }
    }
}

struct PlotPoint {
    double x = 0, y = 0;
    std::string label;
    Marker marker = Marker::Circle;
    bool filled = true;
};

struct PlotSeries {
    std::string name;
    Color8 color{};
    std::vector<PlotPoint> points;
    std::vector<std::pair<double, double>> curve; ///< a polyline in data coordinates
};

struct PlotSpec {
    std::string title, xLabel, yLabel;
    std::vector<PlotSeries> series;
    std::vector<std::string> notes; ///< legend lines below the series names
};

/// log10 axis over [lo, hi] (log10 units) mapped to pixels [p0, p1].
struct LogAxis {
    double lo = 0, hi = 1;
    float p0 = 0, p1 = 1;
    float map(double v) const {
        return p0 + float((std::log10(v) - lo) / (hi - lo)) * (p1 - p0);
    }
};

LogAxis fitAxis(const std::vector<double>& values, float p0, float p1) {
    double lo = 1e300, hi = -1e300;
    for (const double v : values)
        if (v > 0 && std::isfinite(v)) {
            lo = std::min(lo, std::log10(v));
            hi = std::max(hi, std::log10(v));
        }
    if (lo > hi) {
        lo = 0;
        hi = 1;
    }
    // At least a factor ~3 of range, plus a margin so that markers stay inside.
    const double span = std::max(hi - lo, 0.5);
    const double mid = 0.5 * (lo + hi);
    lo = mid - 0.5 * span - 0.08 * span;
    hi = mid + 0.5 * span + 0.08 * span;
    return {lo, hi, p0, p1};
}

std::string tickText(double v) {
    if (v >= 1e5 || v < 1e-3) {
        const int e = int(std::floor(std::log10(v) + 1e-9));
        const double mantissa = v / std::pow(10.0, e);
        return std::abs(mantissa - 1.0) < 1e-9 ? strCat("1e", e) : strCat(format("%g", mantissa), "e", e);
    }
    return format("%g", v);
}

/// Tick values of a log axis: every integer mantissa within a decade, 1, 2, 5
/// per decade over a few, powers of ten beyond.
std::vector<double> ticks(const LogAxis& a) {
    const double span = a.hi - a.lo;
    const std::vector<double> mantissas = span <= 1.2   ? std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8, 9}
                                          : span <= 3.0 ? std::vector<double>{1, 2, 5}
                                                        : std::vector<double>{1};
    std::vector<double> out;
    for (int d = int(std::floor(a.lo)); d <= int(std::ceil(a.hi)); ++d)
        for (const double m : mantissas) {
            const double v = m * std::pow(10.0, d);
            if (std::log10(v) >= a.lo && std::log10(v) <= a.hi)
                out.push_back(v);
        }
    return out;
}

/// One log-log panel in the box (x0, y0)–(x1, y1) of the canvas, legend on its right.
void drawPlot(Canvas& c, float x0, float y0, float x1, float y1, const PlotSpec& spec) {
    const float legendWidth = 300;
    const float left = x0 + 78, right = x1 - legendWidth, top = y0 + 58, bottom = y1 - 62;
    std::vector<double> xs, ys;
    for (const PlotSeries& s : spec.series) {
        for (const PlotPoint& p : s.points) {
            xs.push_back(p.x);
            ys.push_back(p.y);
        }
        for (const auto& [x, y] : s.curve) {
            xs.push_back(x);
            ys.push_back(y);
        }
    }
    const LogAxis ax = fitAxis(xs, left, right), ay = fitAxis(ys, bottom, top);

    c.text(left, y0 + 14, spec.title, 2, kBlack);
    c.text(left - 60, top - 22, spec.yLabel, 1.5f, kBlack);
    c.text(0.5f * (left + right) - 0.5f * Canvas::textWidth(spec.xLabel, 1.5f), bottom + 36,
           spec.xLabel, 1.5f, kBlack);
    for (const double t : ticks(ax)) {
        const float x = ax.map(t);
        c.line(x, top, x, bottom, 1, kGridGray);
        c.line(x, bottom, x, bottom + 5, 1.2f, kGray);
        const std::string s = tickText(t);
        c.text(x - 0.5f * Canvas::textWidth(s, 1.5f), bottom + 10, s, 1.5f, kGray);
    }
    for (const double t : ticks(ay)) {
        const float y = ay.map(t);
        c.line(left, y, right, y, 1, kGridGray);
        c.line(left - 5, y, left, y, 1.2f, kGray);
        const std::string s = tickText(t);
        c.text(left - 9 - Canvas::textWidth(s, 1.5f), y - 5, s, 1.5f, kGray);
    }
    c.line(left, bottom, right, bottom, 1.5f, kBlack);
    c.line(left, top, left, bottom, 1.5f, kBlack);

    for (const PlotSeries& s : spec.series) {
        for (std::size_t i = 1; i < s.curve.size(); ++i)
            c.line(ax.map(s.curve[i - 1].first), ay.map(s.curve[i - 1].second),
                   ax.map(s.curve[i].first), ay.map(s.curve[i].second), 2, s.color);
        for (const PlotPoint& p : s.points) {
            if (!(p.x > 0) || !(p.y > 0))
                continue;
            const float x = ax.map(p.x), y = ay.map(p.y);
            drawMarker(c, p.marker, x, y, s.color, p.filled);
            c.text(x + 7, y - 10, p.label, 1, s.color);
        }
    }

    float ly = top + 4;
    for (const PlotSeries& s : spec.series) {
        c.rect(right + 20, ly + 1, right + 34, ly + 11, s.color);
        c.text(right + 42, ly, s.name, 1.5f, kBlack);
        ly += 20;
    }
    ly += 10;
    for (const std::string& note : spec.notes) {
        c.text(right + 20, ly, note, 1, kGray);
        ly += 13;
    }
}

Marker markerOf(GlobalTermMode mode) {
    switch (mode) {
    case GlobalTermMode::Exact:
        return Marker::Circle;
    case GlobalTermMode::Grid:
        return Marker::Square;
    case GlobalTermMode::Approx:
        return Marker::Triangle;
    }
    return Marker::Circle;
}

std::string shortLabel(const BenchConfig& c) {
    if (c.mode == GlobalTermMode::Exact)
        return strCat("e", c.rays);
    return strCat(c.mode == GlobalTermMode::Grid ? "g" : "a", scaleText(c.voxelScale));
}

/// The points no other point beats in both time and error, by increasing time.
std::vector<std::pair<double, double>> paretoFront(std::vector<std::pair<double, double>> pts) {
    std::sort(pts.begin(), pts.end());
    std::vector<std::pair<double, double>> front;
    for (const auto& p : pts)
        if (front.empty() || p.second < front.back().second)
            front.push_back(p);
    return front;
}

bool plotRuntimeVsError(const std::filesystem::path& path, const std::vector<BenchRow>& rows,
                        std::uint32_t referenceRays, int runs) {
    PlotSpec spec;
    spec.title = "hairvox: run time against image error";
    spec.xLabel = strCat("end-to-end time, s (median of ", runs, ")");
    spec.yLabel = strCat("rel. L1 error vs exact K=", referenceRays);
    std::size_t colour = 0;
    for (const std::string& scene : sceneOrder(rows, BenchSweepKind::Accuracy)) {
        PlotSeries s;
        s.name = scene;
        s.color = kPalette[colour++ % std::size(kPalette)];
        std::vector<std::pair<double, double>> pts;
        for (const BenchRow& r : rows) {
            if (r.scene != scene || r.kind != BenchSweepKind::Accuracy || !r.m.image ||
                !(r.m.image->relL1 > 0))
                continue;
            s.points.push_back({r.m.totalSeconds, r.m.image->relL1, shortLabel(r.config),
                                markerOf(r.config.mode),
                                r.config.shadingRate == ShadingRate::Fragment});
            pts.emplace_back(r.m.totalSeconds, r.m.image->relL1);
        }
        s.curve = paretoFront(pts);
        if (!s.points.empty())
            spec.series.push_back(std::move(s));
    }
    if (spec.series.empty())
        return false;
    spec.notes = {"line: Pareto front of the scene",
                  "circle  eK: exact, K rays",
                  "square  gS: grid, voxel S x h0",
                  "triangle aS: approx, voxel S x h0",
                  "filled: fragment shading",
                  "hollow: vertex shading",
                  "h0: default voxel size"};
    Canvas canvas(1400, 820);
    drawPlot(canvas, 0, 0, 1400, 820, spec);
    writeCanvasPng(path, canvas);
    return true;
}

bool plotScaling(const std::filesystem::path& path, const std::vector<BenchRow>& rows,
                 const std::vector<ScalingFit>& fits) {
    if (fits.empty())
        return false;
    const float panelWidth = 820;
    Canvas canvas(int(panelWidth) * int(fits.size()), 620);
    float x0 = 0;
    for (const ScalingFit& fit : fits) {
        const bool segments = fit.kind == BenchSweepKind::Segments;
        PlotSpec spec;
        spec.title = segments ? "time against segment count" : "time against image size";
        spec.xLabel = segments ? "segments" : "pixels";
        spec.yLabel = "seconds";
        struct Stage {
            const char* name;
            std::function<double(const BenchMeasurement&)> value;
            const std::optional<PowerLawFit>& fit;
        };
        const Stage stages[] = {
            {"total", [](const BenchMeasurement& m) { return m.totalSeconds; }, fit.total},
            {"voxelize", [](const BenchMeasurement& m) { return m.times.voxelize; }, fit.voxelize},
            {"global term", [](const BenchMeasurement& m) { return m.times.globalTerm; }, fit.globalTerm},
            {"raster+shade", [](const BenchMeasurement& m) { return m.times.raster + m.times.shade; },
             fit.rasterShade}};
        std::size_t colour = 0;
        for (const Stage& stage : stages) {
            PlotSeries s;
            s.color = kPalette[colour++];
            double xMin = 1e300, xMax = 0;
            for (const BenchRow& r : rows) {
                if (r.kind != fit.kind)
                    continue;
                const double x = segments ? double(r.m.segments) : double(r.width) * double(r.height);
                s.points.push_back({x, stage.value(r.m), "", Marker::Circle, true});
                xMin = std::min(xMin, x);
                xMax = std::max(xMax, x);
            }
            s.name = stage.fit ? strCat(stage.name, " k=", format("%.2f", stage.fit->exponent))
                               : std::string(stage.name);
            if (stage.fit)
                for (const double x : {xMin, xMax})
                    s.curve.emplace_back(x, stage.fit->coefficient * std::pow(x, stage.fit->exponent));
            spec.series.push_back(std::move(s));
        }
        spec.notes = {"lines: least-squares fits", "cost = c * size^k"};
        drawPlot(canvas, x0, 0, x0 + panelWidth, 620, spec);
        x0 += panelWidth;
    }
    writeCanvasPng(path, canvas);
    return true;
}

std::vector<std::filesystem::path> writeSweepOutputs(const SweepOptions& o, SweepResult& result,
                                                     const RunInfo& info) {
    result.fits = fitScaling(result.rows);
    std::vector<std::filesystem::path> written;
    const auto writeText = [&](const std::filesystem::path& path, const std::string& text) {
        writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
            std::ofstream out(tmp, std::ios::trunc);
            out << text;
            if (!out)
                throw InputError(strCat(path.string(), ": cannot write"));
        });
        written.push_back(path);
    };
    writeText(o.outDir / "results.csv", csvText(result.rows));
    writeText(o.outDir / "results.md", markdownText(o, result, info));
    if (plotRuntimeVsError(o.outDir / "runtime_vs_error.png", result.rows, o.referenceRays, o.runs))
        written.push_back(o.outDir / "runtime_vs_error.png");
    if (plotScaling(o.outDir / "scaling.png", result.rows, result.fits))
        written.push_back(o.outDir / "scaling.png");
    return written;
}

/// The output directory's working files, removed however the sweep ends.
class WorkDir {
public:
    explicit WorkDir(std::filesystem::path path) : path_(std::move(path)) {
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

} // namespace

// --- Public API -------------------------------------------------------------------

Scene BenchScene::build() const {
    if (style && !file.empty())
        throw InputError(strCat(label, ": a groom style swap applies to the default scene only"));
    Scene scene = file.empty() ? defaultScene() : loadScene(file);
    if (style) {
        scene.groom.procedural.style = *style;
        scene.groom.procedural.pointsPerStrand = pointsPerStrand;
    }
    if ((strands > 0 || pointsPerStrand > 0) && !scene.groom.isProcedural())
        throw InputError(strCat(label, ": strand and point counts apply to procedural grooms only"));
    if (strands > 0)
        scene.groom.procedural.strands = strands;
    if (pointsPerStrand > 0)
        scene.groom.procedural.pointsPerStrand = pointsPerStrand;
    if (width > 0)
        scene.camera.width = width;
    if (height > 0)
        scene.camera.height = height;
    scene.name = label;
    scene.output.exr.clear();
    scene.output.png.clear();
    scene.validate();
    return scene;
}

std::string BenchConfig::label() const {
    if (mode == GlobalTermMode::Exact)
        return strCat("exact K=", rays);
    return strCat(toString(mode), " x", scaleText(voxelScale));
}

BeautyImage BeautyImage::fromFilm(const Film& film) {
    BeautyImage image;
    image.width = film.width;
    image.height = film.height;
    image.beauty.resize(film.pixelCount());
    for (std::size_t p = 0; p < film.pixelCount(); ++p)
        image.beauty[p] = film.beauty(p);
    image.hairAlpha = film.hairAlpha;
    return image;
}

std::optional<ImageError> compareImages(const BeautyImage& estimate, const BeautyImage& reference) {
    const std::size_t n = std::size_t(reference.width) * std::size_t(reference.height);
    if (estimate.width != reference.width || estimate.height != reference.height ||
        estimate.beauty.size() != n || reference.beauty.size() != n ||
        reference.hairAlpha.size() != n)
        throw InputError(strCat("images differ in size: ", estimate.width, "x", estimate.height,
                                " against a ", reference.width, "x", reference.height,
                                " reference"));
    double sumAbs = 0, sumSquares = 0, sumReference = 0;
    std::size_t hairPixels = 0;
    for (std::size_t p = 0; p < n; ++p) {
        if (!(reference.hairAlpha[p] > 0))
            continue;
        ++hairPixels;
        for (int c = 0; c < 3; ++c) {
            const double d = double(estimate.beauty[p][c]) - double(reference.beauty[p][c]);
            sumAbs += std::abs(d);
            sumSquares += d * d;
            sumReference += std::abs(double(reference.beauty[p][c]));
        }
    }
    if (hairPixels == 0 || !(sumReference > 0))
        return std::nullopt;
    const double values = 3.0 * double(hairPixels);
    ImageError e;
    e.hairPixels = hairPixels;
    e.relL1 = sumAbs / sumReference;
    e.relRmse = std::sqrt(sumSquares / values) / (sumReference / values);
    return e;
}

std::optional<PowerLawFit> fitPowerLaw(std::span<const double> x, std::span<const double> y) {
    if (x.size() != y.size())
        throw InputError(strCat("fitPowerLaw: ", x.size(), " x values but ", y.size(), " y values"));
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

const char* toString(BenchSweepKind kind) {
    switch (kind) {
    case BenchSweepKind::Reference:
        return "reference";
    case BenchSweepKind::Accuracy:
        return "accuracy";
    case BenchSweepKind::Segments:
        return "segments";
    case BenchSweepKind::Pixels:
        return "pixels";
    }
    return "?";
}

SweepOptions SweepOptions::full(const std::filesystem::path& ratboyScene) {
    SweepOptions o;
    const auto style = [](const char* label, GroomStyle s) {
        BenchScene b;
        b.label = label;
        b.style = s;
        return b;
    };
    BenchScene wavy;
    wavy.label = "wavy (default scene)";
    BenchScene ratboy;
    ratboy.label = "Ratboy mohawk";
    ratboy.file = ratboyScene;
    BenchScene head;
    head.label = "wavy head 1.4M";
    head.strands = 50000;
    head.pointsPerStrand = 29;
    head.width = 1920;
    head.height = 1080;
    o.scenes = {style("straight", GroomStyle::Straight), wavy, style("curly", GroomStyle::Curly),
                ratboy, head};
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
        s.label = strCat("default scene ", size, "^2");
        s.width = s.height = size;
        o.pixelScaling.push_back(s);
    }
    return o;
}

SweepOptions SweepOptions::quick() {
    SweepOptions o;
    BenchScene wavy;
    wavy.label = "wavy (default scene) 512^2";
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
        s.strands = strands;
        s.pointsPerStrand = 29;
        s.width = 960;
        s.height = 540;
        o.segmentScaling.push_back(s);
    }
    for (const std::uint32_t size : {256u, 512u, 1024u}) {
        BenchScene s;
        s.label = strCat("default scene ", size, "^2");
        s.width = s.height = size;
        o.pixelScaling.push_back(s);
    }
    return o;
}

void SweepOptions::validate() const {
    if (scenes.empty() && segmentScaling.empty() && pixelScaling.empty())
        throw InputError("bench: nothing to measure (no scenes and no scaling sweep)");
    std::set<std::string> labels;
    for (const auto* list : {&scenes, &segmentScaling, &pixelScaling})
        for (const BenchScene& s : *list) {
            if (!s.file.empty() && !std::filesystem::exists(s.file))
                throw InputError(strCat(s.file.string(), ": no such scene file (the default sweep "
                                        "reads data/scenes/ under the working directory: run it "
                                        "from the repository root, or pass --scene)"));
            if (!labels.insert(s.label).second)
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
    for (const auto* list : {&o.scenes, &o.segmentScaling, &o.pixelScaling})
        for (const BenchScene& s : *list)
            s.build(); // every scene is valid before hours of work start
    std::filesystem::create_directories(o.outDir);
    const WorkDir work(o.outDir / ".work");
    RunInfo info;
    info.started = utcNow();
    info.cpu = cpuModel();
    info.cores = std::thread::hardware_concurrency();
    info.loadStart = info.loadMax = loadAverage();

    std::vector<double> probeScales = o.voxelScales;
    if (std::find(probeScales.begin(), probeScales.end(), 1.0) == probeScales.end())
        probeScales.push_back(1.0); // the exact configurations' footprint
    const std::size_t perScene =
        1 + o.shadingRates.size() * (o.exactRays.size() + 2 * o.voxelScales.size());
    const std::size_t jobCount =
        o.scenes.size() * perScene + o.segmentScaling.size() + o.pixelScaling.size();
    std::size_t jobIndex = 0;
    const auto start = Clock::now();

    SweepResult result;
    const auto run = [&](BenchJob job, BenchSweepKind kind) {
        throwIfInterrupted();
        const double load = loadAverage();
        info.loadMax = std::max(info.loadMax, load);
        job.runs = kind == BenchSweepKind::Reference ? 1 : o.runs;
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
        row.config = job.config;
        const Scene scene = job.scene.build();
        row.width = scene.camera.width;
        row.height = scene.camera.height;
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
            if (row.m.image)
                line += strCat(", rel L1 ", format("%.4f", row.m.image->relL1));
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
                    const auto at = std::find(probeScales.begin(), probeScales.end(), base.voxelScale);
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
        result.written = writeSweepOutputs(o, result, info);
    }

    for (const auto& [list, kind] : {std::pair{&o.segmentScaling, BenchSweepKind::Segments},
                                     std::pair{&o.pixelScaling, BenchSweepKind::Pixels}})
        for (const BenchScene& scene : *list) {
            BenchJob job;
            job.scene = scene;
            job.config = {GlobalTermMode::Grid, 1.0, 1, ShadingRate::Fragment};
            run(job, kind);
        }
    info.loadEnd = loadAverage();
    info.loadMax = std::max(info.loadMax, info.loadEnd);
    result.written = writeSweepOutputs(o, result, info);
    return result;
}

} // namespace hairvox
