// hairvox pathtrace benchmarks: how fast rays go through the hair, against
// Embree's own rate on the same curves, and the path tracer's rays/s and
// paths/s (printed figures, never asserted).
//
//   pathtrace_bench                                   # everything
//   pathtrace_bench --benchmark_filter=Embree         # the ray kernels only
//
// Rays start at random points on the fibers of the default scene's groom
// (620k segments) in uniformly random directions — what a path's continuation
// and shadow rays do — and are traced with 2 threads:
//  - EmbreeRaw: rtcIntersect1 on an Embree scene of the same flat curves built
//    here directly (no filter, no own-fiber test): Embree's own rate;
//  - RaySceneIntersect / RaySceneOccluded: the path tracer's queries, which
//    also skip the origin's own fiber (geometry/ray_scene.h);
//  - PathTrace512: the default look under its key and back lights
//    (data/scenes/key_back.json) at 512², 4 samples per pixel.
#include <hairvox/core/parallel.h>
#include <hairvox/core/rng.h>
#include <hairvox/geometry/ray_scene.h>
#include <hairvox/pathtrace/path_tracer.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/strands/procedural.h>

#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <memory>
#include <vector>

namespace hairvox {
namespace {

struct Fixture {
    Scene scene = loadScene(HAIRVOX_DATA_DIR "/scenes/key_back.json");
    Groom groom = generateGroom(scene.groom.procedural);
    struct Ray {
        Vec3f origin, dir;
        FiberPoint fiber;
    };
    std::vector<Ray> rays;

    Fixture() {
        Pcg32 rng(7);
        std::vector<std::uint32_t> firstPoint;
        for (std::size_t s = 0; s < groom.strandCount(); ++s)
            for (std::uint32_t k = groom.strandStart[s]; k + 1 < groom.strandStart[s + 1]; ++k)
                firstPoint.push_back(k);
        for (int i = 0; i < 200000; ++i) {
            const auto seg = std::uint32_t(rng.uniformFloat() * float(firstPoint.size() - 1));
            const std::uint32_t k = firstPoint[seg];
            const float t = rng.uniformFloat();
            const Vec3f p = groom.points[k] + t * (groom.points[k + 1] - groom.points[k]);
            const float z = rng.uniform(-1, 1), phi = rng.uniform(0, 6.2831853f);
            const float r = std::sqrt(std::max(0.0f, 1 - z * z));
            const auto strand = static_cast<std::uint32_t>(
                std::upper_bound(groom.strandStart.begin(), groom.strandStart.end(), k) -
                groom.strandStart.begin() - 1);
            rays.push_back({p, Vec3f(r * std::cos(phi), r * std::sin(phi), z), {strand, seg, 0.0f}});
        }
    }
    static const Fixture& get() {
        static const Fixture f;
        return f;
    }
};

void BM_RaySceneBuild(benchmark::State& state) {
    const Fixture& f = Fixture::get();
    for (auto _ : state) {
        const RayScene scene(f.groom, f.scene.fiberScale);
        benchmark::DoNotOptimize(&scene);
    }
    state.counters["segments"] = double(f.groom.segmentCount());
}
BENCHMARK(BM_RaySceneBuild)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

/// Embree's own rate: the same flat curves, width k·D, plain rtcIntersect1.
void BM_EmbreeRaw(benchmark::State& state) {
    const Fixture& f = Fixture::get();
    RTCDevice device = rtcNewDevice(nullptr);
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneBuildQuality(scene, state.range(0) == 0 ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM);
    std::vector<float> vertices;
    std::vector<std::uint32_t> index;
    const float radius = 0.5f * f.scene.fiberScale.ribbonWidth();
    for (const Vec3f& p : f.groom.points)
        vertices.insert(vertices.end(), {p.x, p.y, p.z, radius});
    vertices.insert(vertices.end(), {0, 0, 0, 0});
    for (std::size_t s = 0; s < f.groom.strandCount(); ++s)
        for (std::uint32_t k = f.groom.strandStart[s]; k + 1 < f.groom.strandStart[s + 1]; ++k)
            index.push_back(k);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_FLAT_LINEAR_CURVE);
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, vertices.data(), 0,
                               4 * sizeof(float), f.groom.pointCount());
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, index.data(), 0,
                               sizeof(std::uint32_t), index.size());
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene);
    std::atomic<std::uint64_t> hits{0};
    for (auto _ : state) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, f.rays.size(), 256), [&](const auto& r) {
            if (state.range(1) == 1)
                flushDenormalsToZero();
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            std::uint64_t h = 0;
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                RTCRayHit rh{};
                const auto& ray = f.rays[i];
                rh.ray.org_x = ray.origin.x;
                rh.ray.org_y = ray.origin.y;
                rh.ray.org_z = ray.origin.z;
                rh.ray.dir_x = ray.dir.x;
                rh.ray.dir_y = ray.dir.y;
                rh.ray.dir_z = ray.dir.z;
                rh.ray.tnear = 1e-3f * radius;
                rh.ray.tfar = 1e30f;
                rh.ray.mask = ~0u;
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rtcIntersect1(scene, &context, &rh);
                h += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
            }
            hits += h;
        });
    }
    state.counters["Mrays/s"] = benchmark::Counter(double(f.rays.size()) * 1e-6,
                                                   benchmark::Counter::kIsIterationInvariantRate);
    state.counters["hit share"] = double(hits) / (double(f.rays.size()) * double(state.iterations()));
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
}
BENCHMARK(BM_EmbreeRaw)->Args({0, 0})->Args({0, 1})->Args({1, 1})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RaySceneIntersect(benchmark::State& state) {
    const Fixture& f = Fixture::get();
    const RayScene scene(f.groom, f.scene.fiberScale);
    const bool skipOwn = state.range(0) == 1;
    for (auto _ : state) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, f.rays.size(), 256), [&](const auto& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const auto& ray = f.rays[i];
                const RayOrigin from{ray.fiber, 2 * scene.ribbonWidth()};
                benchmark::DoNotOptimize(
                    scene.intersect(ray.origin, ray.dir, 1e30f, skipOwn ? &from : nullptr));
            }
        });
    }
    state.counters["Mrays/s"] = benchmark::Counter(double(f.rays.size()) * 1e-6,
                                                   benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_RaySceneIntersect)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RaySceneOccluded(benchmark::State& state) {
    const Fixture& f = Fixture::get();
    const RayScene scene(f.groom, f.scene.fiberScale);
    for (auto _ : state) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, f.rays.size(), 256), [&](const auto& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const auto& ray = f.rays[i];
                const RayOrigin from{ray.fiber, 2 * scene.ribbonWidth()};
                benchmark::DoNotOptimize(scene.occluded(ray.origin, ray.dir, 1e30f, &from));
            }
        });
    }
    state.counters["Mrays/s"] = benchmark::Counter(double(f.rays.size()) * 1e-6,
                                                   benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_RaySceneOccluded)->Unit(benchmark::kMillisecond)->UseRealTime();

/// The default scene at 512², 4 samples per pixel.
void BM_PathTrace512(benchmark::State& state) {
    const Fixture& f = Fixture::get();
    PathTraceScene pts;
    pts.groom = &f.groom;
    pts.fiberScale = f.scene.fiberScale;
    pts.fibers = {f.scene.fiber};
    pts.lights = f.scene.lights;
    pts.camera = f.scene.camera;
    pts.camera.width = pts.camera.height = 512;
    const SceneSurfaces surfaces = loadSurfaces(f.scene);
    pts.surfaces = surfaces.scene;
    pts.surfaceAlbedo = surfaces.albedo;
    pts.background = f.scene.background;
    PathTraceSettings settings;
    settings.spp = 4;
    PathTraceStats stats;
    for (auto _ : state)
        stats = pathTrace(pts, settings).stats;
    state.counters["Mrays/s"] = stats.raysPerSecond() * 1e-6;
    state.counters["Mpaths/s"] = stats.pathsPerSecond() * 1e-6;
    state.counters["events/path"] = double(stats.scatteringEvents) / double(stats.paths);
    state.counters["deepest"] = stats.deepestPath;
}
BENCHMARK(BM_PathTrace512)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);

} // namespace
} // namespace hairvox
