// hairvox environment-light benchmark (issue 37; docs/environment.md): the
// figures of the environment light, printed — identities, the dual-scattering
// integrator against the path tracer under real maps, the path tracer's noise
// under a sun, and what an environment costs against two directional lights.
//
//   environment_bench [--out DIR] [--quick] [section ...]
//
// Sections (all by default):
//   identities  a uniform environment on a Lambertian sphere (ρ·L) and a
//               small patch at the zenith against a directional light from
//               +y of the same irradiance, both integrators
//   design      dual scattering's choices (regions K, median cut of energy
//               or of solid angle, the regions' spread, the caches'
//               spacings) on the default look (data/scenes/key_back.json) under studio, sky and
//               city, against the path tracer: rel. L1 of the hair's radiance over 8×8 blocks with
//               the reference's noise removed, and the time
//   ratboy      Ratboy's mohawk on its body under studio.exr and sky.exr,
//               dual scattering (grid) against the path tracer, beside the
//               same under its two directional lights; the hair's surface
//               shadow from 4 rays a region against the default
//   noise       the path tracer's noise floor under sky.exr against
//               city.exr at equal time
//   regions     what the regions cost at 1024² (K, shadow rays, spacings): wall and CPU
//               time, preparation, lookups, shading, in this process
//   cost        key_back.json at 1024², grid mode: lit by studio.exr
//               against its two directional lights — wall time and peak
//               memory of the hairvox CLI, paired runs in child processes
//
// Path-traced references are written to DIR (default out/environment_bench)
// and reused while their scene is unchanged (the render hash in the EXR).
// --quick: smaller images and fewer samples (a smoke run, not the figures).
#include <hairvox/bench/host_report.h>
#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/film/image_file.h>
#include <hairvox/pipeline/pipeline.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <set>
#include <spawn.h>
#include <string>
#include <sys/resource.h>
#include <sys/wait.h>
#include <tuple>
#include <unistd.h>
#include <vector>

extern char** environ;

namespace hairvox {
namespace {

using Clock = std::chrono::steady_clock;

struct Options {
    std::filesystem::path out = "out/environment_bench";
    bool quick = false;
    std::set<std::string> sections;
};

const std::filesystem::path kData = HAIRVOX_DATA_DIR;
const std::filesystem::path kHairvox = HAIRVOX_BINARY;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string loadAverage() {
    std::ifstream in("/proc/loadavg");
    std::string one, five, fifteen;
    in >> one >> five >> fifteen;
    return one + " " + five + " " + fifteen;
}

/// The default look under its key and back lights (data/scenes/key_back.json),
/// its outputs cleared: the figures' base, as before the embedded default
/// scene was lit by the studio map.
Scene keyBackScene() {
    Scene scene = loadScene(kData / "scenes" / "key_back.json");
    scene.output.exr.clear();
    scene.output.png.clear();
    return scene;
}

/// The scene with an environment light of `map` (a file in data/hdri, or ""
/// for a uniform white one) in place of its lights.
Scene withEnvironment(Scene scene, const std::string& map, bool visible = true) {
    scene.lights.clear();
    EnvironmentLight env;
    if (!map.empty())
        env.file = kData / "hdri" / map;
    env.visible = visible;
    scene.environment = env;
    return scene;
}

/// A path-traced reference of `scene` in DIR/name.exr: read back when its
/// render hash is the scene's and it has `spp` samples, rendered otherwise.
Film reference(const Scene& scene, const Options& o, const std::string& name, std::uint32_t spp) {
    Scene s = scene;
    s.integrator = Integrator::Path;
    s.pathTrace.spp = spp;
    s.output = {};
    s.output.exr = o.out / (name + ".exr");
    const SceneGroom groom = loadGroom(s);
    const SceneSurfaces surfaces = loadSurfaces(s);
    const auto environment = loadEnvironment(s);
    const std::string hash = pathTraceHash(s, groom, surfaces, environment.get());
    if (std::filesystem::exists(s.output.exr)) {
        const ExrImage exr = readExr(s.output.exr);
        const auto attribute = [&](const char* key) {
            const auto it = exr.attributes.find(key);
            return it == exr.attributes.end() ? std::string() : it->second;
        };
        if (attribute("hairvox:pathTraceHash") == hash &&
            attribute("hairvox:spp") == std::to_string(spp + (spp & 1u)))
            return filmFromExr(exr);
    }
    const auto start = Clock::now();
    std::fprintf(stderr, "  (path tracing %s: %ux%u, %u spp ...)\n", name.c_str(), s.camera.width,
                 s.camera.height, spp);
    SceneRender r = renderScene(s, PipelineOptions{}, true);
    std::fprintf(stderr, "  (%s: %.0f s)\n", name.c_str(), secondsSince(start));
    return std::move(r.film);
}

struct Rendered {
    Film film;
    double seconds = 0;
    SceneRender render;
};

Rendered renderDual(const Scene& scene, const PipelineOptions& options = {}) {
    Scene s = scene;
    s.integrator = Integrator::DualScattering;
    s.output = {};
    const auto start = Clock::now();
    Rendered r;
    r.render = renderScene(s, options, false);
    r.seconds = secondsSince(start);
    r.film = std::move(r.render.film);
    return r;
}

/// The hair's radiance of `estimate` against the path-traced `ref` over
/// blocks of `block` pixels (the reference's noise removed).
ImageError hairError(const Film& estimate, const Film& ref, int block) {
    const ComparedImage e = hairRadianceOf(estimate).boxFiltered(block);
    const ComparedImage r = hairRadianceOf(ref).boxFiltered(block);
    return compareImages(e, r).value_or(ImageError{});
}

std::string errorText(const ImageError& e) {
    char line[160];
    std::snprintf(line, sizeof(line), "%6.3f (floor %5.3f, raw %5.3f, bias %+6.3f)%s",
                  e.relL1NoiseRemoved, e.noiseFloorL1, e.relL1, e.relBias,
                  e.resolved() ? "" : " unresolved");
    return line;
}

/// Mean of a film layer's channel-average over the pixels whose `mask` > 0.
double meanOver(const Film& film, const std::string& layer, const std::string& mask) {
    const FilmLayer& l = film.layer(layer);
    const FilmLayer& m = film.layer(mask);
    double sum = 0, n = 0;
    for (std::size_t p = 0; p < film.pixelCount(); ++p)
        if (m.value(p, 0) > 0.999f) {
            sum += double(l.rgb(p).average());
            n += 1;
        }
    return n > 0 ? sum / n : 0;
}

// --- identities ----------------------------------------------------------------

/// A 512 × 256 map black but for its first two rows (θ < 1.4°), of radiance L.
void writeZenithPatch(const std::filesystem::path& path, const Rgb& L) {
    Film film(512, 256);
    FilmLayer& rgb = film.layer(film.addLayer(std::string(Film::kBeauty), 3, true));
    for (std::size_t p = 0; p < 2 * 512; ++p)
        for (int c = 0; c < 3; ++c)
            rgb.at(p, c) = L[c];
    writeExr(path, film);
}

void identities(const Options& o) {
    std::printf("\n## Identities\n\n");
    // A Lambertian sphere of albedo ρ under a uniform environment L: ρ·L
    // everywhere it is seen (no hair in front of it).
    Scene sphere = keyBackScene();
    sphere.groom.procedural.strands = 1;
    sphere.groom.procedural.headCenter = Vec3f(0.0f, 5.0f, 0.0f); // far out of view
    sphere.meshes.clear();
    sphere.head = Head{Sphere{Vec3f(0.0f), 0.1f}, Rgb(0.5f, 0.4f, 0.3f)};
    sphere.camera.width = sphere.camera.height = o.quick ? 64 : 128;
    sphere.environment = EnvironmentLight{};
    sphere.environment->color = Rgb(0.8f, 1.0f, 1.2f);
    sphere.environment->visible = false;
    sphere.lights.clear();
    const Rgb expected = sphere.head->albedo * sphere.environment->color;
    for (const Integrator integrator : {Integrator::DualScattering, Integrator::Path}) {
        Scene s = sphere;
        s.integrator = integrator;
        s.pathTrace.spp = o.quick ? 16 : 64;
        s.output = {};
        const Film film = renderScene(s, PipelineOptions{}, false).film;
        const double got = meanOver(film, "surface", "A");
        std::printf("uniform environment on a Lambertian sphere, %-15s  rho*L %.4f, rendered %.4f "
                    "(%+.2f%%)\n",
                    toString(integrator), double(expected.average()), got,
                    100.0 * (got / double(expected.average()) - 1.0));
    }

    // A patch at the zenith (the map's first two rows, 1.4° around +y)
    // against a directional light from +y of the same irradiance ∫L dω.
    const std::filesystem::path patch = o.out / "zenith_patch.exr";
    const Rgb L(2000.0f);
    writeZenithPatch(patch, L);
    Scene hair = keyBackScene();
    hair.camera.width = hair.camera.height = o.quick ? 96 : 192;
    hair.output = {};
    Scene lit = hair;
    lit.lights = {Light::directional(Vec3f(0.0f, 1.0f, 0.0f))};
    lit.lights[0].name = "zenith";
    lit.lights[0].intensity =
        EnvironmentMap::readExr(patch, Rgb(1.0f), 0, 1u << 30).integral().average();
    Scene env = hair;
    env.lights.clear();
    env.environment = EnvironmentLight{};
    env.environment->file = patch;
    env.environment->visible = false;
    {
        const Film a = renderDual(env).film, b = renderDual(lit).film;
        const ImageError e =
            compareImages(hairRadianceOf(a).boxFiltered(8), hairRadianceOf(b).boxFiltered(8))
                .value_or(ImageError{});
        std::printf("zenith patch against a directional light from +y, dual scattering: hair "
                    "rel. L1 %.4f, bias %+.4f (8x8 blocks)\n",
                    e.relL1, e.relBias);
    }
    {
        const std::uint32_t spp = o.quick ? 32 : 256;
        const Film a = reference(env, o, "zenith_patch", spp);
        const Film b = reference(lit, o, "zenith_light", spp);
        const ImageError e = hairError(a, b, 8);
        std::printf("zenith patch against a directional light from +y, path tracer (%u spp each): "
                    "hair %s\n",
                    spp, errorText(e).c_str());
    }
}

// --- design --------------------------------------------------------------------

struct Variant {
    std::string label;
    std::uint32_t regions = kDefaultEnvironmentLights;
    std::function<void(EnvironmentOptions&)> change;
};

void design(const Options& o) {
    std::printf("\n## Dual scattering's design against the path tracer\n\n");
    Scene base = keyBackScene();
    base.camera.width = base.camera.height = o.quick ? 128 : 256;
    const std::uint32_t spp = o.quick ? 32 : 256;
    constexpr int kBlock = 8;
    std::printf("key_back.json at %ux%u, grid mode; error: rel. L1 of the hair's radiance over "
                "%dx%d blocks against a %u-spp path trace, its noise removed\n",
                base.camera.width, base.camera.height, kBlock, kBlock, spp);
    {
        const Film ref = reference(base, o, "default_lights", spp);
        const Rendered ds = renderDual(base);
        std::printf("\nits two directional lights: %s, %.2f s\n",
                    errorText(hairError(ds.film, ref, kBlock)).c_str(), ds.seconds);
    }
    std::vector<Variant> variants;
    for (const std::uint32_t k : {4u, 8u, 16u, 24u, 32u})
        variants.push_back({"energy", k, {}});
    variants.push_back({"solid angle", 16, [](EnvironmentOptions& e) {
                            e.split = EnvironmentSplit::SolidAngle;
                        }});
    variants.push_back({"no spread", 16, [](EnvironmentOptions& e) {
                            e.spread = false;
                        }});
    variants.push_back({"lights' spacings 1.5, 1", 16, [](EnvironmentOptions& e) {
                            e.cacheSpacing = 1.5f;
                            e.fiberSampleSpacing = 1.0f;
                        }});
    // Dual scattering with many regions: what the model itself gives under
    // the map, against which the regions' own error is measured.
    const std::uint32_t converged = o.quick ? 64 : 256;
    for (const char* map : {"studio.exr", "sky.exr", "city.exr"}) {
        const Scene scene = withEnvironment(base, map);
        const Film ref = reference(scene, o, std::string("default_") + map, spp);
        Scene many = scene;
        many.environmentLights = converged;
        const Rendered manyDs = renderDual(many);
        std::printf("\n%s; against K = %u: the same dual scattering with %u regions (%.1f s)\n"
                    "%-26s %5s  %-58s %-14s %7s\n",
                    map, converged, converged, manyDs.seconds, "regions", "K",
                    "error against the path tracer", "against K", "seconds");
        std::printf("%-26s %5u  %-58s %-14s %7.2f\n", "energy", converged,
                    errorText(hairError(manyDs.film, ref, kBlock)).c_str(), "", manyDs.seconds);
        for (const Variant& v : variants) {
            Scene s = scene;
            s.environmentLights = v.regions;
            PipelineOptions options;
            if (v.change)
                v.change(options.environment);
            const Rendered ds = renderDual(s, options);
            const ImageError toMany = compareImages(hairRadianceOf(ds.film).boxFiltered(kBlock),
                                                    hairRadianceOf(manyDs.film).boxFiltered(kBlock))
                                          .value_or(ImageError{});
            char against[32];
            std::snprintf(against, sizeof(against), "%.3f (%+.3f)", toMany.relL1, toMany.relBias);
            std::printf("%-26s %5u  %-58s %-14s %7.2f\n", v.label.c_str(), v.regions,
                        errorText(hairError(ds.film, ref, kBlock)).c_str(), against, ds.seconds);
            std::fflush(stdout);
        }
    }
}

// --- ratboy ---------------------------------------------------------------------

void ratboy(const Options& o) {
    std::printf("\n## A real groom on its body: Ratboy's mohawk under studio.exr\n\n");
    const std::uint32_t size = o.quick ? 160 : 320, spp = o.quick ? 64 : 512;
    constexpr int kBlock = 8;
    const auto prepare = [&](const char* file) {
        Scene s = loadScene(kData / "scenes" / file);
        s.globalTermMode = GlobalTermMode::Grid;
        s.shadingRate = ShadingRate::Fragment;
        s.camera.width = s.camera.height = size;
        return s;
    };
    std::printf("%ux%u, grid mode, fragment rate; error: rel. L1 of the hair's radiance over "
                "%dx%d blocks against a %u-spp path trace, its noise removed; single: the "
                "direct_* layers alone, rel. L1 and bias (no noise estimate)\n\n",
                size, size, kBlock, kBlock, spp);
    std::printf("%-40s %-58s %-16s %7s\n", "lighting", "error", "single", "seconds");
    struct Row {
        const char* label;
        const char* file;
        const char* name;
        std::size_t hairShadowRays;
    };
    const std::size_t rays = EnvironmentOptions{}.hairShadowRays;
    for (const Row& row :
         {Row{"its two lights (ratboy_mohawk)", "ratboy_mohawk.json", "ratboy_lights", rays},
          Row{"studio.exr (ratboy_studio)", "ratboy_studio.json", "ratboy_studio", rays},
          Row{"studio.exr, 4 shadow rays a region", "ratboy_studio.json", "ratboy_studio", 4},
          Row{"sky.exr (ratboy_sky)", "ratboy_sky.json", "ratboy_sky", rays},
          Row{"sky.exr, 4 shadow rays a region", "ratboy_sky.json", "ratboy_sky", 4}}) {
        const Scene scene = prepare(row.file);
        const Film ref = reference(scene, o, row.name, spp);
        PipelineOptions options;
        options.environment.hairShadowRays = row.hairShadowRays;
        const Rendered ds = renderDual(scene, options);
        const std::vector<std::string> direct = {"direct_R", "direct_TT", "direct_TRT"};
        const ImageError single =
            compareImages(ComparedImage::fromFilm(ds.film, direct, "hair.A").boxFiltered(kBlock),
                          ComparedImage::fromFilm(ref, direct, "hair.A").boxFiltered(kBlock))
                .value_or(ImageError{});
        std::printf("%-40s %-58s %6.3f (%+6.3f)  %7.2f\n", row.label,
                    errorText(hairError(ds.film, ref, kBlock)).c_str(), single.relL1,
                    single.relBias, ds.seconds);
        std::fflush(stdout);
    }
}

// --- noise -----------------------------------------------------------------------

void noise(const Options& o) {
    std::printf("\n## The path tracer's noise under a sun\n\n");
    Scene base = keyBackScene();
    base.camera.width = base.camera.height = o.quick ? 128 : 256;
    const double seconds = o.quick ? 10 : 120;
    std::printf("key_back.json at %ux%u, %.0f s each; noise floor: E|I_A - I| / E|I| of the hair's "
                "radiance (per pixel, and over 8x8 blocks)\n\n",
                base.camera.width, base.camera.height, seconds);
    double floors[2] = {0, 0};
    int k = 0;
    for (const char* map : {"city.exr", "sky.exr"}) {
        Scene s = withEnvironment(base, map);
        s.integrator = Integrator::Path;
        s.pathTrace.spp = 1'000'000;
        s.pathTrace.timeLimit = seconds;
        s.output = {};
        const SceneRender r = renderScene(s, PipelineOptions{}, false);
        const ComparedImage hair = hairRadianceOf(r.film);
        const ImageError pixel = compareImages(hair, hair).value_or(ImageError{});
        const ImageError block =
            compareImages(hair.boxFiltered(8), hair.boxFiltered(8)).value_or(ImageError{});
        floors[k++] = pixel.noiseFloorL1;
        std::printf("%-10s %5u spp: floor %.4f per pixel, %.4f over 8x8 blocks\n", map,
                    r.pathTrace->spp, pixel.noiseFloorL1, block.noiseFloorL1);
        std::fflush(stdout);
    }
    std::printf("sky / city: %.2f (goal: within 2)\n", floors[1] / floors[0]);
}

// --- regions: what each costs ----------------------------------------------------

double cpuSeconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

void regions(const Options& o) {
    std::printf("\n## What the regions cost (dual scattering, grid mode)\n\n");
    Scene base = keyBackScene();
    const std::uint32_t size = o.quick ? 512 : 1024;
    base.camera.width = base.camera.height = size;
    std::printf("key_back.json at %ux%u, in this process (CPU seconds: the machine may be "
                "shared); global term = the regions' preparation and lookups\n\n",
                size, size);
    std::printf("%-34s %9s %9s %9s %9s %9s\n", "lighting", "wall s", "CPU s", "prepare", "lookups",
                "shade");
    const auto row = [&](const std::string& label, const Scene& scene,
                         const PipelineOptions& options) {
        const double cpu = cpuSeconds();
        const Rendered r = renderDual(scene, options);
        const double prepare = r.render.environment ? r.render.environment->prepareSeconds +
                                                          r.render.environment->splitSeconds
                                                    : r.render.globalTermPrepareSeconds;
        std::printf("%-34s %9.2f %9.2f %9.2f %9.2f %9.2f\n", label.c_str(), r.seconds,
                    cpuSeconds() - cpu, prepare, r.render.times.globalTerm - prepare,
                    r.render.times.shade);
        std::fflush(stdout);
    };
    row("its two directional lights", base, PipelineOptions{});
    for (const std::uint32_t k : {8u, 16u, 24u, 32u}) {
        Scene s = withEnvironment(base, "studio.exr");
        s.environmentLights = k;
        row("studio.exr, K = " + std::to_string(k), s, PipelineOptions{});
    }
    {
        Scene s = withEnvironment(base, "studio.exr");
        PipelineOptions options;
        options.environment.hairShadowRays = 4;
        row("studio.exr, K = " + std::to_string(s.environmentLights) + ", 4 shadow rays", s,
            options);
    }
    for (const float spacing : {3.0f, 4.0f}) {
        Scene s = withEnvironment(base, "studio.exr");
        s.environmentLights = 16;
        PipelineOptions options;
        options.environment.fiberSampleSpacing = spacing;
        row("studio.exr, K = 16, samples " + std::to_string(int(spacing)) + " voxels", s, options);
    }
    {
        Scene s = withEnvironment(base, "studio.exr");
        s.environmentLights = 16;
        PipelineOptions options;
        options.environment.cacheSpacing = 4.0f;
        row("studio.exr, K = 16, cache lines 4", s, options);
    }
}

// --- cost ------------------------------------------------------------------------

struct ChildRun {
    double seconds = 0;
    double peakMiB = 0;
};

/// Runs the hairvox CLI with `args`, its output to `log`: wall time and peak RSS.
ChildRun runCli(const std::vector<std::string>& args, const std::filesystem::path& log) {
    std::vector<std::string> all = {kHairvox.string()};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& a : all)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    const auto start = Clock::now();
    pid_t pid = 0;
    if (posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ) != 0)
        throw std::runtime_error("cannot run " + kHairvox.string());
    posix_spawn_file_actions_destroy(&actions);
    int status = 0;
    rusage usage{};
    wait4(pid, &status, 0, &usage);
    ChildRun r;
    r.seconds = secondsSince(start);
    r.peakMiB = double(usage.ru_maxrss) / 1024.0;
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        throw std::runtime_error("hairvox failed; see " + log.string());
    return r;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

void cost(const Options& o) {
    std::printf("\n## What an environment costs (dual scattering, grid mode)\n\n");
    nlohmann::json lights =
        nlohmann::json::parse(std::ifstream(kData / "scenes" / "key_back.json"));
    nlohmann::json studio = lights;
    studio["lights"] =
        nlohmann::json::array({{{"name", "studio"},
                                {"type", "environment"},
                                {"file", (kData / "hdri" / "studio.exr").string()}}});
    studio.erase("background");
    const int size = o.quick ? 512 : 1024;
    for (nlohmann::json* j : {&lights, &studio}) {
        (*j)["camera"]["resolution"] = {size, size};
        (*j)["output"] = {{"exr", (o.out / "cost.exr").string()},
                          {"png", (o.out / "cost.png").string()}};
    }
    std::ofstream(o.out / "cost_lights.json") << lights.dump(1);
    std::ofstream(o.out / "cost_studio.json") << studio.dump(1);
    const int pairs = o.quick ? 1 : 5;
    std::printf("key_back.json at %dx%d: its two directional lights, and studio.exr instead "
                "(%u regions); %d alternating pairs of `hairvox render` (EXR and PNG written), "
                "medians\n\n",
                size, size, kDefaultEnvironmentLights, pairs);
    std::vector<double> t[2], peak[2], ratio;
    for (int p = 0; p < pairs; ++p)
        for (int k = 0; k < 2; ++k) {
            const std::filesystem::path scene =
                o.out / (k == 0 ? "cost_lights.json" : "cost_studio.json");
            const ChildRun r = runCli({"render", scene.string()},
                                      o.out / (k == 0 ? "cost_lights.log" : "cost_studio.log"));
            t[k].push_back(r.seconds);
            peak[k].push_back(r.peakMiB);
            if (k == 1)
                ratio.push_back(t[1].back() / t[0].back());
        }
    std::printf("two directional lights  %6.2f s  %6.0f MiB peak\n", median(t[0]), median(peak[0]));
    std::printf("studio.exr              %6.2f s  %6.0f MiB peak\n", median(t[1]), median(peak[1]));
    std::printf(
        "ratio (median of the pairs' ratios) %.2f (goal: at most 2); peak under 1 GiB: %s\n",
        median(ratio), median(peak[1]) < 1024 ? "yes" : "no");
    std::printf("\nthe last environment-lit run's report:\n");
    std::ifstream log(o.out / "cost_studio.log");
    for (std::string line; std::getline(log, line);)
        if (line.rfind("wrote", 0) != 0)
            std::printf("  %s\n", line.c_str());
}

} // namespace
} // namespace hairvox

int main(int argc, char** argv) {
    using namespace hairvox;
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--out" && i + 1 < argc)
            o.out = argv[++i];
        else if (a == "--quick")
            o.quick = true;
        else if (a == "identities" || a == "design" || a == "ratboy" || a == "noise" ||
                 a == "cost" || a == "regions")
            o.sections.insert(a);
        else {
            std::fprintf(stderr,
                         "usage: %s [--out DIR] [--quick] "
                         "[identities|design|ratboy|noise|regions|cost ...]\n",
                         argv[0]);
            return 2;
        }
    }
    if (o.sections.empty())
        o.sections = {"identities", "design", "ratboy", "noise", "cost"};
    std::filesystem::create_directories(o.out);
    std::printf("# hairvox environment light (environment_bench%s), load average %s\n",
                o.quick ? " --quick" : "", loadAverage().c_str());
    std::printf("host: %s\n", bench::HostReport::measure().line().c_str());
    try {
        if (o.sections.count("identities"))
            identities(o);
        if (o.sections.count("design"))
            design(o);
        if (o.sections.count("ratboy"))
            ratboy(o);
        if (o.sections.count("noise"))
            noise(o);
        if (o.sections.count("regions"))
            regions(o);
        if (o.sections.count("cost"))
            cost(o);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "environment_bench: %s\n", e.what());
        return 1;
    }
    return 0;
}
