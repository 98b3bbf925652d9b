#include "bindings.h"

#include <hairvox/core/error.h>

#include <limits>

namespace hairvox::python {

namespace {

/// Deeper than any scene: a value that contains itself.
constexpr int kMaxDepth = 64;

/// What the JSON holds in place of an in-memory groom until the scene is
/// parsed (GroomSource::file, then cleared for GroomSource::inMemory).
constexpr const char* kGroomPlaceholder = "in-memory groom";

struct Converter {
    const std::string& source;
    std::shared_ptr<const Groom>* groom;

    [[noreturn]] void fail(const std::string& path, const std::string& what) const {
        throw InputError(strCat(source, ": ", path.empty() ? "/" : path, ": ", what));
    }

    nlohmann::json operator()(py::handle v, const std::string& path, int depth) const {
        if (depth > kMaxDepth)
            fail(path, "nested too deeply (a value that contains itself?)");
        if (v.is_none())
            return nullptr;
        if (py::isinstance<PyGroom>(v)) {
            if (!groom || (path != "/groom" && path != "/groom/file"))
                fail(path, "a hairvox.Groom goes in /groom (or /groom/file)");
            *groom = v.cast<const PyGroom&>().groom;
            return path == "/groom" ? nlohmann::json{{"file", kGroomPlaceholder}}
                                    : nlohmann::json(kGroomPlaceholder);
        }
        const py::module_ numpy = py::module_::import("numpy");
        if (py::isinstance<py::bool_>(v) || py::isinstance(v, numpy.attr("bool_")))
            return PyObject_IsTrue(v.ptr()) == 1;
        if (py::isinstance<py::int_>(v) || py::isinstance(v, numpy.attr("integer"))) {
            const py::int_ i = py::reinterpret_steal<py::int_>(PyNumber_Index(v.ptr()));
            if (!i)
                throw py::error_already_set();
            int overflow = 0;
            const long long s = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
            if (overflow == 0)
                return std::int64_t(s);
            const unsigned long long u = PyLong_AsUnsignedLongLong(i.ptr());
            if (!PyErr_Occurred())
                return std::uint64_t(u);
            PyErr_Clear();
            fail(path, strCat(py::repr(v).cast<std::string>(), " does not fit in 64 bits"));
        }
        if (py::isinstance<py::float_>(v) || py::isinstance(v, numpy.attr("floating")))
            return PyFloat_AsDouble(v.ptr()); // NaN and Inf: the scene reader names the range
        if (py::isinstance<py::str>(v))
            return v.cast<std::string>();
        if (py::hasattr(v, "__fspath__"))
            return py::module_::import("os").attr("fspath")(v).cast<std::string>();
        if (py::isinstance<py::dict>(v)) {
            nlohmann::json object = nlohmann::json::object();
            for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(v)) {
                if (!py::isinstance<py::str>(key))
                    fail(path,
                         strCat("key ", py::repr(key).cast<std::string>(), " is not a string"));
                const std::string k = key.cast<std::string>();
                object[k] = (*this)(value, path + "/" + k, depth + 1);
            }
            return object;
        }
        if (py::isinstance(v, numpy.attr("ndarray")))
            return (*this)(v.attr("tolist")(), path, depth);
        if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
            nlohmann::json array = nlohmann::json::array();
            std::size_t i = 0;
            for (const py::handle item : v)
                array.push_back((*this)(item, strCat(path, "/", i++), depth + 1));
            return array;
        }
        fail(path, strCat("a ", typeName(v),
                          " is not a value of the scene schema (expected a dict, list, str, "
                          "number, bool or None)"));
    }
};

} // namespace

nlohmann::json toJson(py::handle value, const std::string& source,
                      std::shared_ptr<const Groom>* groom) {
    return Converter{source, groom}(value, "", 0);
}

Scene defaultSceneWith(const std::string& key, const nlohmann::json& value,
                       const std::string& source) {
    nlohmann::json document = nlohmann::json::parse(defaultSceneJson());
    if (value.is_null())
        document.erase(key);
    else
        document[key] = value;
    return parseScene(document, source, "");
}

Scene sceneOf(py::handle value, const std::string& source) {
    if (value.is_none())
        return defaultScene();
    if (py::isinstance<PyGroom>(value)) {
        // As the CLI reads a groom file given instead of a scene
        // (cli/scene_input.h): the default scene's settings, without the
        // head and meshes that belong to the default groom, one hair per strand.
        Scene scene = defaultScene();
        scene.name = "groom";
        scene.head.reset();
        scene.meshes.clear();
        scene.fiberScale = FiberScale{};
        scene.groom.inMemory = value.cast<const PyGroom&>().groom;
        scene.validate();
        return scene;
    }
    if (isPathLike(value))
        return loadScene(pathArg(value, source));
    if (py::isinstance<py::dict>(value)) {
        std::shared_ptr<const Groom> groom;
        Scene scene = parseScene(toJson(value, source, &groom), source, "");
        if (groom) {
            scene.groom.file.clear();
            scene.groom.inMemory = std::move(groom);
        }
        return scene;
    }
    throw InputError(strCat(source,
                            ": expected None (the default scene), a scene file path, a "
                            "dict in the scene file's schema or a hairvox.Groom, got ",
                            typeName(value)));
}

Light lightOf(py::handle value, const Scene& scene, const std::string& name) {
    if (value.is_none()) {
        if (scene.lights.empty())
            throw InputError(strCat(name, ": ", scene.name, " has no lights; give one, e.g. ", name,
                                    "={\"type\": \"directional\", \"direction\": [0, 1, 0]}"));
        return scene.lights.front();
    }
    if (py::isinstance<py::str>(value)) {
        const std::string wanted = value.cast<std::string>();
        std::string names;
        for (const Light& l : scene.lights) {
            if (l.name == wanted)
                return l;
            names += (names.empty() ? "" : ", ") + l.name;
        }
        throw InputError(strCat(name, " = '", wanted, "': ", scene.name, " has no such light (",
                                names.empty() ? std::string("it has none") : "its lights: " + names,
                                ")"));
    }
    if (py::isinstance<py::dict>(value))
        return defaultSceneWith("lights", nlohmann::json::array({toJson(value, name)}), name)
            .lights.front();
    throw InputError(strCat(name,
                            ": expected a light name, a dict in the scene schema's light "
                            "form or None, got ",
                            typeName(value)));
}

} // namespace hairvox::python
