#include "bindings.h"

#include <hairvox/core/error.h>

#include <cmath>
#include <limits>

namespace hairvox::python {

namespace {

/// "[lo, hi]" as the scene reader writes ranges.
template <typename T>
std::string range(T lo, T hi) {
    return strCat("[", lo, ", ", hi, "]");
}

std::string shown(py::handle value) {
    std::string text = py::repr(value).cast<std::string>();
    if (text.size() > 60)
        text = text.substr(0, 57) + "...";
    return text;
}

bool isNumpyScalar(py::handle value, const char* kind) {
    const py::module_ numpy = py::module_::import("numpy");
    return py::isinstance(value, numpy.attr(kind));
}

} // namespace

std::string typeName(py::handle value) {
    return py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>();
}

std::int64_t intArg(py::handle value, const std::string& name, std::int64_t lo, std::int64_t hi) {
    const bool integer = (py::isinstance<py::int_>(value) && !py::isinstance<py::bool_>(value)) ||
                         isNumpyScalar(value, "integer");
    if (integer) {
        // Beyond 64 bits, Python raises OverflowError: out of range as well.
        const py::int_ i = py::reinterpret_steal<py::int_>(PyNumber_Index(value.ptr()));
        long long v = 0;
        int overflow = 0;
        if (i)
            v = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
        PyErr_Clear();
        if (i && overflow == 0 && v >= lo && v <= hi)
            return v;
    }
    throw InputError(strCat(name, " = ", shown(value), ": expected an integer in ", range(lo, hi)));
}

double numberArg(py::handle value, const std::string& name, double lo, double hi) {
    const bool number = (py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value) ||
                         isNumpyScalar(value, "integer") || isNumpyScalar(value, "floating")) &&
                        !py::isinstance<py::bool_>(value);
    if (number) {
        const double v = PyFloat_AsDouble(value.ptr());
        PyErr_Clear();
        if (std::isfinite(v) && v >= lo && v <= hi)
            return v;
    }
    throw InputError(strCat(name, " = ", shown(value), ": expected a number in ", range(lo, hi)));
}

bool boolArg(py::handle value, const std::string& name) {
    if (py::isinstance<py::bool_>(value) || isNumpyScalar(value, "bool_"))
        return PyObject_IsTrue(value.ptr()) == 1;
    throw InputError(strCat(name, " = ", shown(value), ": expected True or False"));
}

std::string strArg(py::handle value, const std::string& name) {
    if (py::isinstance<py::str>(value))
        return value.cast<std::string>();
    throw InputError(
        strCat(name, " = ", shown(value), ": expected a string, got ", typeName(value)));
}

bool isPathLike(py::handle value) {
    return py::isinstance<py::str>(value) || py::hasattr(value, "__fspath__");
}

std::filesystem::path pathArg(py::handle value, const std::string& name) {
    if (isPathLike(value)) {
        const py::object path = py::module_::import("os").attr("fspath")(value);
        if (py::isinstance<py::str>(path)) {
            const std::string text = path.cast<std::string>();
            if (!text.empty())
                return text;
        }
    }
    throw InputError(
        strCat(name, " = ", shown(value), ": expected a path (a non-empty str or os.PathLike)"));
}

} // namespace hairvox::python
