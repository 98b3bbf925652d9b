// The extension module hairvox._hairvox, which the package hairvox
// (python/hairvox/__init__.py) re-exports: docs/python.md is its manual.
#include "bindings.h"

#include <hairvox/core/version.h>

#include <openvdb/openvdb.h>

namespace hairvox::python {

namespace {

/// hairvox.HairvoxWarning, created once with the module (never freed: the
/// module lives as long as the interpreter).
PyObject* gWarning = nullptr;

} // namespace

void warn(const std::string& message) {
    if (PyErr_WarnEx(gWarning, message.c_str(), 1) != 0)
        throw py::error_already_set(); // the warnings filter made it an error
}

} // namespace hairvox::python

PYBIND11_MODULE(_hairvox, m) {
    using namespace hairvox::python;
    m.doc() = "hairvox: hair rendering with a voxel-grid dual-scattering global term "
              "(the C++ libraries; use the package `hairvox`).";
    openvdb::initialize();
    gWarning = PyErr_NewExceptionWithDoc(
        "hairvox.HairvoxWarning",
        "What a hairvox call reports and goes on (dropped segments, a light that lights "
        "nothing, ...): the CLI's warnings.",
        PyExc_UserWarning, nullptr);
    if (!gWarning)
        throw py::error_already_set();
    m.attr("HairvoxWarning") = py::handle(gWarning);
    m.attr("__version__") = hairvox::version();
    bindLongCalls(m);
    bindGroom(m);
    bindRender(m);
    bindGrids(m);
    bindTables(m);
    bindCompare(m);
}
