// hairvox.voxelize / hairvox.FiberGrid and hairvox.transmittance /
// hairvox.LitGrid: the fiber grid (voxelize/fiber_grid.h) and the global
// term toward a light at its voxels (transmittance/lit_grid.h), as numpy
// arrays over the active voxels — views of the packed arrays the libraries
// hold, in the grid's value order — and as Debian's pyopenvdb grids.
#include "bindings.h"
#include "long_call.h"

#include <hairvox/core/error.h>
#include <hairvox/core/parallel.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/transmittance/lit_grid.h>

#include <mutex>

namespace hairvox::python {

namespace {

/// A hairvox.FiberGrid: the grid, shared (a LitGrid keeps the grid it was
/// computed on), and its voxels' coordinates once asked for.
struct PyFiberGrid {
    std::shared_ptr<const FiberGrid> grid;
    std::shared_ptr<std::vector<openvdb::Coord>> ijk; ///< filled on first access
};

const std::vector<openvdb::Coord>& coordsOf(PyFiberGrid& g) {
    if (!g.ijk) {
        auto ijk = std::make_shared<std::vector<openvdb::Coord>>();
        ijk->reserve(g.grid->activeVoxelCount());
        g.grid->forEachVoxel([&](std::size_t, const openvdb::Coord& c) { ijk->push_back(c); });
        g.ijk = std::move(ijk);
    }
    return *g.ijk;
}

py::array ijkArray(py::object self) {
    const auto& ijk = coordsOf(self.cast<PyFiberGrid&>());
    static_assert(sizeof(openvdb::Coord) == 12);
    return view(ijk.empty() ? nullptr : ijk.front().data(), {py::ssize_t(ijk.size()), 3}, {12, 4},
                self);
}

py::array positionsArray(PyFiberGrid& g) {
    const auto& ijk = coordsOf(g);
    const double h = g.grid->info.voxelSize;
    py::array_t<double> out({py::ssize_t(ijk.size()), py::ssize_t(3)});
    double* p = out.mutable_data();
    for (const openvdb::Coord& c : ijk) {
        *p++ = double(c.x()) * h;
        *p++ = double(c.y()) * h;
        *p++ = double(c.z()) * h;
    }
    return out;
}

py::object vec3View(const std::vector<openvdb::Vec3s>& values, py::handle owner) {
    if (values.empty())
        return py::none();
    return view(values.front().asPointer(), {py::ssize_t(values.size()), 3}, {12, 4}, owner);
}

py::dict infoOf(const FiberGridInfo& info) {
    py::dict d;
    d["voxel_size"] = info.voxelSize;
    d["fiber_diameter"] = info.fiberScale.diameter;
    d["density_multiplier"] = info.fiberScale.densityMultiplier;
    d["source_file"] = info.sourceFile;
    d["source_hash"] = info.sourceHash;
    d["strands"] = info.strands;
    d["segments"] = info.segments;
    d["total_length"] = info.totalLength;
    d["hairvox_version"] = info.version;
    return d;
}

py::dict statsOf(const GlobalTermStats& s) {
    py::dict d;
    d["queries"] = s.queries;
    d["evaluated"] = s.evaluated;
    d["blocked_by_surface"] = s.blockedBySurface;
    d["empty_paths"] = s.emptyPaths;
    return d;
}

py::dict gridsToPython(const openvdb::GridPtrVec& grids) {
    py::dict out;
    for (const openvdb::GridBase::Ptr& g : grids)
        out[py::str(g->getName())] = toPyOpenVdb(g);
    return out;
}

/// A hairvox.LitGrid: the global term at the fiber grid's active voxels, and
/// what the .vdb's metadata records of how it was computed.
struct PyLitGrid {
    PyFiberGrid grid;
    VoxelGlobalTerms values;
    Light light;
    GlobalTermMode mode = GlobalTermMode::Grid;
    FiberParams fiber;
    DualScatteringParams dualScattering;

    openvdb::MetaMap metadata() const {
        return litGridMetadata(light, mode, grid.grid->info, fiber, dualScattering);
    }
};

/// A field of every GlobalTerm, viewed across the packed array.
py::array termView(py::object self, float GlobalTerm::*scalar) {
    const auto& terms = self.cast<const PyLitGrid&>().values.terms;
    const auto n = py::ssize_t(terms.size());
    const float* first = terms.empty() ? nullptr : &(terms.front().*scalar);
    return view(first, {n}, {py::ssize_t(sizeof(GlobalTerm))}, self);
}
py::array termView(py::object self, Rgb GlobalTerm::*rgb) {
    const auto& terms = self.cast<const PyLitGrid&>().values.terms;
    const auto n = py::ssize_t(terms.size());
    const float* first = terms.empty() ? nullptr : &(terms.front().*rgb).r;
    static_assert(sizeof(Rgb) == 12);
    return view(first, {n, 3}, {py::ssize_t(sizeof(GlobalTerm)), 4}, self);
}

py::dict lightDict(const Light& light) {
    py::dict d;
    d["name"] = light.name;
    d["type"] = kLightKindNames.name(light.kind);
    if (light.kind == Light::Kind::Directional)
        d["direction"] = py::make_tuple(light.direction.x, light.direction.y, light.direction.z);
    else
        d["position"] = py::make_tuple(light.position.x, light.position.y, light.position.z);
    d["color"] = py::make_tuple(light.color.r, light.color.g, light.color.b);
    d["intensity"] = light.intensity;
    return d;
}

/// The groom a voxelize() argument names: a hairvox.Groom, or a file read
/// (on the worker) by readGroom.
struct GroomArg {
    std::shared_ptr<const Groom> groom;
    std::filesystem::path file;

    static GroomArg from(py::handle value) {
        if (py::isinstance<PyGroom>(value))
            return {value.cast<const PyGroom&>().groom, {}};
        if (isPathLike(value))
            return {nullptr, pathArg(value, "groom")};
        throw InputError(
            strCat("groom: expected a hairvox.Groom or a groom file path, got ", typeName(value)));
    }
};

} // namespace

void bindGrids(py::module_& m) {
    py::class_<PyFiberGrid>(m, "FiberGrid",
                            R"doc(The fiber grid: the groom splatted into a sparse grid
of fiber length density λ and orientation (docs/DESIGN.md §5).

Arrays are over the active voxels, in one order shared by all of them:
ijk (N, 3) index coordinates, density (N,) λ in 1/length², orientation
(N, 3) the mean unit tangent E[u] (its length is the coherence), and with the
tensor, tensor_diag / tensor_off_diag (N, 3). A voxel (i, j, k) sits at
(i, j, k) · voxel_size (vertex-centred). Views of the grid, read-only.)doc")
        .def_property_readonly("voxel_size",
                               [](const PyFiberGrid& g) { return g.grid->info.voxelSize; })
        .def_property_readonly("active_voxel_count",
                               [](const PyFiberGrid& g) { return g.grid->activeVoxelCount(); })
        .def("__len__", [](const PyFiberGrid& g) { return g.grid->activeVoxelCount(); })
        .def_property_readonly("ijk", &ijkArray,
                               "(N, 3) int32 index coordinates of the active voxels")
        .def_property_readonly("positions", &positionsArray,
                               "(N, 3) float64 world positions ijk · voxel_size (a new array)")
        .def_property_readonly(
            "density",
            [](py::object self) {
                const auto& d = self.cast<const PyFiberGrid&>().grid->density;
                return view(d.data(), {py::ssize_t(d.size())}, {4}, self);
            },
            "(N,) float32 fiber length per unit volume λ (1/length²)")
        .def_property_readonly(
            "orientation",
            [](py::object self) {
                return vec3View(self.cast<const PyFiberGrid&>().grid->orientation, self);
            },
            "(N, 3) float32 mean unit tangent E[u], root to tip; |E[u]| is the coherence")
        .def_property_readonly(
            "tensor_diag",
            [](py::object self) {
                return vec3View(self.cast<const PyFiberGrid&>().grid->tensorDiag, self);
            },
            "(N, 3) float32 E[uuᵀ] xx, yy, zz, or None without the tensor")
        .def_property_readonly(
            "tensor_off_diag",
            [](py::object self) {
                return vec3View(self.cast<const PyFiberGrid&>().grid->tensorOffDiag, self);
            },
            "(N, 3) float32 E[uuᵀ] xy, xz, yz, or None without the tensor")
        .def_property_readonly(
            "type_fractions",
            [](py::object self) {
                py::list out;
                for (const auto& f : self.cast<const PyFiberGrid&>().grid->typeFraction)
                    out.append(view(f.data(), {py::ssize_t(f.size())}, {4}, self));
                return out;
            },
            "Per fiber type, (N,) float32 fraction of the voxel's fibers of that type "
            "(empty for a groom of one type)")
        .def_property_readonly(
            "info", [](const PyFiberGrid& g) { return infoOf(g.grid->info); },
            "What the grid was made from (the .vdb's metadata)")
        .def_property_readonly("memory_bytes",
                               [](const PyFiberGrid& g) { return g.grid->memoryBytes(); })
        .def_property_readonly("warnings", [](const PyFiberGrid& g) { return g.grid->warnings; })
        .def(
            "to_openvdb",
            [](const PyFiberGrid& g) {
                const FiberVdbGrids grids =
                    longCall(Progress{}, [&] { return toVdbGrids(*g.grid); });
                return gridsToPython(grids.all());
            },
            R"doc(The grids a .vdb of this grid holds, as Debian's pyopenvdb grids, by name
("density", "orientation", ...; with their metadata). Built once per call.)doc")
        .def(
            "save",
            [](const PyFiberGrid& g, py::handle path) {
                const std::filesystem::path p = pathArg(path, "path");
                longCall(Progress{}, [&] { writeFiberGrid(p, *g.grid); });
            },
            py::arg("path"),
            "Writes the grid as a .vdb file (atomically), as `hairvox voxelize` does.")
        .def_static(
            "load",
            [](py::handle path) {
                const std::filesystem::path p = pathArg(path, "path");
                return PyFiberGrid{std::make_shared<const FiberGrid>(
                                       longCall(Progress{}, [&] { return readFiberGrid(p); })),
                                   nullptr};
            },
            py::arg("path"),
            "Reads a fiber grid .vdb written by hairvox (ValueError if it is not one).")
        .def("__repr__", [](const PyFiberGrid& g) {
            return strCat("hairvox.FiberGrid(", g.grid->activeVoxelCount(), " active voxels of ",
                          g.grid->info.voxelSize, ")");
        });

    m.def(
        "voxelize",
        [](py::handle groomArg, py::handle voxelSize, py::handle voxelsAcross, py::handle diameter,
           py::handle densityMultiplier, py::handle tensor, py::handle memoryBudget,
           py::handle threads, py::handle progressArg) {
            const GroomArg groom = GroomArg::from(groomArg);
            SplatOptions splat;
            if (!voxelSize.is_none())
                splat.voxelSize = numberArg(voxelSize, "voxel_size", 1e-9, 1e6);
            const int across = voxelsAcross.is_none()
                                   ? kDefaultVoxelsAcross
                                   : int(intArg(voxelsAcross, "voxels_across", 1, 1 << 20));
            if (!voxelSize.is_none() && !voxelsAcross.is_none())
                throw InputError("voxel_size and voxels_across both set the voxel size; give one");
            const auto scale = [&](py::handle value, const char* name, float FiberScale::*field) {
                if (value.is_none())
                    return;
                splat.fiberScale.*field = float(numberArg(value, name, -1e30, 1e30));
                try {
                    splat.fiberScale.validate();
                } catch (const InputError& e) {
                    throw InputError(strCat(name, ": ", e.what()));
                }
            };
            scale(diameter, "diameter", &FiberScale::diameter);
            scale(densityMultiplier, "density_multiplier", &FiberScale::densityMultiplier);
            if (!tensor.is_none())
                splat.storeOrientationTensor = boolArg(tensor, "orientation_tensor");
            if (!memoryBudget.is_none())
                splat.memoryBudgetBytes = std::uint64_t(
                    numberArg(memoryBudget, "memory_budget", 0.001, 1e6) * double(1ull << 30));
            const int threadCount =
                threads.is_none() ? 0 : int(intArg(threads, "threads", 0, 1024));
            const Progress progress = Progress::from(progressArg);
            splat.showProgress = progress.bars;
            std::vector<std::string> warnings;
            auto grid = longCall(progress, [&] {
                const ThreadLimit limit(threadCount);
                std::shared_ptr<const Groom> g = groom.groom;
                if (!g) {
                    LoadedGroom loaded = readGroom(groom.file);
                    warnings = loaded.warnings;
                    g = std::make_shared<const Groom>(std::move(loaded.groom));
                }
                splat.sourceFile = g == groom.groom ? "in-memory groom" : groom.file.string();
                if (splat.voxelSize <= 0)
                    splat.voxelSize = defaultVoxelSize(*g, across);
                return std::make_shared<const FiberGrid>(splatStrands(*g, splat));
            });
            for (const std::string& w : warnings)
                warn(strCat(groom.file.string(), ": ", w));
            for (const std::string& w : grid->warnings)
                warn(w);
            return PyFiberGrid{std::move(grid), nullptr};
        },
        py::arg("groom"), py::kw_only(), py::arg("voxel_size") = py::none(),
        py::arg("voxels_across") = py::none(), py::arg("diameter") = py::none(),
        py::arg("density_multiplier") = py::none(), py::arg("orientation_tensor") = py::none(),
        py::arg("memory_budget") = py::none(), py::arg("threads") = py::none(),
        py::arg("progress") = py::none(),
        R"doc(Splats a groom into a FiberGrid, as `hairvox voxelize` does.

groom: a hairvox.Groom or a groom file path. voxel_size (scene units) or
voxels_across (across the groom's longest side, default 256). diameter and
density_multiplier: the fiber scale recorded in the grid. orientation_tensor:
also store E[uuᵀ]. memory_budget: GiB the splat may use (refused before
allocating otherwise). threads, progress: as in render(). The GIL is
released while splatting; Ctrl-C raises KeyboardInterrupt.)doc");

    py::class_<PyLitGrid>(m, "LitGrid",
                          R"doc(The dual-scattering global term toward one light at every
active voxel of a fiber grid (what `hairvox transmittance` writes).

Arrays over the fiber grid's active voxels, in its order (fiber_grid.ijk):
n (N,) expected fibers crossed toward the light, V (N,) direct visibility
e^-n, P (N, 3) the mean product of forward attenuations, T_s (N, 3) forward
transmittance d_f (P - V), sigma2_f (N, 3) forward variance (rad²). Views of
the computed values, read-only.)doc")
        .def_property_readonly(
            "fiber_grid", [](const PyLitGrid& l) { return l.grid; },
            "The FiberGrid the values are at (shared, not copied).")
        .def_property_readonly(
            "ijk",
            [](py::object self) {
                // The fiber grid's coordinates, kept alive by this object's grid.
                PyLitGrid& l = self.cast<PyLitGrid&>();
                const auto& ijk = coordsOf(l.grid);
                return view(ijk.empty() ? nullptr : ijk.front().data(),
                            {py::ssize_t(ijk.size()), 3}, {12, 4}, self);
            },
            "(N, 3) int32 index coordinates (the fiber grid's)")
        .def_property_readonly(
            "positions", [](PyLitGrid& l) { return positionsArray(l.grid); },
            "(N, 3) float64 world positions (a new array)")
        .def_property_readonly(
            "n", [](py::object self) { return termView(self, &GlobalTerm::n); },
            "(N,) float32 expected number of fibers crossed toward the light")
        .def_property_readonly(
            "V", [](py::object self) { return termView(self, &GlobalTerm::V); },
            "(N,) float32 direct visibility e^-n")
        .def_property_readonly(
            "P", [](py::object self) { return termView(self, &GlobalTerm::P); },
            "(N, 3) float32 mean product of forward attenuations ∏ā_f")
        .def_property_readonly(
            "T_s", [](py::object self) { return termView(self, &GlobalTerm::T_s); },
            "(N, 3) float32 forward-scattered transmittance d_f·(P − V)")
        .def_property_readonly(
            "sigma2_f", [](py::object self) { return termView(self, &GlobalTerm::sigma2_f); },
            "(N, 3) float32 accumulated forward variance σ_f² (rad²)")
        .def_property_readonly("light", [](const PyLitGrid& l) { return lightDict(l.light); })
        .def_property_readonly("mode", [](const PyLitGrid& l) { return toString(l.mode); })
        .def_property_readonly("stats", [](const PyLitGrid& l) { return statsOf(l.values.stats); })
        .def(
            "to_openvdb",
            [](const PyLitGrid& l) {
                const LitGrid lit =
                    longCall(Progress{}, [&] { return toLitGrid(*l.grid.grid, l.values); });
                const openvdb::MetaMap metadata = l.metadata();
                openvdb::GridPtrVec grids;
                for (const openvdb::GridBase::Ptr& g :
                     {openvdb::GridBase::Ptr(lit.n), openvdb::GridBase::Ptr(lit.V),
                      openvdb::GridBase::Ptr(lit.T_s), openvdb::GridBase::Ptr(lit.sigma2_f)}) {
                    for (auto it = metadata.beginMeta(); it != metadata.endMeta(); ++it)
                        g->insertMeta(it->first, *it->second);
                    grids.push_back(g);
                }
                return gridsToPython(grids);
            },
            R"doc(The lit grids n, V, T_s and sigma2_f as Debian's pyopenvdb grids, by name,
with the metadata `hairvox transmittance` writes. Built once per call.)doc")
        .def(
            "save",
            [](const PyLitGrid& l, py::handle path) {
                const std::filesystem::path p = pathArg(path, "path");
                longCall(Progress{},
                         [&] { writeLitGrid(p, toLitGrid(*l.grid.grid, l.values), l.metadata()); });
            },
            py::arg("path"),
            "Writes the lit grids as a .vdb (atomically), as `hairvox transmittance` does.")
        .def("__repr__", [](const PyLitGrid& l) {
            return strCat("hairvox.LitGrid(", l.values.terms.size(), " voxels, light '",
                          l.light.name, "', ", toString(l.mode), " mode)");
        });

    m.def(
        "transmittance",
        [](py::handle sceneArg, py::handle lightArg, py::handle mode, py::handle voxelSize,
           py::handle threads, py::handle progressArg) {
            Scene scene = sceneOf(sceneArg);
            if (!mode.is_none())
                scene.globalTermMode = enumArg(mode, "mode", kGlobalTermModeNames);
            if (!voxelSize.is_none())
                scene.voxelSize = float(numberArg(voxelSize, "voxel_size", 1e-9, 1000));
            scene.validate();
            const Light light = lightOf(lightArg, scene);
            PipelineOptions options;
            if (!threads.is_none())
                options.threads = int(intArg(threads, "threads", 0, 1024));
            const Progress progress = Progress::from(progressArg);
            options.progress = progress.bars;
            auto lit = std::make_unique<PyLitGrid>();
            lit->light = light;
            lit->mode = scene.globalTermMode;
            lit->fiber = scene.fiber;
            lit->dualScattering = scene.dualScattering;
            longCall(progress, [&] {
                // As `hairvox transmittance` (cli/commands/transmittance.cpp).
                const ThreadLimit limit(options.threads);
                const std::unique_ptr<SceneAssets> assets = loadSceneAssets(scene, options);
                if (!assets->grid) { // exact mode builds no grid: its voxels are the queries
                    checkVoxelSizeForGroom(scene, assets->groom.groom);
                    SplatOptions splat;
                    splat.voxelSize = scene.voxelSize.value_or(0.0f);
                    splat.fiberScale = scene.fiberScale;
                    splat.sourceFile = scene.groom.sourceName();
                    splat.showProgress = options.progress;
                    assets->grid =
                        std::make_shared<const FiberGrid>(splatStrands(assets->groom.groom, splat));
                }
                lit->grid.grid = assets->grid;
                lit->values =
                    evaluateAtActiveVoxels(*assets->grid, *assets->globalTerm->forLight(light));
            });
            return lit;
        },
        py::arg("scene") = py::none(), py::kw_only(), py::arg("light") = py::none(),
        py::arg("mode") = py::none(), py::arg("voxel_size") = py::none(),
        py::arg("threads") = py::none(), py::arg("progress") = py::none(),
        R"doc(The global term toward one light at every active voxel of the scene's fiber
grid: a LitGrid (what `hairvox transmittance` writes as a .vdb).

scene: as in render() (None, a path, a dict, or a hairvox.Groom).
light: the name of one of the scene's lights, a dict in the scene schema's
light form ({"type": "directional", "direction": [0, 1, 0]}), or None (the
scene's first light). mode: "grid", "approx" or "exact". voxel_size: of the
fiber grid (scene units). threads, progress: as in render().)doc");
}

} // namespace hairvox::python
