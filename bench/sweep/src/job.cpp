#include "job.h"

#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <spawn.h>
#include <sys/wait.h>

extern char** environ;

namespace hairvox::bench {

using nlohmann::json;

namespace {

// Binary working files (references shared between job processes):
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

constexpr std::size_t kTermFloats = 11; // n, V, P, T_s, σ_f²

json optionalJson(const std::optional<double>& v) {
    return v ? json(*v) : json(nullptr);
}

json sceneToJson(const BenchScene& s) {
    return {{"label", s.label},
            {"file", s.file.string()},
            {"style", s.style ? json(toString(*s.style)) : json(nullptr)},
            {"strands", s.strands},
            {"points_per_strand", s.pointsPerStrand},
            {"width", s.width},
            {"height", s.height},
            {"voxel_size", optionalJson(s.voxelSize)},
            {"eumelanin", s.eumelanin ? json(*s.eumelanin) : json(nullptr)}};
}

BenchScene sceneFromJson(const json& j) {
    BenchScene s;
    s.label = j.at("label").get<std::string>();
    s.file = j.at("file").get<std::string>();
    if (!j.at("style").is_null())
        s.style = kGroomStyleNames.parse(j.at("style").get<std::string>());
    s.strands = j.at("strands").get<std::uint32_t>();
    s.pointsPerStrand = j.at("points_per_strand").get<std::uint32_t>();
    s.width = j.at("width").get<std::uint32_t>();
    s.height = j.at("height").get<std::uint32_t>();
    if (!j.at("voxel_size").is_null())
        s.voxelSize = j.at("voxel_size").get<double>();
    if (!j.at("eumelanin").is_null())
        s.eumelanin = j.at("eumelanin").get<float>();
    return s;
}

std::optional<double> optionalFromJson(const json& j) {
    return j.is_null() ? std::nullopt : std::optional<double>(j.get<double>());
}

} // namespace

void writeComparedImage(const std::filesystem::path& path, const ComparedImage& image) {
    FloatFile file;
    file.header = {std::uint64_t(image.width), std::uint64_t(image.height),
                   image.halfA.empty() ? 0u : 1u};
    file.data.reserve(image.value.size() * 7);
    for (const Rgb& c : image.value)
        file.data.insert(file.data.end(), {c.r, c.g, c.b});
    file.data.insert(file.data.end(), image.mask.begin(), image.mask.end());
    for (const Rgb& c : image.halfA)
        file.data.insert(file.data.end(), {c.r, c.g, c.b});
    writeFloatFile(path, file);
}

ComparedImage readComparedImage(const std::filesystem::path& path) {
    const FloatFile file = readFloatFile(path);
    if (file.header.size() != 3 || file.header[2] > 1 ||
        file.header[0] * file.header[1] * (file.header[2] == 1 ? 7 : 4) != file.data.size())
        throw InputError(strCat(path.string(), ": not a reference image"));
    ComparedImage image;
    image.width = static_cast<int>(file.header[0]);
    image.height = static_cast<int>(file.header[1]);
    const std::size_t n = file.header[0] * file.header[1];
    const float* f = file.data.data();
    image.value.resize(n);
    for (std::size_t p = 0; p < n; ++p, f += 3)
        image.value[p] = Rgb(f[0], f[1], f[2]);
    image.mask.assign(f, f + n);
    f += n;
    if (file.header[2] == 1) {
        image.halfA.resize(n);
        for (std::size_t p = 0; p < n; ++p, f += 3)
            image.halfA[p] = Rgb(f[0], f[1], f[2]);
    }
    return image;
}

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
    if (file.header.size() != 2 ||
        file.header[0] * file.header[1] * kTermFloats != file.data.size())
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

json jobToJson(const BenchJob& job) {
    json probeFiles = json::array();
    for (const auto& p : job.probeFiles)
        probeFiles.push_back(p.string());
    return {{"reference", job.reference},
            {"path_reference", job.pathReference},
            {"spp", job.spp},
            {"time_limit", job.timeLimit},
            {"block", job.block},
            {"scene", sceneToJson(job.scene)},
            {"mode", toString(job.config.mode)},
            {"integrator", toString(job.config.integrator)},
            {"voxel_scale", job.config.voxelScale},
            {"rays", job.config.rays},
            {"shading_rate", toString(job.config.shadingRate)},
            {"paths_per_cell", job.config.pathsPerCell},
            {"config_spp", job.config.spp},
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
    job.pathReference = j.at("path_reference").get<bool>();
    job.spp = j.at("spp").get<std::uint32_t>();
    job.timeLimit = j.at("time_limit").get<double>();
    job.block = j.at("block").get<int>();
    job.scene = sceneFromJson(j.at("scene"));
    job.config.mode = kGlobalTermModeNames.parse(j.at("mode").get<std::string>()).value();
    job.config.integrator = kIntegratorNames.parse(j.at("integrator").get<std::string>()).value();
    job.config.voxelScale = j.at("voxel_scale").get<double>();
    job.config.rays = j.at("rays").get<std::uint32_t>();
    job.config.shadingRate =
        kShadingRateNames.parse(j.at("shading_rate").get<std::string>()).value();
    job.config.pathsPerCell = j.at("paths_per_cell").get<float>();
    job.config.spp = j.at("config_spp").get<std::uint32_t>();
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

json measurementToJson(const BenchMeasurement& m) {
    const StageTimes& t = m.times;
    json j = {{"times",
               {{"load", t.load},
                {"voxelize", t.voxelize},
                {"tables", t.tables},
                {"global_term", t.globalTerm},
                {"raster", t.raster},
                {"shade", t.shade},
                {"trace", t.trace},
                {"write", t.write}}},
              {"total", m.totalSeconds},
              {"prepare", m.prepareSeconds},
              {"runs", m.runs},
              {"peak_mib", optionalJson(m.peakMiB)},
              {"segments", m.segments},
              {"shading_points", m.shadingPoints},
              {"active_voxels", m.activeVoxels},
              {"voxel_size", m.voxelSize},
              {"default_voxel_size", m.defaultVoxelSize},
              {"image", nullptr},
              {"image_blocks", nullptr},
              {"probe", nullptr},
              {"path_trace", nullptr}};
    if (m.pathTrace) {
        const PathTraceStats& s = *m.pathTrace;
        j["path_trace"] = {{"spp", s.spp},
                           {"seconds", s.seconds},
                           {"paths", s.paths},
                           {"rays", s.rays},
                           {"shadow_rays", s.shadowRays},
                           {"deepest_path", s.deepestPath},
                           {"paths_at_depth_cap", s.pathsAtDepthCap},
                           {"energy_at_depth_cap", s.energyAtDepthCap},
                           {"time_limited", s.timeLimited}};
    }
    const auto imageJson = [](const ImageError& e) {
        return json{{"rel_l1", e.relL1},
                    {"rel_rmse", e.relRmse},
                    {"pixels", e.pixels},
                    {"rel_bias", e.relBias},
                    {"noise_floor_l1", e.noiseFloorL1},
                    {"rel_l1_noise_removed", e.relL1NoiseRemoved},
                    {"rel_rmse_noise_removed", e.relRmseNoiseRemoved}};
    };
    if (m.image)
        j["image"] = imageJson(*m.image);
    if (m.imageBlocks)
        j["image_blocks"] = imageJson(*m.imageBlocks);
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
    m.times.trace = t.at("trace").get<double>();
    m.times.write = t.at("write").get<double>();
    m.totalSeconds = j.at("total").get<double>();
    m.prepareSeconds = j.at("prepare").get<double>();
    m.runs = j.at("runs").get<int>();
    m.peakMiB = optionalFromJson(j.at("peak_mib"));
    m.segments = j.at("segments").get<std::uint64_t>();
    m.shadingPoints = j.at("shading_points").get<std::uint64_t>();
    m.activeVoxels = j.at("active_voxels").get<std::uint64_t>();
    m.voxelSize = j.at("voxel_size").get<double>();
    m.defaultVoxelSize = j.at("default_voxel_size").get<double>();
    const auto imageFromJson = [](const json& i) {
        ImageError e;
        e.relL1 = i.at("rel_l1").get<double>();
        e.relRmse = i.at("rel_rmse").get<double>();
        e.relBias = i.at("rel_bias").get<double>();
        e.pixels = i.at("pixels").get<std::size_t>();
        e.noiseFloorL1 = i.at("noise_floor_l1").get<double>();
        e.relL1NoiseRemoved = i.at("rel_l1_noise_removed").get<double>();
        e.relRmseNoiseRemoved = i.at("rel_rmse_noise_removed").get<double>();
        return e;
    };
    if (const json& i = j.at("image"); !i.is_null())
        m.image = imageFromJson(i);
    if (const json& i = j.at("image_blocks"); !i.is_null())
        m.imageBlocks = imageFromJson(i);
    if (const json& p = j.at("probe"); !p.is_null())
        m.probe = ProbeError{p.at("mae_v").get<double>(), p.at("mae_ts").get<double>(),
                             p.at("bias_n").get<double>(), p.at("mean_n_ref").get<double>()};
    if (const json& p = j.at("path_trace"); !p.is_null()) {
        PathTraceStats s;
        s.spp = p.at("spp").get<std::uint32_t>();
        s.seconds = p.at("seconds").get<double>();
        s.paths = p.at("paths").get<std::uint64_t>();
        s.rays = p.at("rays").get<std::uint64_t>();
        s.shadowRays = p.at("shadow_rays").get<std::uint64_t>();
        s.deepestPath = p.at("deepest_path").get<std::uint32_t>();
        s.pathsAtDepthCap = p.at("paths_at_depth_cap").get<std::uint64_t>();
        s.energyAtDepthCap = p.at("energy_at_depth_cap").get<double>();
        s.timeLimited = p.at("time_limited").get<bool>();
        m.pathTrace = s;
    }
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
        throw InputError(
            strCat("cannot start the benchmark worker ", args[0], ": ", std::strerror(rc)));
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
    const std::string message =
        strCat("benchmark job ", jobFile.string(), " failed (", how, "; its message is above)");
    if (WIFEXITED(status) && WEXITSTATUS(status) == 2)
        throw InputError(message);
    throw std::runtime_error(message);
}

} // namespace hairvox::bench
