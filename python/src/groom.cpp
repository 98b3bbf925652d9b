// hairvox.Groom, hairvox.load_groom, hairvox.generate: grooms with numpy in
// and out (strands/groom.h), validated as the readers validate a file
// (sanitizeGroom: strands of at least 2 points, finite points; zero-length
// segments dropped with a warning), plus per-point thickness and colours
// checked where they are given.
#include "bindings.h"
#include "long_call.h"

#include <hairvox/core/error.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/strands/procedural.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace hairvox::python {

namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;

/// `value` as a C-contiguous float32 array of `columns` columns (0: 1-D) and
/// `rows` rows (SIZE_MAX: any); InputError naming `name` otherwise.
FloatArray floatArray(py::handle value, const std::string& name, std::size_t rows,
                      std::size_t columns) {
    const std::string shape = columns == 0
                                  ? (rows == SIZE_MAX ? "(N,)" : strCat("(", rows, ",)"))
                                  : (rows == SIZE_MAX ? strCat("(N, ", columns, ")")
                                                      : strCat("(", rows, ", ", columns, ")"));
    py::array a;
    try {
        a = py::array::ensure(value);
    } catch (const py::error_already_set&) {
    }
    if (!a || a.dtype().kind() == 'O' || a.dtype().kind() == 'U' || a.dtype().kind() == 'S' ||
        a.dtype().kind() == 'b' || a.dtype().kind() == 'c')
        throw InputError(strCat("hairvox.Groom: ", name, ": expected an array of numbers of shape ",
                                shape, ", got ", typeName(value)));
    const bool shapeOk =
        columns == 0 ? a.ndim() == 1 : a.ndim() == 2 && std::size_t(a.shape(1)) == columns;
    if (!shapeOk || (rows != SIZE_MAX && std::size_t(a.shape(0)) != rows)) {
        std::string got = "(";
        for (py::ssize_t d = 0; d < a.ndim(); ++d)
            got += strCat(d ? ", " : "", a.shape(d));
        throw InputError(strCat("hairvox.Groom: ", name, ": expected shape ", shape, ", got ", got,
                                a.ndim() == 1 ? ",)" : ")"));
    }
    return FloatArray::ensure(a);
}

/// Strand offsets: integers, S + 1 of them from 0 to the point count,
/// non-decreasing, each strand at least 2 points.
std::vector<std::uint32_t> strandOffsets(py::handle value, std::size_t points) {
    py::array a;
    try {
        a = py::array::ensure(value);
    } catch (const py::error_already_set&) {
    }
    if (!a || (a.dtype().kind() != 'i' && a.dtype().kind() != 'u') || a.ndim() != 1)
        throw InputError("hairvox.Groom: strand_offsets: expected a 1-D array of integers (S + 1 "
                         "offsets into points, from 0 to the point count)");
    const auto offsets =
        py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
    const std::int64_t* o = offsets.data();
    const auto n = std::size_t(offsets.size());
    if (n == 0 || o[0] != 0 || o[n - 1] != std::int64_t(points))
        throw InputError(
            strCat("hairvox.Groom: strand_offsets: expected S + 1 offsets from 0 to the ", points,
                   " points, got ", n, " offset(s) from ", n ? strCat(o[0]) : "-", " to ",
                   n ? strCat(o[n - 1]) : "-"));
    if (points > std::numeric_limits<std::uint32_t>::max())
        throw InputError(strCat("hairvox.Groom: points: ", points, " points, expected at most ",
                                std::numeric_limits<std::uint32_t>::max()));
    std::vector<std::uint32_t> out(n);
    for (std::size_t i = 0; i < n; ++i) {
        if (i > 0 && o[i] - o[i - 1] < 2)
            throw InputError(strCat("hairvox.Groom: strand_offsets: strand ", i - 1, " has ",
                                    o[i] - o[i - 1], " point(s) (offsets ", o[i - 1], " to ", o[i],
                                    "); a strand needs at least 2"));
        out[i] = static_cast<std::uint32_t>(o[i]);
    }
    return out;
}

/// The strand and point within it of global point i, for messages.
std::string pointName(const Groom& g, std::size_t i) {
    const auto it = std::upper_bound(g.strandStart.begin(), g.strandStart.end(), i);
    const auto s = std::size_t(it - g.strandStart.begin()) - 1;
    return strCat("strand ", s, ", point ", i - g.strandStart[s]);
}

void warnAll(const std::vector<std::string>& warnings, const std::string& source) {
    for (const std::string& w : warnings)
        warn(strCat(source, ": ", w));
}

std::vector<std::string> sanitizeWarnings(const SanitizeReport& report) {
    std::vector<std::string> out;
    if (report.droppedSegments > 0)
        out.push_back(strCat("dropped ", report.droppedSegments, " zero-length segment(s)"));
    if (report.droppedStrands > 0)
        out.push_back(strCat("dropped ", report.droppedStrands, " degenerate strand(s)"));
    return out;
}

PyGroom makeGroom(py::handle points, py::handle strandOffsetsArg, py::handle thickness,
                  py::handle colors) {
    auto groom = std::make_shared<Groom>();
    const FloatArray p = floatArray(points, "points", SIZE_MAX, 3);
    const auto n = std::size_t(p.shape(0));
    groom->strandStart = strandOffsets(strandOffsetsArg, n);
    groom->points.resize(n);
    std::copy_n(p.data(), 3 * n, &groom->points.data()->x);
    if (!thickness.is_none()) {
        const FloatArray t = floatArray(thickness, "thickness", n, 0);
        groom->thickness.assign(t.data(), t.data() + n);
        for (std::size_t i = 0; i < n; ++i)
            if (!(std::isfinite(groom->thickness[i]) && groom->thickness[i] >= 0))
                throw InputError(strCat("hairvox.Groom: thickness: ", pointName(*groom, i), ": ",
                                        groom->thickness[i],
                                        "; expected a finite diameter >= 0 (scene units)"));
    }
    if (!colors.is_none()) {
        const FloatArray c = floatArray(colors, "colors", n, 3);
        groom->color.resize(n);
        std::copy_n(c.data(), 3 * n, &groom->color.data()->r);
        for (std::size_t i = 0; i < n; ++i) {
            const Rgb& rgb = groom->color[i];
            if (!(rgb.r >= 0 && rgb.g >= 0 && rgb.b >= 0 && std::isfinite(rgb.r + rgb.g + rgb.b)))
                throw InputError(strCat("hairvox.Groom: colors: ", pointName(*groom, i), ": ", rgb,
                                        "; expected finite linear RGB >= 0"));
        }
    }
    const SanitizeReport report = sanitizeGroom(*groom, "hairvox.Groom: points");
    warnAll(sanitizeWarnings(report), "hairvox.Groom");
    return PyGroom{std::move(groom)};
}

py::object optionalView(const std::vector<float>& values, std::size_t columns, py::handle owner) {
    if (values.empty())
        return py::none();
    const auto rows = py::ssize_t(values.size() / columns);
    if (columns == 1)
        return view(values.data(), {rows}, {4}, owner);
    return view(values.data(), {rows, py::ssize_t(columns)}, {py::ssize_t(4 * columns), 4}, owner);
}

py::dict statsOf(const Groom& groom) {
    const GroomStats st = computeStats(groom);
    py::dict d;
    d["strands"] = st.strands;
    d["points"] = st.points;
    d["segments"] = st.segments;
    d["bounds"] = py::make_tuple(py::make_tuple(st.bounds.min.x, st.bounds.min.y, st.bounds.min.z),
                                 py::make_tuple(st.bounds.max.x, st.bounds.max.y, st.bounds.max.z));
    d["total_length"] = st.totalLength;
    d["mean_segment_length"] = st.meanSegmentLength;
    d["min_segment_length"] = st.minSegmentLength;
    d["max_segment_length"] = st.maxSegmentLength;
    return d;
}

} // namespace

void bindGroom(py::module_& m) {
    py::class_<PyGroom>(m, "Groom", R"doc(A groom: strands as polylines, root to tip, with optional
per-point thickness (fiber diameter in scene units) and colour (linear RGB).

Built from numpy arrays (copied into the groom, which is immutable after):
points (N, 3), strand_offsets (S + 1 integers: strand i is
points[strand_offsets[i]:strand_offsets[i + 1]]), thickness (N,) and colors
(N, 3). Validated as a groom file's reader validates: every strand at least
2 points, every coordinate finite (ValueError naming the field, strand and
point); zero-length segments are dropped with a HairvoxWarning. The arrays it
returns are read-only views of the groom (no copy).

In a scene dict, a Groom stands in place of a groom file:
{"groom": groom, ...} or {"groom": {"file": groom, "color": "ignore"}, ...}.)doc")
        .def(py::init(&makeGroom), py::arg("points"), py::arg("strand_offsets"),
             py::arg("thickness") = py::none(), py::arg("colors") = py::none())
        .def_property_readonly(
            "points",
            [](py::object self) {
                const Groom& g = *self.cast<const PyGroom&>().groom;
                return view(&g.points.data()->x, {py::ssize_t(g.pointCount()), 3}, {12, 4}, self);
            },
            "(N, 3) float32: the points, strand after strand (a read-only view)")
        .def_property_readonly(
            "strand_offsets",
            [](py::object self) {
                const Groom& g = *self.cast<const PyGroom&>().groom;
                return view(g.strandStart.data(), {py::ssize_t(g.strandStart.size())}, {4}, self);
            },
            "(S + 1,) uint32: strand i is points[strand_offsets[i]:strand_offsets[i + 1]]")
        .def_property_readonly(
            "thickness",
            [](py::object self) {
                return optionalView(self.cast<const PyGroom&>().groom->thickness, 1, self);
            },
            "(N,) float32 per-point fiber diameter, or None")
        .def_property_readonly(
            "colors",
            [](py::object self) {
                const Groom& g = *self.cast<const PyGroom&>().groom;
                if (g.color.empty())
                    return py::object(py::none());
                return py::object(
                    view(&g.color.data()->r, {py::ssize_t(g.pointCount()), 3}, {12, 4}, self));
            },
            "(N, 3) float32 per-point linear RGB colour, or None")
        .def_property_readonly(
            "transparency",
            [](py::object self) {
                return optionalView(self.cast<const PyGroom&>().groom->transparency, 1, self);
            },
            "(N,) float32 per-point transparency from a .hair file, or None (not rendered)")
        .def_property_readonly("strand_count",
                               [](const PyGroom& g) { return g.groom->strandCount(); })
        .def_property_readonly("point_count",
                               [](const PyGroom& g) { return g.groom->pointCount(); })
        .def_property_readonly("segment_count",
                               [](const PyGroom& g) { return g.groom->segmentCount(); })
        .def("__len__", [](const PyGroom& g) { return g.groom->strandCount(); })
        .def(
            "strand",
            [](py::object self, std::int64_t i) {
                const Groom& g = *self.cast<const PyGroom&>().groom;
                const auto s = std::size_t(
                    intArg(py::int_(i), "strand", 0, std::int64_t(g.strandCount()) - 1));
                const auto points = g.strand(s);
                return view(&points.data()->x, {py::ssize_t(points.size()), 3}, {12, 4}, self);
            },
            py::arg("index"), "The points of strand `index` ((n, 3) read-only view).")
        .def(
            "stats", [](const PyGroom& g) { return statsOf(*g.groom); },
            "Strands, points, segments, bounds and lengths (what `hairvox info` prints).")
        .def(
            "save",
            [](const PyGroom& g, py::handle path) {
                const std::filesystem::path p = pathArg(path, "path");
                writeHairFile(p, *g.groom); // atomic
            },
            py::arg("path"),
            "Writes the groom as a Cem Yuksel .hair file (atomically), with its attributes.")
        .def("__repr__", [](const PyGroom& g) {
            return strCat("hairvox.Groom(", g.groom->strandCount(), " strands, ",
                          g.groom->pointCount(), " points",
                          g.groom->thickness.empty() ? "" : ", thickness",
                          g.groom->color.empty() ? "" : ", colors", ")");
        });

    m.def(
        "load_groom",
        [](py::handle path) {
            const std::filesystem::path p = pathArg(path, "path");
            LoadedGroom loaded = longCall(Progress{}, [&] { return readGroom(p); });
            std::vector<std::string> warnings = loaded.warnings;
            for (std::string& w : sanitizeWarnings(loaded.sanitized))
                warnings.push_back(std::move(w));
            warnAll(warnings, p.string());
            return PyGroom{std::make_shared<const Groom>(std::move(loaded.groom))};
        },
        py::arg("path"),
        R"doc(Reads a groom file: Cem Yuksel .hair, AMD TressFX .tfx or OBJ polylines.

Bad files raise ValueError naming the file and what is wrong (the CLI's
message); what the reader dropped is reported as HairvoxWarning.)doc");

    m.def(
        "generate",
        [](py::handle style, py::kwargs params) {
            py::dict procedural;
            procedural["style"] = style;
            for (const auto& [key, value] : params)
                procedural[key] = value;
            const Scene scene = defaultSceneWith(
                "groom", nlohmann::json{{"procedural", toJson(procedural, "generate")}},
                "generate");
            const ProceduralGroomParams p = scene.groom.procedural;
            return PyGroom{std::make_shared<const Groom>(
                longCall(Progress{}, [&] { return generateGroom(p); }))};
        },
        py::arg("style") = "wavy",
        R"doc(A procedural groom on a head sphere, as `hairvox generate` and a scene's
groom.procedural make it: style "straight", "wavy" or "curly", and any key of
the scene schema's procedural groom (strands, points_per_strand, seed,
length, length_variation, wave_amplitude, wave_length, curl_radius,
curl_pitch, clump_strength, colors, head_center, head_radius).
Deterministic by seed.)doc");
}

} // namespace hairvox::python
