// The benchmark sweep (bench/sweep): the power-law
// fit, and a tiny sweep end to end — in this process and through
// `hairvox bench`, whose jobs run in child processes.
#include "test_util.h"

#include <hairvox/bench/sweep.h>
#include <hairvox/core/error.h>
#include <hairvox/core/rng.h>
#include <hairvox/shading/simd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>

namespace hairvox {
namespace {

TEST(BenchPowerLaw, RecoversASyntheticExponent) {
    std::vector<double> x, y;
    for (const double v : {1e4, 3e4, 1e5, 4e5, 1.4e6}) {
        x.push_back(v);
        y.push_back(3.0 * std::pow(v, 1.7));
    }
    const std::optional<PowerLawFit> exact = fitPowerLaw(x, y);
    ASSERT_TRUE(exact);
    EXPECT_NEAR(exact->exponent, 1.7, 1e-9);
    EXPECT_NEAR(exact->coefficient, 3.0, 1e-6);
    EXPECT_NEAR(exact->r2, 1.0, 1e-12);

    // ±10% multiplicative noise over two decades: the slope is still within 0.05.
    Pcg32 rng(11);
    std::vector<double> noisy;
    for (std::size_t i = 0; i < x.size(); ++i)
        noisy.push_back(0.02 * std::pow(x[i], 0.6) * (0.9 + 0.2 * rng.uniformDouble()));
    const std::optional<PowerLawFit> fit = fitPowerLaw(x, noisy);
    ASSERT_TRUE(fit);
    EXPECT_NEAR(fit->exponent, 0.6, 0.05);
    EXPECT_GT(fit->r2, 0.95);
}

TEST(BenchPowerLaw, NeedsTwoDistinctPositivePoints) {
    const std::vector<double> x = {5, 5, 0, -1}, y = {1, 2, 3, 4};
    EXPECT_FALSE(fitPowerLaw(x, y));
    const std::vector<double> x2 = {1, 10, 0}, y2 = {2, 20, 7};
    const std::optional<PowerLawFit> fit = fitPowerLaw(x2, y2); // the x = 0 pair is skipped
    ASSERT_TRUE(fit);
    EXPECT_NEAR(fit->exponent, 1.0, 1e-12);
    EXPECT_THROW(fitPowerLaw(x, y2), InputError);
}

/// A small procedural groom at a coarse voxel size, 64×64: every stage runs in milliseconds.
std::filesystem::path writeTinyScene(const test::TempDir& dir) {
    const auto path = dir / "tiny.json";
    test::writeText(path, R"({
  "groom": { "procedural": { "style": "wavy", "strands": 300, "points_per_strand": 12, "seed": 3 } },
  "fiber": { "diameter": 7e-5, "density_multiplier": 5, "sigma_a": [0.2, 0.3, 0.5] },
  "lights": [ { "name": "key", "type": "directional", "direction": [-0.6, 0.65, -0.45], "intensity": 3 },
              { "name": "back", "type": "directional", "direction": [0.45, 0.3, 0.85], "intensity": 4 } ],
  "camera": { "position": [-0.55, 0.02, -0.72], "look_at": [-0.025, -0.125, -0.025], "fov": 40,
              "resolution": [64, 64] },
  "head": { "center": [0, 0, 0], "radius": 0.1 },
  "grid": { "voxel_size": 0.012 },
  "output": { "exr": null, "png": null }
})");
    return path;
}

BenchScene sceneFile(std::string label, std::filesystem::path file) {
    BenchScene s;
    s.label = std::move(label);
    s.file = std::move(file);
    return s;
}

std::vector<std::vector<std::string>> readCsv(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::vector<std::vector<std::string>> rows;
    std::string line;
    while (std::getline(in, line)) {
        // RFC 4180 cells: a quoted cell may hold commas and doubled quotes.
        std::vector<std::string> cells(1);
        bool quoted = false;
        for (std::size_t i = 0; i < line.size(); ++i) {
            const char c = line[i];
            if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"')
                cells.back() += line[++i];
            else if (c == '"')
                quoted = !quoted;
            else if (c == ',' && !quoted)
                cells.emplace_back();
            else
                cells.back() += c;
        }
        rows.push_back(cells);
    }
    return rows;
}

/// Width and height from a PNG's signature and IHDR chunk.
std::pair<std::uint32_t, std::uint32_t> pngSize(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    unsigned char b[24] = {};
    in.read(reinterpret_cast<char*>(b), sizeof(b));
    const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (!in || std::memcmp(b, signature, 8) != 0 || std::memcmp(b + 12, "IHDR", 4) != 0)
        return {0, 0};
    const auto be32 = [](const unsigned char* p) {
        return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 |
               p[3];
    };
    return {be32(b + 16), be32(b + 20)};
}

std::size_t column(const std::string& name) {
    for (std::size_t i = 0; i < kBenchCsvColumns.size(); ++i)
        if (name == kBenchCsvColumns[i])
            return i;
    ADD_FAILURE() << "no column " << name;
    return 0;
}

TEST(BenchSweep, TinySweepWritesTablesAndPlots) {
    test::TempDir dir;
    const auto scene = writeTinyScene(dir);
    SweepOptions o;
    o.scenes = {sceneFile("tiny", scene)};
    o.voxelScales = {2, 1};
    o.exactRays = {1};
    o.referenceRays = 2;
    o.probePoints = 40;
    o.probeRays = 16;
    o.runs = 1;
    for (const std::uint32_t strands : {100u, 300u}) {
        BenchScene s = sceneFile(strCat("tiny ", strands), scene);
        s.strands = strands;
        o.segmentScaling.push_back(s);
    }
    for (const std::uint32_t size : {32u, 64u}) {
        BenchScene s = sceneFile(strCat("tiny ", size), scene);
        s.width = s.height = size;
        o.pixelScaling.push_back(s);
    }
    for (const double h : {0.024, 0.012}) {
        BenchScene s = sceneFile(strCat("tiny ", h * 1e3, " mm"), scene);
        s.voxelSize = h;
        o.voxelScaling.push_back(s);
    }
    o.model.scenes = {sceneFile("tiny", scene).atWidth(32)};
    o.model.melanins = {{"blond", 0.3f}, {"dark", 3.0f}};
    o.model.modes = {GlobalTermMode::Exact, GlobalTermMode::Grid};
    o.model.spp = 8;
    o.model.block = 4;
    o.model.frontierPathsPerCell = {4};
    o.model.frontierSpp = {4};
    o.outDir = dir / "out";
    const SweepResult result = runSweep(o);

    // 1 reference + 3 rates × (1 exact + 2 grid + 2 approx) + 2 melanins × (1
    // path reference + 2 modes + volumetric at its own and at one frontier
    // budget + the path tracer at one frontier spp) + 2 + 2 + 2 scaling rows.
    ASSERT_EQ(result.rows.size(), 34u);
    const auto csv = readCsv(o.outDir / "results.csv");
    ASSERT_EQ(csv.size(), 35u);
    ASSERT_EQ(csv[0].size(), kBenchCsvColumns.size());
    for (std::size_t i = 0; i < kBenchCsvColumns.size(); ++i)
        EXPECT_EQ(csv[0][i], kBenchCsvColumns[i]);
    for (std::size_t r = 1; r < csv.size(); ++r) {
        ASSERT_EQ(csv[r].size(), kBenchCsvColumns.size()) << r;
        EXPECT_GT(std::stod(csv[r][column("total_s")]), 0.0) << r;
        EXPECT_EQ(csv[r][column("peak_mib")], "") << "in-process jobs report no peak memory";
        const bool accuracy = csv[r][column("sweep")] == "accuracy";
        const bool model = csv[r][column("sweep")] == "model";
        const bool pathReference = csv[r][column("sweep")] == "path_reference";
        EXPECT_EQ(!csv[r][column("rel_l1")].empty(), accuracy || model) << r;
        EXPECT_EQ(!csv[r][column("mae_v")].empty(), accuracy) << r;
        EXPECT_EQ(!csv[r][column("eumelanin")].empty(), model || pathReference) << r;
        const bool path = model && csv[r][column("mode")] == "path";
        EXPECT_EQ(!csv[r][column("spp")].empty(), pathReference || path) << r;
        EXPECT_EQ(!csv[r][column("paths_per_cell")].empty(), csv[r][column("mode")] == "volumetric")
            << r;
        EXPECT_EQ(csv[r][column("block")], accuracy || model ? "4" : "") << r;
        if (accuracy) {
            EXPECT_GE(std::stod(csv[r][column("rel_l1")]), 0.0);
            EXPECT_LT(std::stod(csv[r][column("rel_l1")]), 1.0);
            // The exact reference's two halves (1 ray each over the h0 disk) give its floor.
            EXPECT_GT(std::stod(csv[r][column("noise_floor_l1")]), 0.0) << r;
            // Over 4×4 block means the reference's noise averages out: a lower floor.
            EXPECT_LT(std::stod(csv[r][column("block_noise_floor_l1")]),
                      std::stod(csv[r][column("noise_floor_l1")]))
                << r;
            EXPECT_LE(std::stod(csv[r][column("block_rel_l1_noise_removed")]),
                      std::stod(csv[r][column("block_rel_l1")]))
                << r;
        } else if (!model) {
            EXPECT_EQ(csv[r][column("block_rel_l1")], "") << r;
        }
        if (model) {
            // Against a noisy 8-spp reference: the floor is known and positive,
            // per pixel and over blocks, and lower over blocks.
            for (const char* prefix : {"", "block_"}) {
                const auto at = [&](const char* name) {
                    return std::stod(csv[r][column(std::string(prefix) + name)]);
                };
                EXPECT_GT(at("noise_floor_l1"), 0.0) << r << prefix;
                EXPECT_LE(at("rel_l1_noise_removed"), at("rel_l1")) << r << prefix;
            }
            EXPECT_LT(std::stod(csv[r][column("block_noise_floor_l1")]),
                      std::stod(csv[r][column("noise_floor_l1")]))
                << r;
        }
        if (path) {
            // The frontier's path tracer, at its own samples and seed: its raw
            // error is its noise and the reference's, well above either floor.
            EXPECT_EQ(csv[r][column("spp")], "4") << r;
            EXPECT_GT(std::stod(csv[r][column("rel_l1")]),
                      std::stod(csv[r][column("noise_floor_l1")]))
                << r;
        }
        if (csv[r][column("sweep")] == "voxels") {
            // Grid mode: the lights' preparation is timed, and is part of the global term.
            EXPECT_GT(std::stod(csv[r][column("global_term_prepare_s")]), 0.0) << r;
            EXPECT_LE(std::stod(csv[r][column("global_term_prepare_s")]),
                      std::stod(csv[r][column("global_term_s")]))
                << r;
        }
        if (pathReference) {
            EXPECT_EQ(csv[r][column("spp")], "8") << r;
            EXPECT_GT(std::stod(csv[r][column("rays_per_s")]), 0.0) << r;
            EXPECT_GT(std::stod(csv[r][column("paths_per_s")]), 0.0) << r;
        }
    }
    EXPECT_EQ(csv[1][column("sweep")], "reference");
    EXPECT_EQ(csv[1][column("rays")], "2");
    EXPECT_NEAR(std::stod(csv[1][column("voxel_size")]), 0.012, 1e-6) << "h0 is the scene's voxel";

    ASSERT_EQ(result.fits.size(), 3u);
    EXPECT_EQ(result.fits[2].kind, BenchSweepKind::Voxels);
    // Halving the voxel size gives the tiny groom more active voxels (the fit's x).
    const auto voxelsOf = [&](std::size_t r) {
        return std::stod(csv[r][column("active_voxels")]);
    };
    EXPECT_GT(voxelsOf(34), voxelsOf(33));
    EXPECT_NEAR(std::stod(csv[34][column("voxel_size")]), 0.012, 1e-6);
    for (const ScalingFit& fit : result.fits) {
        ASSERT_TRUE(fit.total);
        ASSERT_TRUE(fit.prepare);
        EXPECT_TRUE(std::isfinite(fit.total->exponent));
        EXPECT_FALSE(fit.peakMemory);
    }

    // The host (bench/host): host.json's figures, and results.md's header names it.
    std::ifstream hostFile(o.outDir / "host.json");
    const nlohmann::json host = nlohmann::json::parse(hostFile);
    EXPECT_EQ(host.at("simd_target").get<std::string>(), simdTarget());
    EXPECT_FALSE(host.at("cpu_model").get<std::string>().empty());
    EXPECT_GE(host.at("logical_cores").get<unsigned>(), 1u);
    for (const char* key : {"simd_fma_flops_per_second", "dram_bytes_per_second", "miss_latency_ns",
                            "baseline_flops_per_second"})
        EXPECT_GT(host.at(key).get<double>(), 0.0) << key;
    std::ifstream header(o.outDir / "results.md");
    std::string line;
    bool named = false;
    while (std::getline(header, line) && !named)
        named = line.rfind("Host: " + host.at("cpu_model").get<std::string>(), 0) == 0 &&
                line.find("SIMD " + simdTarget()) != std::string::npos;
    EXPECT_TRUE(named) << "results.md: no line \"Host: <cpu>, ..., SIMD <target>\"";

    std::ifstream md(o.outDir / "results.md");
    const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
    for (const char* needle :
         {"## Summary", "| tiny | 3,300 | 64×64 |", "## tiny", "| exact K=2 (reference) |",
          "4×4 blocks: noise removed | floor |", "| grid x1 | 0.012 | vertex |",
          "## Scaling with segment count", "## Scaling with image size",
          "cost ∝ pixels^k: total time k = ", "## Scaling with active voxels",
          "| tiny 24 mm | 0.024 |", "cost ∝ active voxels^k: total time k = ",
          "## Model error: dual scattering and volumetric against path tracing",
          "| tiny, dark | grid | ", "| tiny, dark | path 8 spp (reference) | ",
          "| tiny, dark | volumetric 12 paths/cell | ", "| tiny, dark | volumetric 4 paths/cell | ",
          "| tiny, dark | path 4 spp | "})
        EXPECT_NE(text.find(needle), std::string::npos) << needle << "\n" << text;

    // matplotlib figures (bench/sweep/plot_sweep.py): 14 × 6.5 in at 110 dpi (per pixel and
    // over blocks) and 3 × 7 × 5.2 in at 120 dpi (segments, pixels, active voxels).
    EXPECT_EQ(pngSize(o.outDir / "runtime_vs_error.png"), std::make_pair(1540u, 715u));
    EXPECT_EQ(pngSize(o.outDir / "scaling.png"), std::make_pair(2520u, 624u));
    // The frontier: one scene (a row) × two hair colours (columns).
    EXPECT_EQ(pngSize(o.outDir / "frontier.png"), std::make_pair(1040u, 500u));
    EXPECT_FALSE(std::filesystem::exists(o.outDir / ".work")) << "working files are removed";
}

TEST(BenchSweep, CommandRunsEachJobInItsOwnProcess) {
    test::TempDir dir;
    const auto scene = writeTinyScene(dir);
    const auto out = dir / "out";
    const test::CommandResult r =
        test::runHairvox("bench --quick --no-scaling --no-model --scene '" + scene.string() +
                         "' --out '" + out.string() + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("wrote " + (out / "results.md").string()), std::string::npos)
        << r.output;
    const auto csv = readCsv(out / "results.csv");
    ASSERT_EQ(csv.size(), 9u); // quick: reference + 1 exact + 3 grid + 3 approx
    for (std::size_t row = 1; row < csv.size(); ++row)
        EXPECT_GT(std::stod(csv[row][column("peak_mib")]), 1.0) << row;
}

TEST(BenchSweep, BadInputIsAnInputError) {
    SweepOptions o = SweepOptions::quick(HAIRVOX_DATA_DIR "/scenes");
    o.runs = 0;
    EXPECT_THROW(o.validate(), InputError);
    o = SweepOptions::full("no/such/dir");
    EXPECT_THROW(o.validate(), InputError);
    o = SweepOptions::quick(HAIRVOX_DATA_DIR "/scenes");
    o.validate();
    o.model.block = 0;
    EXPECT_THROW(o.validate(), InputError);
    o.model.block = 4;
    o.model.frontierSpp = {o.model.spp}; // the path tracer below its reference's samples
    EXPECT_THROW(o.validate(), InputError);
    o.model.frontierSpp = {};
    o.model.frontierPathsPerCell = {0.0f};
    EXPECT_THROW(o.validate(), InputError);
    // A style swap needs a procedural groom (key_back.json's), not a file's strands.
    BenchScene s = sceneFile("x", HAIRVOX_DATA_DIR "/scenes/ratboy_mohawk.json");
    s.style = GroomStyle::Curly;
    try {
        s.build();
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_TRUE(test::contains(e.what(), "x: a groom style swap applies to procedural grooms "
                                             "only"))
            << e.what();
    }
    s.file = HAIRVOX_DATA_DIR "/scenes/key_back.json";
    EXPECT_EQ(s.build().groom.procedural.style, GroomStyle::Curly);
    const auto r = test::runHairvox("bench --runs 0");
    EXPECT_EQ(r.exitCode, 2) << r.output;
}

} // namespace
} // namespace hairvox
