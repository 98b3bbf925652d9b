// hairvox render benchmarks: rasterizer throughput with a trivial shader.
//
// Printed figures (never asserted): wall time of rasterize() and its split
// (setup = tangents + projection + binning, raster = raster/sort/composite,
// shade = shader calls + accumulation), fragment counts, and the process's
// peak resident memory. The shading here is a constant, so "shade" is the
// renderer's share only; the real dual-scattering shader and the global term
// add their own cost on top (issue 6 targets: default scene ≤ 5 s end to end,
// 1.4M segments at 1920×1080 ≤ 10 s end to end and ≤ 2 GiB). The scene is
// data/scenes/key_back.json, the default look under its two directional
// lights, on which every earlier figure was measured (the embedded default
// scene is lit by an environment map since; `hairvox render` times it).
//
//   render_bench                                   # everything
//   render_bench --benchmark_filter=Head1080p      # the 1.4M-segment case alone (clean peak
//   memory)
//   render_bench --benchmark_filter=Turntable      # four frames, alone and sharing (FrameReuse)
#include <hairvox/core/host.h>
#include <hairvox/core/math.h>
#include <hairvox/film/image_file.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/render/rasterizer.h>
#include <hairvox/strands/procedural.h>

#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <unistd.h>

namespace hairvox {
namespace {

/// The default groom, mannequin and camera under a key and a back light.
Scene keyBackScene() {
    return loadScene(HAIRVOX_DATA_DIR "/scenes/key_back.json");
}

/// The cheapest valid shader: constants, in the layers of a real render (the
/// dual-scattering shader's five radiance layers and per light V, n, T_s, σ_f).
class ConstantShader : public FragmentShader {
public:
    explicit ConstantShader(const std::vector<Light>& lights) {
        layout_.radiance = {"direct_R", "direct_TT", "direct_TRT", "back_direct", "scatter"};
        for (const Light& l : lights)
            for (const auto& [name, channels] : {std::pair{".V", 1}, std::pair{".n", 1},
                                                 std::pair{".T_s", 3}, std::pair{".sigma_f", 3}})
                layout_.averages.push_back({l.name + name, channels});
    }
    const ShaderLayout& layout() const override { return layout_; }
    void shade(std::span<const ShadingPoint> points, std::span<float> out) const override {
        const std::size_t stride = layout_.stride();
        for (std::size_t i = 0; i < points.size(); ++i)
            for (std::size_t k = 0; k < stride; ++k)
                out[i * stride + k] = 0.1f + 0.01f * float(k);
    }

private:
    ShaderLayout layout_;
};

/// The process's peak so far (core/host.h; the host calibration is not in it).
double peakResidentMiB() {
    return peakResidentBytes() / double(1 << 20);
}

void report(benchmark::State& state, const RasterOutput& out) {
    const RasterStats& s = out.stats;
    state.counters["setup_s"] = s.setupSeconds;
    state.counters["raster_s"] = s.rasterSeconds;
    state.counters["shade_s"] = s.shadeSeconds;
    state.counters["segments"] = double(s.segments);
    state.counters["fragments"] = double(s.fragments);
    state.counters["composited"] = double(s.fragmentsComposited);
    state.counters["behind_opaque"] = double(s.fragmentsBehindOpaque);
    state.counters["shading_points"] = double(s.shadingPoints);
    state.counters["behind_surfaces"] = double(s.segmentTilesBehindSurfaces);
    state.counters["peak_MiB"] = peakResidentMiB();
}

/// The default groom and camera (1024²), arg 0: fragment / 1: vertex shading.
void BM_RenderDefaultScene(benchmark::State& state) {
    Scene scene = keyBackScene();
    scene.shadingRate = state.range(0) == 0 ? ShadingRate::Fragment : ShadingRate::Vertex;
    const Groom groom = generateGroom(scene.groom.procedural);
    const ConstantShader shader(scene.lights);
    RasterOutput out;
    for (auto _ : state)
        out = rasterize(groom, Camera(scene.camera), shader, rasterSettings(scene));
    report(state, out);
}
BENCHMARK(BM_RenderDefaultScene)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// 50,000 wavy strands × 29 points (1.4M segments) at 1920×1080, default camera and lights.
void BM_RenderHead1080p(benchmark::State& state) {
    Scene scene = keyBackScene();
    scene.camera.width = 1920;
    scene.camera.height = 1080;
    scene.shadingRate = state.range(0) == 0 ? ShadingRate::Fragment : ShadingRate::Vertex;
    ProceduralGroomParams params = scene.groom.procedural;
    params.strands = 50000;
    params.pointsPerStrand = 29;
    const Groom groom = generateGroom(params);
    const ConstantShader shader(scene.lights);
    RasterOutput out;
    for (auto _ : state)
        out = rasterize(groom, Camera(scene.camera), shader, rasterSettings(scene));
    report(state, out);
}
BENCHMARK(BM_RenderHead1080p)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Writing the default scene's film: arg 0 the EXR with every layer, 1 the PNG preview.
/// What a 100k-triangle mesh costs a 1920×1080 grid render of the default
/// groom (issue 15: ≤ 10% around the hair, < 5% far from it). Arg 0: the
/// analytic head sphere alone (before meshes); 1: the mannequin head at
/// 158 rings (99,856 triangles) instead; 2: the sphere, and that mannequin
/// 5 m away (off screen and off every shadow path). End to end, no files.
void BM_MeshCost1080p(benchmark::State& state) {
    Scene scene = keyBackScene();
    scene.camera.width = 1920;
    scene.camera.height = 1080;
    scene.output.exr.clear();
    scene.output.png.clear();
    MeshSource mannequin = scene.meshes.at(0);
    mannequin.mannequinRings = 158;
    scene.meshes.clear();
    if (state.range(0) != 1)
        scene.head =
            Head{Sphere{scene.groom.procedural.headCenter, scene.groom.procedural.headRadius}};
    if (state.range(0) == 1)
        scene.meshes.push_back(mannequin);
    if (state.range(0) == 2) {
        mannequin.transform.translate = Vec3f(5.0f, 0.0f, 0.0f);
        scene.meshes.push_back(mannequin);
    }
    SceneRender r;
    for (auto _ : state)
        r = renderScene(scene, {}, false);
    state.counters["total_s"] = r.times.total();
    state.counters["load_s"] = r.times.load;
    state.counters["globalterm_s"] = r.times.globalTerm;
    state.counters["raster_s"] = r.times.raster;
    state.counters["shade_s"] = r.times.shade;
    state.counters["fragments"] = double(r.raster->fragments);
}
BENCHMARK(BM_MeshCost1080p)
    ->DenseRange(0, 2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(3);

/// A turntable of the default scene: four frames, the camera 20° apart
/// around the head, rendered one after another (no files). Arg 0: each frame
/// as if alone; 1: the frames share the fiber grid and the lights'
/// preparation (FrameReuse, what `hairvox render a.json b.json ...` does).
/// frame_s is a frame's mean, later_frame_s that of the frames after the first.
void BM_Turntable(benchmark::State& state) {
    Scene scene = keyBackScene();
    scene.output.exr.clear();
    scene.output.png.clear();
    const Vec3f centre = scene.camera.lookAt, offset = scene.camera.position - centre;
    constexpr int kFrames = 4;
    double total = 0, later = 0;
    for (auto _ : state) {
        FrameReuse reuse;
        for (int f = 0; f < kFrames; ++f) {
            const float a = radians(20.0f * float(f));
            scene.camera.position =
                centre + Vec3f(offset.x * std::cos(a) - offset.z * std::sin(a), offset.y,
                               offset.x * std::sin(a) + offset.z * std::cos(a));
            const SceneRender r =
                renderScene(scene, {}, false, state.range(0) == 1 ? &reuse : nullptr);
            total += r.times.total();
            if (f > 0)
                later += r.times.total();
        }
    }
    const auto runs = double(state.iterations());
    state.counters["frame_s"] = total / (runs * kFrames);
    state.counters["later_frame_s"] = later / (runs * (kFrames - 1));
    state.counters["peak_MiB"] = peakResidentMiB();
}
BENCHMARK(BM_Turntable)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(2);

void BM_WriteOutput(benchmark::State& state) {
    const Scene scene = keyBackScene();
    const Groom groom = generateGroom(scene.groom.procedural);
    const RasterOutput out =
        rasterize(groom, Camera(scene.camera), ConstantShader(scene.lights), rasterSettings(scene));
    const auto dir = std::filesystem::temp_directory_path() /
                     ("hairvox-render-bench-" + std::to_string(::getpid()));
    const auto path = dir / (state.range(0) == 0 ? "default.exr" : "default.png");
    for (auto _ : state) {
        if (state.range(0) == 0)
            writeExr(path, out.film);
        else
            writePng(path, out.film.width(), out.film.height(),
                     previewPixels(out.film, scene.output.exposure, scene.output.toneMap));
    }
    state.counters["MiB"] = double(std::filesystem::file_size(path)) / 1048576.0;
    std::filesystem::remove_all(dir);
}
BENCHMARK(BM_WriteOutput)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
} // namespace hairvox
