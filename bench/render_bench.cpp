// hairvox render benchmarks: rasterizer throughput with a trivial shader.
//
// Printed figures (never asserted): wall time of renderImage() and its split
// (setup = tangents + projection + binning, raster = raster/sort/composite,
// shade = shader calls + accumulation), fragment counts, and the process's
// peak resident memory. The shading here is a constant, so "shade" is the
// renderer's share only; the real dual-scattering shader and the global term
// add their own cost on top (issue 6 targets: default scene ≤ 5 s end to end,
// 1.4M segments at 1920×1080 ≤ 10 s end to end and ≤ 2 GiB).
//
//   render_bench                                   # everything
//   render_bench --benchmark_filter=Head1080p      # the 1.4M-segment case alone (clean peak memory)
#include <hairvox/render/output.h>
#include <hairvox/render/render.h>
#include <hairvox/strands/procedural.h>

#include <benchmark/benchmark.h>

#include <filesystem>
#include <sys/resource.h>
#include <unistd.h>

namespace hairvox {
namespace {

/// The cheapest valid shader: a constant per lobe.
class ConstantShader : public FragmentShader {
public:
    void shade(std::span<const ShadingPoint> points, std::span<ShadeResult> radiance,
               std::span<GlobalTerm> terms) const override {
        ShadeResult r;
        r.directR = Rgb(0.3f, 0.25f, 0.2f);
        r.directTT = Rgb(0.2f, 0.15f, 0.1f);
        r.scatter = Rgb(0.1f, 0.08f, 0.05f);
        for (std::size_t i = 0; i < points.size(); ++i)
            radiance[i] = r;
        for (GlobalTerm& g : terms)
            g = GlobalTerm::unoccluded();
    }
};

double peakResidentMiB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0; // ru_maxrss is in KiB on Linux
}

void report(benchmark::State& state, const RenderOutput& out) {
    const RenderStats& s = out.stats;
    state.counters["setup_s"] = s.setupSeconds;
    state.counters["raster_s"] = s.rasterSeconds;
    state.counters["shade_s"] = s.shadeSeconds;
    state.counters["segments"] = double(s.segments);
    state.counters["fragments"] = double(s.fragments);
    state.counters["composited"] = double(s.fragmentsComposited);
    state.counters["behind_opaque"] = double(s.fragmentsBehindOpaque);
    state.counters["shading_points"] = double(s.shadingPoints);
    state.counters["behind_head"] = double(s.segmentsBehindHead);
    state.counters["peak_MiB"] = peakResidentMiB();
}

/// The default scene's groom and camera (1024²), arg 0: fragment / 1: vertex shading.
void BM_RenderDefaultScene(benchmark::State& state) {
    Scene scene = defaultScene();
    scene.shadingRate = state.range(0) == 0 ? ShadingRate::Fragment : ShadingRate::Vertex;
    const Groom groom = generateGroom(scene.groom.procedural);
    const ConstantShader shader;
    RenderOutput out;
    for (auto _ : state)
        out = renderImage(groom, scene, shader);
    report(state, out);
}
BENCHMARK(BM_RenderDefaultScene)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// 50,000 wavy strands × 29 points (1.4M segments) at 1920×1080, default camera and lights.
void BM_RenderHead1080p(benchmark::State& state) {
    Scene scene = defaultScene();
    scene.camera.width = 1920;
    scene.camera.height = 1080;
    scene.shadingRate = state.range(0) == 0 ? ShadingRate::Fragment : ShadingRate::Vertex;
    ProceduralGroomParams params = scene.groom.procedural;
    params.strands = 50000;
    params.pointsPerStrand = 29;
    const Groom groom = generateGroom(params);
    const ConstantShader shader;
    RenderOutput out;
    for (auto _ : state)
        out = renderImage(groom, scene, shader);
    report(state, out);
}
BENCHMARK(BM_RenderHead1080p)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Writing the default scene's film: arg 0 the EXR with every layer, 1 the PNG preview.
void BM_WriteOutput(benchmark::State& state) {
    const Scene scene = defaultScene();
    const Groom groom = generateGroom(scene.groom.procedural);
    const RenderOutput out = renderImage(groom, scene, ConstantShader());
    const auto dir = std::filesystem::temp_directory_path() /
                     ("hairvox-render-bench-" + std::to_string(::getpid()));
    const auto path = dir / (state.range(0) == 0 ? "default.exr" : "default.png");
    for (auto _ : state) {
        if (state.range(0) == 0)
            writeExr(path, out.film, Camera(scene.camera));
        else
            writePng(path, out.film, scene.output.exposure, scene.output.toneMap);
    }
    state.counters["MiB"] = double(std::filesystem::file_size(path)) / 1048576.0;
    std::filesystem::remove_all(dir);
}
BENCHMARK(BM_WriteOutput)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
} // namespace hairvox

BENCHMARK_MAIN();
