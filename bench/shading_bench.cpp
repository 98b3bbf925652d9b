// hairvox shading benchmarks: evaluations per second of f_s (tabulated and
// exact N_p), of the full dual-scattering shader per RGB sample, of the table
// lookups the transmittance stage makes per crossing, and the build times of
// the Marschner N_p table and of the dual-scattering tables.
// Target (issue 3): ≥ 5 M full-shader evaluations per second per core.
//
//   build/release/bench/shading_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only
#include <hairvox/core/math.h>
#include <hairvox/core/rng.h>
#include <hairvox/shading/dual_scattering_shader.h>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

namespace hairvox {
namespace {

/// Light, camera and tangent per fragment. Random: consecutive fragments share
/// nothing (the worst case for the caches). Coherent: as a rasterizer sees
/// them for one light — light and camera directions fixed, the tangent
/// turning slowly along a strand (≤ 1° per fragment), a new strand every 64.
struct Inputs {
    Inputs(std::size_t n, bool coherent) {
        Pcg32 rng(1);
        const auto dir = [&rng] {
            const float z = rng.uniform(-1, 1), a = rng.uniform(0, float(TwoPi));
            const float r = std::sqrt(1 - z * z);
            return Vec3f(r * std::cos(a), r * std::sin(a), z);
        };
        const Vec3f light = dir(), camera = dir();
        Vec3f tangent = dir();
        for (std::size_t k = 0; k < n; ++k) {
            if (coherent) {
                tangent = k % 64 == 0 ? dir() : glm::normalize(tangent + 0.017f * dir());
                wi.push_back(light);
                wo.push_back(camera);
                u.push_back(tangent);
            } else {
                wi.push_back(dir());
                wo.push_back(dir());
                u.push_back(dir());
            }
            theta.push_back(rng.uniform(-1.5f, 1.5f));
        }
    }
    std::vector<Vec3f> wi, wo, u;
    std::vector<float> theta;
};

const Inputs& inputs(bool coherent = false) {
    static const Inputs random(1 << 16, false), walk(1 << 16, true);
    return coherent ? walk : random;
}

struct Shading {
    Shading()
        : bcsdf(FiberParams{}), tables(DualScatteringTables::build(FiberParams{})),
          shader(bcsdf, tables, DualScatteringParams{}) {}
    MarschnerBcsdf bcsdf;
    DualScatteringTables tables;
    DualScatteringShader shader;
};

const Shading& shading() {
    static const Shading s;
    return s;
}

template <typename F>
void loop(benchmark::State& state, F&& f, bool coherent = false) {
    const Inputs& in = inputs(coherent);
    const std::size_t mask = in.wi.size() - 1;
    std::size_t k = 0;
    for (auto _ : state) {
        benchmark::DoNotOptimize(f(in, k & mask));
        ++k;
    }
    state.SetItemsProcessed(state.iterations());
}

void BM_FiberAngles(benchmark::State& state) {
    loop(state, [](const Inputs& in, std::size_t k) {
        return FiberAngles::fromDirections(in.wi[k], in.wo[k], in.u[k]);
    });
}

void BM_MarschnerEval(benchmark::State& state) {
    const MarschnerBcsdf& bcsdf = shading().bcsdf;
    loop(state, [&](const Inputs& in, std::size_t k) { return bcsdf.eval(in.wi[k], in.wo[k], in.u[k]); });
}

void BM_MarschnerEvalExact(benchmark::State& state) {
    const MarschnerBcsdf& bcsdf = shading().bcsdf;
    loop(state, [&](const Inputs& in, std::size_t k) {
        return bcsdf.evalExact(FiberAngles::fromDirections(in.wi[k], in.wo[k], in.u[k]));
    });
}

/// A global term with direct and scattered light both present (no
/// component of the shader skipped).
GlobalTerm partlyShadowed() {
    GlobalTerm g;
    g.n = 2;
    g.V = std::exp(-2.0f);
    g.P = Rgb(0.5f, 0.4f, 0.3f);
    g.T_s = 0.7f * (g.P - Rgb(g.V));
    g.sigma2_f = Rgb(0.02f, 0.021f, 0.022f);
    return g;
}

/// The full shader at one point at a time (a batch of one: the SIMD lanes
/// mostly idle): direct and scattered light both present (no component
/// skipped). Argument: coherent inputs.
void BM_ShaderShade(benchmark::State& state) {
    const DualScatteringShader& shader = shading().shader;
    const GlobalTerm g = partlyShadowed();
    loop(
        state, [&](const Inputs& in, std::size_t k) { return shader.shade(in.wi[k], in.wo[k], in.u[k], g); },
        state.range(0) != 0);
}

/// The renderer's path: the same shader over batches of 1024 points (the
/// rasterizer's shading batch) across SIMD lanes; time per point.
/// Argument: coherent inputs.
void BM_ShaderShadeBatch(benchmark::State& state) {
    const DualScatteringShader& shader = shading().shader;
    const Inputs& in = inputs(state.range(0) != 0);
    const GlobalTerm g = partlyShadowed();
    constexpr std::size_t kBatch = 1024;
    ShadeBatch batch;
    std::size_t first = 0;
    for (auto _ : state) {
        batch.reset(kBatch);
        for (std::size_t i = 0; i < kBatch; ++i) {
            const std::size_t k = (first + i) & (in.wi.size() - 1);
            batch.setView(i, in.wo[k], in.u[k]);
            batch.setIncident(i, in.wi[k], Rgb(1.0f));
            batch.setGlobalTerm(i, g);
        }
        shader.shade(batch);
        benchmark::DoNotOptimize(batch.radiance(0));
        first += kBatch;
    }
    state.SetItemsProcessed(state.iterations() * std::int64_t(kBatch));
}

void BM_ShaderShadeUnshadowed(benchmark::State& state) {
    const DualScatteringShader& shader = shading().shader;
    loop(state, [&](const Inputs& in, std::size_t k) {
        return shader.shade(in.wi[k], in.wo[k], in.u[k], GlobalTerm::unoccluded());
    });
}

/// What the transmittance stage calls per fiber crossing.
void BM_TableLookupForward(benchmark::State& state) {
    const DualScatteringTables& t = shading().tables;
    loop(state, [&](const Inputs& in, std::size_t k) {
        return t.aBar_f(in.theta[k]) + t.beta2Bar_f(in.theta[k]);
    });
}

void BM_MarschnerTableBuild(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                                      static_cast<std::size_t>(state.range(0)));
    FiberParams p;
    p.eccentricity = state.range(1) != 0 ? 0.85f : 1.0f;
    for (auto _ : state)
        benchmark::DoNotOptimize(MarschnerBcsdf(p));
}

void BM_DualScatteringTablesBuild(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                                      static_cast<std::size_t>(state.range(0)));
    FiberParams p;
    p.eccentricity = state.range(1) != 0 ? 0.85f : 1.0f;
    for (auto _ : state)
        benchmark::DoNotOptimize(DualScatteringTables::build(p));
}

BENCHMARK(BM_FiberAngles);
BENCHMARK(BM_MarschnerEval);
BENCHMARK(BM_MarschnerEvalExact);
BENCHMARK(BM_ShaderShade)->Arg(0)->Arg(1)->ArgName("coherent");
BENCHMARK(BM_ShaderShadeBatch)->Arg(0)->Arg(1)->ArgName("coherent");
BENCHMARK(BM_ShaderShadeUnshadowed);
BENCHMARK(BM_TableLookupForward);
BENCHMARK(BM_MarschnerTableBuild)->ArgsProduct({{1, 2}, {0, 1}})->ArgNames({"threads", "eccentric"})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DualScatteringTablesBuild)->ArgsProduct({{1, 2}, {0, 1}})->ArgNames({"threads", "eccentric"})->Unit(benchmark::kMillisecond);

} // namespace
} // namespace hairvox
