// OpenVDB grids handed to Debian's pyopenvdb (python3-openvdb) without a
// copy: pyopenvdb wraps grids with Boost.Python, whose converter registry
// lives in the shared libboost_python shared by both modules, so a
// shared_ptr to a grid built here converts to pyopenvdb's own grid object
// (what openvdb/python/pyopenvdb.h's getPyObjectFromGrid() does inside
// pyopenvdb). Both modules link the same libopenvdb, so the grid types are
// one. pyopenvdb must be imported first: its import registers the converters.
// Boost.Python stays in this file.
#define BOOST_ALLOW_DEPRECATED_HEADERS // Boost 1.74's Python headers include deprecated ones
#include "bindings.h"

#include <hairvox/core/error.h>

#include <openvdb/openvdb.h>

#include <boost/python/object.hpp>

namespace hairvox::python {

namespace {

template <typename GridT>
boost::python::object wrap(const openvdb::GridBase::Ptr& grid) {
    return boost::python::object(openvdb::gridPtrCast<GridT>(grid));
}

} // namespace

py::object toPyOpenVdb(const openvdb::GridBase::Ptr& grid) {
    try {
        py::module_::import("pyopenvdb");
    } catch (py::error_already_set& e) {
        throw std::runtime_error(strCat("to_openvdb() needs Debian's pyopenvdb (python3-openvdb, "
                                        "scripts/setup.sh) in this interpreter: ",
                                        e.what()));
    }
    boost::python::object object;
    try {
        if (grid->isType<openvdb::FloatGrid>())
            object = wrap<openvdb::FloatGrid>(grid);
        else if (grid->isType<openvdb::Vec3SGrid>())
            object = wrap<openvdb::Vec3SGrid>(grid);
        else
            throw std::runtime_error(strCat("to_openvdb: grid '", grid->getName(), "' of type ",
                                            grid->type(), " has no pyopenvdb type here"));
    } catch (const boost::python::error_already_set&) {
        throw py::error_already_set(); // the Python error Boost.Python left set
    }
    return py::reinterpret_borrow<py::object>(object.ptr());
}

} // namespace hairvox::python
