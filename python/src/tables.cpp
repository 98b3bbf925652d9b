// hairvox.tables: the dual-scattering tables of a fiber (shading/
// dual_scattering_tables.h) as numpy arrays — views of the tables' rows —
// loaded from or built into the disk cache as `hairvox tables` does.
#include "bindings.h"
#include "long_call.h"

#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/shading/dual_scattering_tables.h>

namespace hairvox::python {

namespace {

using Sample = DualScatteringTables::Sample;

py::array rowView(const std::shared_ptr<const DualScatteringTables>& t, Rgb Sample::*field) {
    const auto rows = py::ssize_t(t->size());
    return viewOwnedBy(&(t->sample(0).*field).r, {rows, 3}, {py::ssize_t(sizeof(Sample)), 4}, t);
}

py::dict paramsOf(const FiberParams& f, float d_b) {
    py::dict d;
    d["eta"] = f.eta;
    d["sigma_a"] = py::make_tuple(f.sigma_a.r, f.sigma_a.g, f.sigma_a.b);
    d["alpha_r"] = f.alpha_R;
    d["beta_r"] = f.beta_R;
    d["eccentricity"] = f.eccentricity;
    d["caustic_width"] = f.causticWidth;
    d["caustic_gain"] = f.causticGain;
    d["caustic_fade"] = f.causticFade;
    d["caustic_max_width"] = f.causticMaxWidth;
    d["d_b"] = d_b;
    return d;
}

} // namespace

void bindTables(py::module_& m) {
    m.def(
        "tables",
        [](py::handle fiber, py::handle d_b, py::handle samples, py::handle cacheDir) {
            FiberParams params;
            TableBuildOptions options;
            if (py::isinstance<py::dict>(fiber) && !fiber.cast<py::dict>().contains("groom")) {
                params = defaultSceneWith("fiber", toJson(fiber, "tables"), "tables").fiber;
            } else if (!fiber.is_none()) { // a scene: its fiber and d_b, as `tables --scene`
                const Scene scene = sceneOf(fiber, "tables");
                params = scene.fiber;
                options.d_b = scene.dualScattering.d_b;
                if (!d_b.is_none())
                    throw InputError("d_b: the scene sets it (dual_scattering.d_b); give a fiber "
                                     "dict to choose it");
            }
            if (!d_b.is_none())
                options.d_b = float(numberArg(d_b, "d_b", 0, 1));
            if (!samples.is_none())
                options.thetaSamples = int(intArg(samples, "samples", 3, 10001));
            options.validate();
            const std::filesystem::path dir =
                cacheDir.is_none() ? defaultTableCacheDir() : pathArg(cacheDir, "cache_dir");
            auto t = std::make_shared<const DualScatteringTables>(longCall(Progress{}, [&] {
                return DualScatteringTables::loadOrBuild(params, dir, options);
            }));

            py::dict out;
            const auto rows = py::ssize_t(t->size());
            py::array_t<float> theta(rows);
            for (int k = 0; k < t->size(); ++k)
                theta.mutable_at(k) = t->theta(k);
            out["theta"] = theta;
            out["a_f"] = rowView(t, &Sample::aBar_f);
            out["a_b"] = rowView(t, &Sample::aBar_b);
            out["alpha_f"] = rowView(t, &Sample::alphaBar_f);
            out["alpha_b"] = rowView(t, &Sample::alphaBar_b);
            out["beta2_f"] = rowView(t, &Sample::beta2Bar_f);
            out["beta2_b"] = rowView(t, &Sample::beta2Bar_b);
            out["A_b"] = rowView(t, &Sample::ABar_b);
            out["Delta_b"] = rowView(t, &Sample::DeltaBar_b);
            out["sigma2_b"] = rowView(t, &Sample::sigma2Bar_b);
            constexpr int kPhi = DualScatteringTables::kNGPhiSamples;
            static_assert(sizeof(LobeValues) == 36);
            out["N_G"] =
                viewOwnedBy(&t->NGSample(0, 0).R.r, {rows, kPhi, 3, 3}, {kPhi * 36, 36, 12, 4}, t);
            py::array_t<float> phi(kPhi);
            for (int j = 0; j < kPhi; ++j)
                phi.mutable_at(j) = float(Pi * j / (kPhi - 1));
            out["N_G_phi"] = phi;
            out["params"] = paramsOf(params, options.d_b);
            out["from_cache"] = t->loadedFromCache();
            return out;
        },
        py::arg("fiber") = py::none(), py::kw_only(), py::arg("d_b") = py::none(),
        py::arg("samples") = py::none(), py::arg("cache_dir") = py::none(),
        R"doc(The dual-scattering tables of a hair fiber over the incident inclination θ
(docs/DESIGN.md §4), as `hairvox tables` computes them (disk cache).

fiber: None (the default fiber), a dict in the scene schema's fiber form
({"melanin": [8, 0.5]}, {"sigma_a": [...], "eta": 1.55}, ...), or a scene
(path or dict) whose fiber and dual_scattering.d_b are taken.
d_b: backward density factor [0, 1] (with a fiber dict). samples: θ rows
[3, 10001] (default 181, 1° steps). cache_dir: the table cache.

Returns a dict: "theta" (S,) radians; per θ (S, 3) RGB: "a_f", "a_b" (ā_f,
ā_b), "alpha_f", "alpha_b", "beta2_f", "beta2_b", "A_b", "Delta_b",
"sigma2_b"; "N_G" (S, 37, 3, 3): N^G at θ_d = θ, φ = "N_G_phi" (37,), lobe
R, TT, TRT, RGB; "params": the fiber used; "from_cache". Arrays are read-only
views of the tables.)doc");
}

} // namespace hairvox::python
