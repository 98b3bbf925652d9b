// hairvox.render and hairvox.Render: renderScene() (pipeline/pipeline.h)
// from Python, its film as numpy arrays, its outputs written as the CLI
// writes them (writeOutputs with the render's own EXR attributes).
//
// The film is sparse, in 32² tiles (film/film.h; docs/DESIGN.md §7, "A
// sparse film"), which no H × W × C array can view. Each layer is laid out
// once, on its first access — in parallel, the GIL released — into an array
// the Render owns; every access then returns a read-only view of that array
// (the same address each time, never a copy into Python). Nothing is laid
// out that is not asked for: a render that is only saved costs what the
// CLI's does. The array is fresh anonymous memory, zero until written, and
// only its pages that hold a value other than +0 are written: the rest of a
// mostly empty AOV is never faulted in (ZeroPages).
#include "bindings.h"
#include "long_call.h"

#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/pipeline/pipeline.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <mutex>
#include <sstream>
#include <sys/mman.h>
#include <unistd.h>

namespace hairvox::python {

namespace {

/// Anonymous memory from mmap: every byte zero until written, and a page
/// never written never faulted in — no first-touch cost, no resident memory.
/// Layers are mostly +0 where no hair is seen (80% of the tiles of a hair
/// AOV on the 1080p head, film/film.h): writeNonZeroPages() leaves those
/// pages alone. Read-only to Python, so they stay untouched.
class ZeroPages {
public:
    explicit ZeroPages(std::size_t bytes)
        : bytes_(std::max<std::size_t>(bytes, 1)) {
        void* p =
            ::mmap(nullptr, bytes_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED)
            throw std::bad_alloc();
        data_ = static_cast<float*>(p);
    }
    ~ZeroPages() { ::munmap(data_, bytes_); }
    ZeroPages(const ZeroPages&) = delete;
    ZeroPages& operator=(const ZeroPages&) = delete;
    float* data() const { return data_; }

private:
    std::size_t bytes_;
    float* data_ = nullptr;
};

/// Copies `count` floats to `dst` (zero-filled memory), skipping every
/// destination page whose part of `src` is all +0 bits: that page is left
/// unfaulted, and reads as the zeros it holds.
void writeNonZeroPages(float* dst, const float* src, std::size_t count) {
    static const auto page = std::uintptr_t(::sysconf(_SC_PAGESIZE));
    std::size_t i = 0;
    while (i < count) {
        // This chunk: up to the next page boundary of the destination.
        const auto address = reinterpret_cast<std::uintptr_t>(dst + i);
        const std::size_t toBoundary = (page - address % page) / sizeof(float);
        const std::size_t n = std::min(count - i, std::max<std::size_t>(toBoundary, 1));
        if (std::any_of(src + i, src + i + n, [](float v) { return !isPositiveZero(v); }))
            std::memcpy(dst + i, src + i, n * sizeof(float));
        i += n;
    }
}

/// A layer as Render.layers names it: "beauty" is the film's "" (RGB) and
/// "A" (when the film has it) as RGBA; every other layer keeps its film name.
struct LayerMap {
    std::string name;
    std::vector<std::size_t> film; ///< film layers interleaved into it, in order
    int channels = 0;
};

struct PyRender {
    Scene scene;
    std::filesystem::path sceneFile; ///< when the scene came from a file (never overwritten)
    SceneRender render;
    std::vector<LayerMap> layers;
    std::map<std::string, std::unique_ptr<ZeroPages>> dense; ///< laid out on first access
    std::mutex denseMutex;

    PyRender(Scene s, std::filesystem::path file, SceneRender r)
        : scene(std::move(s))
        , sceneFile(std::move(file))
        , render(std::move(r)) {
        const Film& film = render.film;
        if (const auto beauty = film.find(Film::kBeauty)) {
            LayerMap b{"beauty", {*beauty}, 3};
            if (const auto alpha = film.find(Film::kAlpha)) {
                b.film.push_back(*alpha);
                b.channels = 4;
            }
            layers.push_back(b);
        }
        for (std::size_t i = 0; i < film.layers().size(); ++i) {
            const FilmLayer& l = film.layer(i);
            if (l.name != Film::kBeauty && l.name != Film::kAlpha)
                layers.push_back({l.name, {i}, l.channels});
        }
    }

    const LayerMap* find(const std::string& name) const {
        for (const LayerMap& l : layers)
            if (l.name == name)
                return &l;
        return nullptr;
    }

    /// The layer laid out as H × W × C (row 0 at the top), once.
    const float* layout(const LayerMap& layer) {
        py::gil_scoped_release released;
        std::lock_guard lock(denseMutex);
        if (const auto it = dense.find(layer.name); it != dense.end())
            return it->second->data();
        const Film& film = render.film;
        const auto width = std::size_t(film.width()), c = std::size_t(layer.channels);
        auto values =
            std::make_unique<ZeroPages>(width * std::size_t(film.height()) * c * sizeof(float));
        tbb::parallel_for(tbb::blocked_range<int>(0, film.height(), 8), [&](const auto& rows) {
            std::vector<float> source, out(width * c);
            for (int y = rows.begin(); y < rows.end(); ++y) {
                std::size_t offset = 0; // of this film layer's first channel in a pixel
                for (const std::size_t index : layer.film) {
                    const FilmLayer& l = film.layer(index);
                    const auto lc = std::size_t(l.channels);
                    source.resize(width * lc);
                    if (!l.copyRow(y, source.data()))
                        for (std::size_t x = 0; x < width; ++x)
                            for (std::size_t k = 0; k < lc; ++k)
                                source[x * lc + k] = l.fill(int(k));
                    for (std::size_t x = 0; x < width; ++x)
                        std::memcpy(out.data() + x * c + offset, source.data() + x * lc,
                                    lc * sizeof(float));
                    offset += lc;
                }
                writeNonZeroPages(values->data() + std::size_t(y) * width * c, out.data(),
                                  width * c);
            }
        });
        return dense.emplace(layer.name, std::move(values)).first->second->data();
    }
};

py::array layerArray(py::object self, const std::string& name) {
    PyRender& r = self.cast<PyRender&>();
    const LayerMap* layer = r.find(name);
    if (!layer) {
        std::string names;
        for (const LayerMap& l : r.layers)
            names += (names.empty() ? "" : ", ") + l.name;
        throw py::key_error(
            strCat("'", name, "': the render has no such layer (it has ", names, ")"));
    }
    const float* data = r.layout(*layer);
    const auto w = py::ssize_t(r.render.film.width()), h = py::ssize_t(r.render.film.height());
    const auto c = py::ssize_t(layer->channels);
    return view(data, {h, w, c}, {w * c * 4, c * 4, 4}, self);
}

/// Render.layers: a read-only mapping from layer name to array.
struct PyLayers {
    py::object render;
};

py::list layerNames(const PyLayers& l) {
    py::list names;
    for (const LayerMap& layer : l.render.cast<const PyRender&>().layers)
        names.append(layer.name);
    return names;
}

// --- the report ---------------------------------------------------------------

py::dict timesOf(const StageTimes& t) {
    py::dict d;
    d["load"] = t.load;
    d["voxelize"] = t.voxelize;
    d["tables"] = t.tables;
    d["global_term"] = t.globalTerm;
    d["raster"] = t.raster;
    d["shade"] = t.shade;
    d["trace"] = t.trace;
    d["write"] = t.write;
    d["total"] = t.total();
    return d;
}

py::dict rasterOf(const RasterStats& s) {
    py::dict d;
    d["segments"] = s.segments;
    d["segments_outside_view"] = s.segmentsOutsideView;
    d["segment_tiles"] = s.segmentTileRefs;
    d["segment_tiles_behind_surfaces"] = s.segmentTilesBehindSurfaces;
    d["segment_tiles_opaque"] = s.segmentTilesSkipped;
    d["fragments"] = s.fragments;
    d["fragments_behind_opaque"] = s.fragmentsBehindOpaque;
    d["fragments_composited"] = s.fragmentsComposited;
    d["shading_points"] = s.shadingPoints;
    d["fragments_interpolated"] = s.fragmentsInterpolated;
    d["tail_fragments"] = s.tailFragments;
    d["tail_vertices"] = s.tailVertices;
    d["probed_segments"] = s.probedSegments;
    d["smooth_segments"] = s.smoothSegments;
    d["invalid_samples"] = s.invalidSamples;
    d["tiles"] = s.tiles;
    return d;
}

py::dict pathTraceOf(const PathTraceStats& s) {
    py::dict d;
    d["spp"] = s.spp;
    d["spp_this_run"] = s.sppThisRun;
    d["seconds"] = s.seconds;
    d["paths"] = s.paths;
    d["rays"] = s.rays;
    d["shadow_rays"] = s.shadowRays;
    d["scattering_events"] = s.scatteringEvents;
    d["deepest_path"] = s.deepestPath;
    d["paths_at_depth_cap"] = s.pathsAtDepthCap;
    d["energy_at_depth_cap"] = s.energyAtDepthCap;
    d["time_limited"] = s.timeLimited;
    return d;
}

py::dict reportOf(const PyRender& r) {
    const SceneRender& s = r.render;
    py::dict d;
    d["scene"] = r.scene.name;
    d["integrator"] = toString(r.scene.integrator);
    d["mode"] = s.pathTrace ? py::object(py::none())
                            : py::object(py::str(toString(r.scene.globalTermMode)));
    d["width"] = s.film.width();
    d["height"] = s.film.height();
    d["times"] = timesOf(s.times);
    d["global_term_prepare_seconds"] = s.globalTermPrepareSeconds;
    py::list lights;
    for (const LightReport& l : s.lights) {
        py::dict light;
        light["name"] = l.name;
        light["skipped"] = l.skipped;
        light["reused"] = l.reused;
        light["prepare_seconds"] = l.prepareSeconds;
        light["held_bytes"] = l.heldBytes;
        light["queries"] = l.stats.queries;
        light["evaluated"] = l.stats.evaluated;
        light["blocked_by_surface"] = l.stats.blockedBySurface;
        light["empty_paths"] = l.stats.emptyPaths;
        lights.append(light);
    }
    d["lights"] = lights;
    d["raster"] = s.raster ? py::object(rasterOf(*s.raster)) : py::object(py::none());
    d["path_trace"] = s.pathTrace ? py::object(pathTraceOf(*s.pathTrace)) : py::object(py::none());
    d["active_voxels"] = s.activeVoxels;
    d["voxel_size"] = s.voxelSize;
    d["grid_reused"] = s.gridReused;
    d["surface_triangles"] = s.surfaceTriangles;
    d["fiber_types"] = s.fiberTypes;
    d["film_bytes_held"] = s.film.bytesHeld();
    d["notes"] = s.groomNotes;
    d["warnings"] = s.warnings;
    std::ostringstream text;
    printTimingReport(text, r.scene, s);
    d["text"] = text.str();
    return d;
}

// --- render() -------------------------------------------------------------------

constexpr std::int64_t kMaxSide = 8192;

/// The keywords of render() applied to the scene, as the CLI applies its
/// options (cli/commands/render.cpp prepareScene): one of width and height
/// keeps the camera's aspect ratio; spp belongs to the path integrator, seed
/// to the path and volumetric integrators.
void applyOverrides(Scene& scene, py::handle width, py::handle height, py::handle integrator,
                    py::handle mode, py::handle spp, py::handle seed) {
    if (!mode.is_none())
        scene.globalTermMode = enumArg(mode, "mode", kGlobalTermModeNames);
    if (!integrator.is_none())
        scene.integrator = enumArg(integrator, "integrator", kIntegratorNames);
    if (!spp.is_none() && scene.integrator != Integrator::Path)
        throw InputError(strCat("spp applies to the path integrator (integrator='path'); ",
                                scene.name, " uses ", toString(scene.integrator)));
    if (!seed.is_none() && scene.integrator != Integrator::Path &&
        scene.integrator != Integrator::Volumetric)
        throw InputError(strCat("seed applies to the path and volumetric integrators; ",
                                scene.name, " uses ", toString(scene.integrator)));
    if (!spp.is_none())
        scene.pathTrace.spp = std::uint32_t(intArg(spp, "spp", 1, 1'000'000));
    if (!seed.is_none())
        (scene.integrator == Integrator::Path ? scene.pathTrace.seed : scene.volumetric.seed) =
            std::uint64_t(intArg(seed, "seed", 0, std::numeric_limits<std::int64_t>::max()));
    CameraParams& camera = scene.camera;
    const double aspect = double(camera.width) / double(camera.height);
    const auto side = [](double v) {
        return std::uint32_t(std::max(1.0, std::round(v)));
    };
    if (!width.is_none() && !height.is_none()) {
        camera.width = std::uint32_t(intArg(width, "width", 1, kMaxSide));
        camera.height = std::uint32_t(intArg(height, "height", 1, kMaxSide));
    } else if (!width.is_none()) {
        camera.width = std::uint32_t(intArg(width, "width", 1, kMaxSide));
        camera.height = side(camera.width / aspect);
    } else if (!height.is_none()) {
        camera.height = std::uint32_t(intArg(height, "height", 1, kMaxSide));
        camera.width = side(camera.height * aspect);
    }
    if (camera.width > kMaxSide || camera.height > kMaxSide)
        throw InputError(strCat(camera.width, " x ", camera.height,
                                " (keeping the scene camera's aspect ratio): expected at most ",
                                kMaxSide, " pixels a side; give both width and height"));
    scene.validate();
}

/// save()'s outputs, as the CLI resolves --exr, --png and -o
/// (cli/commands/render.cpp resolveOutputs): given ones replace the scene's.
OutputSettings resolveOutputs(const PyRender& r, py::handle path, py::handle exr, py::handle png) {
    OutputSettings out = r.scene.output;
    if (!path.is_none() || !exr.is_none() || !png.is_none()) {
        out.exr = exr.is_none() ? std::filesystem::path() : pathArg(exr, "exr");
        out.png = png.is_none() ? std::filesystem::path() : pathArg(png, "png");
        if (!path.is_none()) {
            const std::filesystem::path p = pathArg(path, "path");
            std::string ext = p.extension().string();
            std::transform(ext.begin(), ext.end(), ext.begin(),
                           [](unsigned char c) { return char(std::tolower(c)); });
            if (ext != ".exr" && ext != ".png")
                throw InputError(strCat("path = '", p.string(),
                                        "': the extension must be .exr or .png (it chooses the "
                                        "output); or give exr= and/or png="));
            std::filesystem::path& target = ext == ".exr" ? out.exr : out.png;
            if (!target.empty())
                throw InputError(strCat("path = '", p.string(), "' and ", ext.substr(1), " = '",
                                        target.string(), "' both set the ", ext.substr(1),
                                        " output; give one"));
            target = p;
        }
    }
    if (out.exr.empty() && out.png.empty())
        throw InputError(strCat(r.scene.name,
                                ": output.exr and output.png are both null; nothing would be "
                                "written (give save(path))"));
    if (!out.exr.empty() && !out.png.empty() && sameFile(out.exr, out.png))
        throw InputError(strCat("exr = '", out.exr.string(), "' and png = '", out.png.string(),
                                "' are the same file; the EXR and the PNG need different paths"));
    for (const std::filesystem::path* o : {&out.exr, &out.png}) {
        if (o->empty())
            continue;
        if (!r.sceneFile.empty() && sameFile(*o, r.sceneFile))
            throw InputError(strCat(o->string(), " is the scene file; it would be overwritten"));
        if (!r.scene.groom.file.empty() && sameFile(*o, r.scene.groom.file))
            throw InputError(strCat(o->string(), " is the groom file ", r.scene.groom.file.string(),
                                    "; it would be overwritten"));
    }
    return out;
}

} // namespace

const Film* filmOf(py::handle value) {
    if (!py::isinstance<PyRender>(value))
        return nullptr;
    return &value.cast<const PyRender&>().render.film;
}

void bindRender(py::module_& m) {
    py::class_<PyLayers>(m, "Layers", R"doc(Render.layers: a read-only mapping from EXR layer name
to a float32 array of shape (height, width, channels), row 0 at the top.

"beauty" is RGBA; the AOVs keep their EXR names ("direct_R", "scatter",
"Z", "hair.A", "key.V", ...). An array is a read-only view of memory the
Render owns: laid out from the film on first access, the same memory every
access after (np.array(layer) for a copy to modify).)doc")
        .def("__getitem__",
             [](const PyLayers& l, const std::string& name) { return layerArray(l.render, name); })
        .def("__len__",
             [](const PyLayers& l) { return l.render.cast<const PyRender&>().layers.size(); })
        .def("__iter__", [](const PyLayers& l) { return py::iter(layerNames(l)); })
        .def("__contains__",
             [](const PyLayers& l, py::handle name) {
                 return py::isinstance<py::str>(name) &&
                        l.render.cast<const PyRender&>().find(name.cast<std::string>()) != nullptr;
             })
        .def("keys", &layerNames)
        .def("values",
             [](const PyLayers& l) {
                 py::list out;
                 for (const py::handle name : layerNames(l))
                     out.append(layerArray(l.render, name.cast<std::string>()));
                 return out;
             })
        .def("items",
             [](const PyLayers& l) {
                 py::list out;
                 for (const py::handle name : layerNames(l))
                     out.append(
                         py::make_tuple(name, layerArray(l.render, name.cast<std::string>())));
                 return out;
             })
        .def(
            "get",
            [](const PyLayers& l, const std::string& name, py::object otherwise) -> py::object {
                if (!l.render.cast<const PyRender&>().find(name))
                    return otherwise;
                return layerArray(l.render, name);
            },
            py::arg("name"), py::arg("default") = py::none())
        .def("__repr__", [](const PyLayers& l) {
            return strCat("hairvox.Layers(", py::repr(layerNames(l)).cast<std::string>(), ")");
        });

    py::class_<PyRender>(m, "Render", R"doc(A finished render: its layers, its report, and save().

Made by hairvox.render(); holds the film until it is dropped.)doc")
        .def_property_readonly(
            "layers", [](py::object self) { return PyLayers{self}; },
            "The film's layers as numpy arrays (a Layers mapping; see its doc).")
        .def_property_readonly(
            "report", [](const PyRender& r) { return reportOf(r); },
            R"doc(What the render did: time per stage ("times"), each light (skipped,
reused, preparation, queries), the rasterizer's or the path tracer's counts
(what was skipped), the grid, warnings, and "text", the CLI's closing report.)doc")
        .def_property_readonly("width", [](const PyRender& r) { return r.render.film.width(); })
        .def_property_readonly("height", [](const PyRender& r) { return r.render.film.height(); })
        .def_property_readonly("scene_name", [](const PyRender& r) { return r.scene.name; })
        .def_property_readonly("warnings", [](const PyRender& r) { return r.render.warnings; })
        .def(
            "save",
            [](const PyRender& r, py::handle path, py::handle exr, py::handle png) {
                Scene scene = r.scene;
                scene.output = resolveOutputs(r, path, exr, png);
                const std::vector<std::filesystem::path> written = longCall(Progress{}, [&] {
                    return writeOutputs(r.render.film, scene, r.render.outputAttributes);
                });
                std::vector<std::string> out;
                for (const auto& p : written)
                    out.push_back(p.string());
                return out;
            },
            py::arg("path") = py::none(), py::kw_only(), py::arg("exr") = py::none(),
            py::arg("png") = py::none(),
            R"doc(Writes the EXR (beauty and AOVs, the CLI's attributes) and/or the PNG preview,
the same bytes `hairvox render` writes for the scene, atomically.

save() writes the scene's outputs (output.exr and output.png); save(path)
writes the one output its extension (.exr or .png) names; exr= and png= name
each. Returns the paths written. Never overwrites the scene or groom file.)doc")
        .def(
            "preview",
            [](const PyRender& r, py::handle exposure, py::handle toneMap) {
                const float stops = exposure.is_none()
                                        ? r.scene.output.exposure
                                        : float(numberArg(exposure, "exposure", -20, 20));
                const ToneMap map = toneMap.is_none() ? r.scene.output.toneMap
                                                      : enumArg(toneMap, "tone_map", kToneMapNames);
                const std::vector<std::uint8_t> pixels = previewPixels(r.render.film, stops, map);
                py::array_t<std::uint8_t> out({r.render.film.height(), r.render.film.width(), 3});
                std::memcpy(out.mutable_data(), pixels.data(), pixels.size());
                return out;
            },
            py::arg("exposure") = py::none(), py::arg("tone_map") = py::none(),
            R"doc(The PNG preview's pixels: uint8 (height, width, 3) sRGB, tone-mapped
("filmic" or "clamp") at the scene's exposure unless given (stops). A new array.)doc")
        .def("__repr__", [](const PyRender& r) {
            return strCat("hairvox.Render(", r.scene.name, ", ", toString(r.scene.integrator), ", ",
                          r.render.film.width(), "x", r.render.film.height(), ", ", r.layers.size(),
                          " layers)");
        });

    py::class_<FrameReuse>(m, "FrameReuse", R"doc(What consecutive renders share: pass the same
FrameReuse to render(reuse=...) and each render takes from the one before the
fiber grid and the lights' preparation wherever what they are made of is
unchanged (keys are contents: the groom's points, the lights, the settings),
as `hairvox render a.json b.json ...` does for a sequence. A sweep over
colour keeps the grid; a turntable keeps the grid and the lights. The images
are the same bytes as rendered alone. Holds one render's groom, grid and
light terms between calls; drop it to free them.)doc")
        .def(py::init<>());

    m.def(
        "default_scene",
        [] { return py::module_::import("json").attr("loads")(std::string(defaultSceneJson())); },
        R"doc(The embedded default scene (data/scenes/default.json) as a dict in the scene
file's schema: a starting point to change and pass to render().)doc");

    m.def(
        "read_exr",
        [](py::handle path) {
            const std::filesystem::path p = pathArg(path, "path");
            SceneRender image;
            image.film = longCall(Progress{}, [&] { return filmFromExr(readExr(p)); });
            Scene scene;
            scene.name = p.string();
            const py::object holder =
                py::cast(std::make_unique<PyRender>(std::move(scene), p, std::move(image)));
            py::dict out;
            for (const LayerMap& layer : holder.cast<const PyRender&>().layers)
                out[py::str(layer.name)] = layerArray(holder, layer.name);
            return out;
        },
        py::arg("path"),
        R"doc(The layers of an EXR file as Render.layers names them ("beauty" RGBA, the
AOVs by their EXR names), float32 (height, width, channels) read-only arrays.
ValueError naming the file if it cannot be read.)doc");

    m.def(
        "render",
        [](py::object sceneArg, py::object width, py::object height, py::object integrator,
           py::object mode, py::object spp, py::object seed, py::object threads,
           py::object progressArg, py::object reuseArg) {
            Scene scene = sceneOf(sceneArg);
            const std::filesystem::path sceneFile =
                isPathLike(sceneArg) ? pathArg(sceneArg, "scene") : std::filesystem::path();
            applyOverrides(scene, width, height, integrator, mode, spp, seed);
            PipelineOptions options;
            if (!threads.is_none())
                options.threads = int(intArg(threads, "threads", 0, 1024));
            const Progress progress = Progress::from(progressArg);
            options.progress = progress.bars;
            FrameReuse* reuse = nullptr;
            if (!reuseArg.is_none()) {
                if (!py::isinstance<FrameReuse>(reuseArg))
                    throw InputError(strCat("reuse: expected None or a hairvox.FrameReuse, got ",
                                            typeName(reuseArg)));
                reuse = &reuseArg.cast<FrameReuse&>();
            }
            SceneRender rendered =
                longCall(progress, [&] { return renderScene(scene, options, false, reuse); });
            if (rendered.pathTrace && rendered.pathTrace->interrupted)
                throw Interrupted(strCat("interrupted after ", rendered.pathTrace->spp,
                                         " samples per pixel; nothing was saved"));
            for (const std::string& w : rendered.warnings)
                warn(w);
            return std::make_unique<PyRender>(std::move(scene), sceneFile, std::move(rendered));
        },
        py::arg("scene") = py::none(), py::kw_only(), py::arg("width") = py::none(),
        py::arg("height") = py::none(), py::arg("integrator") = py::none(),
        py::arg("mode") = py::none(), py::arg("spp") = py::none(), py::arg("seed") = py::none(),
        py::arg("threads") = py::none(), py::arg("progress") = py::none(),
        py::arg("reuse") = py::none(),
        R"doc(Renders a scene; returns a Render (nothing is written until Render.save()).

scene: None (the embedded default scene), a scene file path, a dict in the
scene file's schema (docs/scene.md; a hairvox.Groom may stand in place of
the groom file), or a hairvox.Groom alone (the default scene's settings).
width, height: pixels, [1, 8192]; one alone keeps the camera's aspect ratio.
integrator: "dual_scattering", "volumetric" or "path" (the scene schema's names).
mode: the global-term mode, "exact", "grid" or "approx".
spp: the path integrator's samples per pixel; seed: the path or volumetric
integrator's seed.
threads: worker threads (0 or None: all cores).
progress: None, True (the CLI's bars on stderr) or a callable
(stage, done, total), called on this thread while the render runs.
reuse: a FrameReuse shared by consecutive renders (the dual-scattering
integrator takes the grid and lights of the render before where unchanged).

The GIL is released while rendering. Ctrl-C raises KeyboardInterrupt once the
render has stopped; bad input raises ValueError with the CLI's message.)doc");
}

} // namespace hairvox::python
