// hairvox Python module: what the binding files share — argument checking
// (arguments.cpp), scenes from Python values (scene_input.cpp), long calls
// with the GIL released (long_call.cpp), numpy views, the OpenVDB hand-off
// (openvdb_handoff.cpp) — and each file's bind function (module.cpp calls them).
//
// Conventions of the whole module (docs/python.md):
//  - bad input raises ValueError with the CLI's message (hairvox::InputError,
//    naming the field and the valid range); wrong Python values for a keyword
//    are bad input too, named after the keyword; internal errors raise
//    RuntimeError; an interrupted call raises KeyboardInterrupt;
//  - arrays the module returns are numpy views of the library's own memory
//    (read-only, kept alive by the object that owns it), never copies, except
//    where a value is computed for the call (documented per property).
#pragma once

#include <hairvox/core/error.h>
#include <hairvox/film/film.h>
#include <hairvox/pipeline/scene.h>
#include <hairvox/strands/groom.h>

#include <nlohmann/json.hpp>
#include <openvdb/Grid.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <string>
#include <vector>

namespace hairvox::python {

namespace py = pybind11;

// --- arguments (arguments.cpp) ----------------------------------------------
// Each throws InputError naming `name` and the valid range, e.g.
//   "width = 0: expected an integer in [1, 8192]".

/// An integer (a Python int or numpy integer, not a bool or a float) in [lo, hi].
std::int64_t intArg(py::handle value, const std::string& name, std::int64_t lo, std::int64_t hi);
/// A finite number in [lo, hi].
double numberArg(py::handle value, const std::string& name, double lo, double hi);
/// A Python bool.
bool boolArg(py::handle value, const std::string& name);
/// A str.
std::string strArg(py::handle value, const std::string& name);
/// A str or os.PathLike (os.fspath).
std::filesystem::path pathArg(py::handle value, const std::string& name);
bool isPathLike(py::handle value);
/// One of an enum's names (EnumNames::parse), e.g. "mode = 'fast': expected one of exact, grid,
/// approx".
template <typename Names>
auto enumArg(py::handle value, const std::string& name, const Names& names) {
    const std::string text = strArg(value, name);
    if (const auto parsed = names.parse(text))
        return *parsed;
    std::string valid;
    for (const std::string& n : names.names())
        valid += (valid.empty() ? "" : ", ") + n;
    throw InputError(name + " = '" + text + "': expected one of " + valid);
}
/// The Python type's name, for messages.
std::string typeName(py::handle value);

// --- numpy ----------------------------------------------------------------

/// A read-only array of `shape` (strides in bytes) viewing `data`, which
/// `owner` keeps alive.
template <typename T>
py::array view(const T* data, std::vector<py::ssize_t> shape, std::vector<py::ssize_t> strides,
               py::handle owner) {
    py::array a(py::dtype::of<T>(), std::move(shape), std::move(strides), data, owner);
    py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
    return a;
}

/// A read-only array viewing `data`, kept alive by a capsule that owns `holder`.
template <typename T, typename Holder>
py::array viewOwnedBy(const T* data, std::vector<py::ssize_t> shape,
                      std::vector<py::ssize_t> strides, std::shared_ptr<Holder> holder) {
    py::capsule owner(new std::shared_ptr<Holder>(std::move(holder)),
                      [](void* p) { delete static_cast<std::shared_ptr<Holder>*>(p); });
    return view(data, std::move(shape), std::move(strides), owner);
}

// --- scenes (scene_input.cpp) -------------------------------------------------

/// A hairvox.Groom: the groom, shared with every scene it is put in.
struct PyGroom {
    std::shared_ptr<const Groom> groom;
};

/// A Python value in the scene file's schema as JSON: dicts, lists and
/// tuples, str, int, float, bool, None, numpy scalars and arrays, os.PathLike
/// (a string). A hairvox.Groom at /groom or /groom/file is taken out into
/// `groom` (the JSON gets a placeholder file). InputError naming `source` and
/// the JSON path of a value that is none of these.
nlohmann::json toJson(py::handle value, const std::string& source,
                      std::shared_ptr<const Groom>* groom = nullptr);

/// The scene a Python value names: None (the embedded default scene), a
/// path (str or os.PathLike: a scene file), a dict in the scene file's schema
/// (relative paths against the working directory; named `source` in
/// messages), or a hairvox.Groom (the default scene's settings without its
/// head and meshes, one hair per strand: what the CLI makes of a groom file).
Scene sceneOf(py::handle value, const std::string& source = "scene");

/// A light in the scene schema's form (a dict, parsed by the scene reader:
/// its messages name `name`), or the name of one of `scene`'s lights; None:
/// the scene's first light.
Light lightOf(py::handle value, const Scene& scene, const std::string& name = "light");

/// The default scene's JSON with `key` replaced by `value` (or removed when
/// null), parsed under `source`: how the functions that take one part of a
/// scene (a fiber, a light, a procedural groom) read it with the scene's
/// validation and messages.
Scene defaultSceneWith(const std::string& key, const nlohmann::json& value,
                       const std::string& source);

// --- warnings and OpenVDB ---------------------------------------------------

/// Issues a hairvox.HairvoxWarning (a UserWarning) with `message`.
void warn(const std::string& message);

/// pyopenvdb's grid object for `grid`, sharing it (openvdb_handoff.cpp):
/// RuntimeError if Debian's python3-openvdb cannot be imported.
py::object toPyOpenVdb(const openvdb::GridBase::Ptr& grid);

// --- films (render.cpp) -------------------------------------------------------

/// The film of a hairvox.Render, or null for any other value.
const Film* filmOf(py::handle value);

// --- bind functions (one per file) -----------------------------------------

void bindLongCalls(py::module_& m);
void bindGroom(py::module_& m);
void bindRender(py::module_& m);
void bindGrids(py::module_& m);
void bindTables(py::module_& m);
void bindCompare(py::module_& m);

} // namespace hairvox::python
