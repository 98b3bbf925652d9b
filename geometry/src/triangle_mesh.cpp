#include <hairvox/core/error.h>
#include <hairvox/core/format.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/math.h>
#include <hairvox/geometry/triangle_mesh.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <tbb/parallel_for.h>
#include <tiny_obj_loader.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <span>

namespace hairvox {

Bounds3f TriangleMesh::bounds() const {
    Bounds3f b;
    for (const Vec3f& p : positions)
        b.extend(p);
    return b;
}

std::uint64_t TriangleMesh::contentHash() const {
    Hasher h;
    h.values(std::span<const Vec3f>(positions));
    h.values(std::span<const std::array<std::uint32_t, 3>>(triangles));
    h.values(std::span<const Vec3f>(cornerNormals));
    return h.digest();
}

bool MeshTransform::isIdentity() const {
    return scale == Vec3f(1.0f) && rotateDegrees == Vec3f(0.0f) && translate == Vec3f(0.0f);
}

void MeshTransform::apply(TriangleMesh& mesh) const {
    if (isIdentity())
        return;
    glm::mat4 m = glm::translate(glm::mat4(1.0f), translate);
    m = glm::rotate(m, glm::radians(rotateDegrees.z), Vec3f(0, 0, 1));
    m = glm::rotate(m, glm::radians(rotateDegrees.y), Vec3f(0, 1, 0));
    m = glm::rotate(m, glm::radians(rotateDegrees.x), Vec3f(1, 0, 0));
    m = glm::scale(m, scale);
    for (Vec3f& p : mesh.positions)
        p = Vec3f(m * glm::vec4(p, 1.0f));
    const glm::mat3 normalMatrix = glm::transpose(glm::inverse(glm::mat3(m)));
    for (Vec3f& n : mesh.cornerNormals)
        n = normalizeOr(normalMatrix * n, n);
    // A mirroring scale flips the winding; keep the geometric normals outward.
    if (scale.x * scale.y * scale.z < 0)
        for (auto& t : mesh.triangles)
            std::swap(t[1], t[2]);
}

namespace {

/// The lines of an OBJ text that tinyobjloader would misread, checked before
/// it reads them: coordinates that are not finite numbers and face indices
/// out of range (tinyobjloader turns "nan" into 0 and keeps such indices).
/// The coordinates of `v` and `vn` lines are kept as parsed here, correctly
/// rounded (std::from_chars): tinyobjloader's own number parser accumulates
/// digits in a double, so a long number such as 1 followed by 400 zeros and
/// "e-399" reads as infinity and 0.(400 zeros)1e400 as 0 (found by fuzz_mesh).
/// tinyobjloader supplies the faces only.
class ObjValidator {
public:
    explicit ObjValidator(const std::string& name) : name_(name) {}

    std::vector<Vec3f> positions, normals;

    void line(std::string_view text, std::size_t number) {
        text = trim(text);
        if (text.starts_with("v ") || text.starts_with("v\t"))
            positions.push_back(vertex(text.substr(2), number));
        else if (text.starts_with("vn ") || text.starts_with("vn\t"))
            normals.push_back(vertex(text.substr(3), number));
        else if (text.starts_with("vt ") || text.starts_with("vt\t"))
            ++texcoords_;
        else if (text.starts_with("f ") || text.starts_with("f\t"))
            face(text.substr(2), number);
    }

private:
    static std::string_view trim(std::string_view s) {
        while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
            s.remove_prefix(1);
        while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
            s.remove_suffix(1);
        return s;
    }
    static std::string_view nextToken(std::string_view& s) {
        s = trim(s);
        const std::size_t end = s.find_first_of(" \t");
        const std::string_view token = s.substr(0, end);
        s = end == std::string_view::npos ? std::string_view{} : s.substr(end);
        return token;
    }
    [[noreturn]] void fail(std::size_t number, const std::string& what) const {
        throw InputError(strCat(name_, ": line ", number, ": ", what));
    }

    Vec3f vertex(std::string_view rest, std::size_t number) {
        Vec3f v;
        for (int k = 0; k < 3; ++k) {
            const std::string_view token = nextToken(rest);
            double value = 0;
            const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
            if (token.empty() || ec != std::errc() || end != token.data() + token.size() ||
                !std::isfinite(value) || std::abs(value) > double(std::numeric_limits<float>::max()))
                fail(number, strCat("coordinate ", k + 1, " is \"", token,
                                    "\": expected a finite number"));
            v[k] = static_cast<float>(value);
        }
        return v;
    }

    /// One index of a face corner: 1-based, or negative (relative to the end).
    void index(std::string_view token, std::uint64_t count, const char* what, std::size_t number) {
        long long i = 0;
        const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), i);
        if (ec != std::errc() || end != token.data() + token.size())
            fail(number, strCat(what, " index \"", token, "\" is not an integer"));
        const long long resolved = i < 0 ? static_cast<long long>(count) + i : i - 1;
        if (i == 0 || resolved < 0 || resolved >= static_cast<long long>(count))
            fail(number, strCat(what, " index ", i, " is out of range: ", count, " ", what,
                                "(s) defined before this line"));
    }

    void face(std::string_view rest, std::size_t number) {
        int corners = 0;
        for (std::string_view token = nextToken(rest); !token.empty(); token = nextToken(rest)) {
            ++corners;
            const std::size_t s1 = token.find('/');
            index(token.substr(0, s1), positions.size(), "vertex", number);
            if (s1 == std::string_view::npos)
                continue;
            const std::string_view after = token.substr(s1 + 1);
            const std::size_t s2 = after.find('/');
            if (const std::string_view t = after.substr(0, s2); !t.empty())
                index(t, texcoords_, "texture coordinate", number);
            if (s2 != std::string_view::npos)
                index(after.substr(s2 + 1), normals.size(), "normal", number);
        }
        if (corners < 3)
            fail(number, strCat("a face needs at least 3 corners, this one has ", corners));
    }

    const std::string& name_;
    std::uint64_t texcoords_ = 0;
};

/// Checks every line (they end at '\n' or '\r' as tinyobjloader splits
/// them, a lone '\r' too; messages count '\n' lines) and returns the
/// validator with the positions and normals it parsed.
ObjValidator validateObjText(std::string_view text, const std::string& name) {
    ObjValidator validator(name);
    std::size_t number = 1;
    for (std::size_t start = 0; start < text.size();) {
        const std::size_t end = std::min(text.find_first_of("\r\n", start), text.size());
        validator.line(text.substr(start, end - start), number);
        if (end < text.size() && text[end] == '\n')
            ++number;
        start = end + 1;
    }
    return validator;
}

/// A unit normal from a finite vector of any magnitude (scaled first, so that
/// components near FLT_MAX do not overflow its length), or `fallback`.
Vec3f unitNormalOr(const Vec3f& n, const Vec3f& fallback) {
    const float largest = std::max({std::abs(n.x), std::abs(n.y), std::abs(n.z)});
    return largest > 0 ? normalizeOr(n / largest, fallback) : fallback;
}

} // namespace

LoadedMesh parseObjMesh(std::string_view text, const std::string& name) {
    ObjValidator parsed = validateObjText(text, name);
    tinyobj::ObjReaderConfig config;
    config.triangulate = false; // fanned below, so that a face stays one face
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    if (!reader.ParseFromString(std::string(text), std::string(), config))
        throw InputError(strCat(name, ": ", reader.Error()));
    const tinyobj::attrib_t& attrib = reader.GetAttrib();

    // The check above makes every index valid; this guards against the two
    // parsers ever disagreeing about a line.
    const auto inconsistent = [&] {
        return InputError(strCat(name, ": a face index names no vertex or normal"));
    };
    if (attrib.vertices.size() != 3 * parsed.positions.size() ||
        attrib.normals.size() != 3 * parsed.normals.size())
        throw inconsistent();

    LoadedMesh out;
    TriangleMesh& mesh = out.mesh;
    mesh.positions = std::move(parsed.positions);
    const std::size_t vertexCount = mesh.positions.size();
    const auto normalAt = [&](int index) {
        if (index < 0)
            return Vec3f(0.0f);
        return parsed.normals[static_cast<std::size_t>(index)];
    };

    std::uint64_t degenerate = 0, withoutNormals = 0, corners = 0;
    std::vector<tinyobj::index_t> face;
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        std::size_t offset = 0;
        for (const unsigned char faceCorners : shape.mesh.num_face_vertices) {
            face.assign(shape.mesh.indices.begin() + static_cast<std::ptrdiff_t>(offset),
                        shape.mesh.indices.begin() + static_cast<std::ptrdiff_t>(offset + faceCorners));
            offset += faceCorners;
            for (std::size_t k = 1; k + 1 < face.size(); ++k) {
                const std::array<tinyobj::index_t, 3> c{face[0], face[k], face[k + 1]};
                for (const tinyobj::index_t& corner : c)
                    if (corner.vertex_index < 0 ||
                        static_cast<std::size_t>(corner.vertex_index) >= vertexCount)
                        throw inconsistent();
                const std::array<std::uint32_t, 3> t{static_cast<std::uint32_t>(c[0].vertex_index),
                                                     static_cast<std::uint32_t>(c[1].vertex_index),
                                                     static_cast<std::uint32_t>(c[2].vertex_index)};
                const Vec3f& a = mesh.positions[t[0]];
                const Vec3f area = glm::cross(mesh.positions[t[1]] - a, mesh.positions[t[2]] - a);
                if (!isFinite(area))
                    throw InputError(strCat(name, ": a triangle's edges overflow single precision "
                                                  "(coordinates near ±3.4e38): not a usable mesh"));
                if (area == Vec3f(0.0f)) {
                    ++degenerate;
                    continue;
                }
                if (mesh.triangles.size() >= kMaxMeshTriangles)
                    throw InputError(strCat(name, ": more than ", kMaxMeshTriangles, " triangles"));
                mesh.triangles.push_back(t);
                const Vec3f geometric = unitNormalOr(area, Vec3f(0.0f, 0.0f, 1.0f));
                for (const tinyobj::index_t& corner : c) {
                    const Vec3f n = normalAt(corner.normal_index);
                    withoutNormals += corner.normal_index < 0 ? 1u : 0u;
                    ++corners;
                    mesh.cornerNormals.push_back(unitNormalOr(n, geometric));
                }
            }
        }
    }
    if (mesh.triangles.empty())
        throw InputError(strCat(name, ": no triangle of non-zero area (", vertexCount,
                                " vertices, ", degenerate, " degenerate triangles)"));
    if (withoutNormals == corners)
        mesh.cornerNormals.clear(); // no normals at all: geometric normals
    if (degenerate > 0)
        out.warnings.push_back(strCat(name, ": dropped ", thousands(degenerate),
                                      " triangle(s) of zero area"));
    if (withoutNormals > 0 && withoutNormals < corners)
        out.warnings.push_back(strCat(name, ": ", thousands(withoutNormals), " of ",
                                      thousands(corners),
                                      " face corners have no normal; they use their "
                                      "triangle's geometric normal"));
    if (!reader.GetShapes().empty()) {
        std::size_t lines = 0, points = 0;
        for (const tinyobj::shape_t& shape : reader.GetShapes()) {
            lines += shape.lines.num_line_vertices.size();
            points += shape.points.indices.size();
        }
        if (lines + points > 0)
            out.warnings.push_back(strCat(name, ": ignored ", lines, " line element(s) and ",
                                          points, " point element(s); only faces are surfaces"));
    }
    return out;
}

LoadedMesh readObjMesh(const std::filesystem::path& path) {
    const std::string name = path.string();
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec)
        throw InputError(strCat(name, ": cannot read the mesh: ", ec.message()));
    if (size > kMaxObjMeshBytes)
        throw InputError(strCat(name, ": ", size, " bytes, over the limit of ", kMaxObjMeshBytes,
                                " bytes for an OBJ mesh"));
    std::ifstream in(path, std::ios::binary);
    std::string text(size, '\0');
    if (!in || !in.read(text.data(), static_cast<std::streamsize>(size)))
        throw InputError(strCat(name, ": cannot read the mesh"));
    return parseObjMesh(text, name);
}

// --- the mannequin head ------------------------------------------------------

namespace {

/// Signed distance (approximate outside the spheres: Quilez's ellipsoid bound)
/// to the head in units of the cranium radius, cranium at the origin; y up,
/// the face toward +z.
class HeadShape {
public:
    float distance(const Vec3f& p) const {
        float d = glm::length(p) - 1.0f; // cranium
        d = smoothUnion(d, ellipsoid(p - Vec3f(0.0f, -0.40f, 0.22f), Vec3f(0.70f, 0.74f, 0.72f)), 0.18f);
        d = smoothUnion(d, ellipsoid(p - Vec3f(0.0f, -0.78f, 0.46f), Vec3f(0.36f, 0.26f, 0.36f)), 0.12f); // chin
        d = smoothUnion(d, ellipsoid(p - Vec3f(0.0f, -0.24f, 0.88f), Vec3f(0.08f, 0.14f, 0.13f)), 0.06f); // nose
        d = smoothUnion(d, neck(p), 0.16f);
        return d;
    }
    Vec3f normal(const Vec3f& p) const {
        constexpr float e = 1e-3f;
        return normalizeOr(Vec3f(distance(p + Vec3f(e, 0, 0)) - distance(p - Vec3f(e, 0, 0)),
                                 distance(p + Vec3f(0, e, 0)) - distance(p - Vec3f(0, e, 0)),
                                 distance(p + Vec3f(0, 0, e)) - distance(p - Vec3f(0, 0, e))),
                           glm::normalize(p));
    }

private:
    static float smoothUnion(float a, float b, float k) {
        const float h = std::clamp(0.5f + 0.5f * (b - a) / k, 0.0f, 1.0f);
        return b + h * (a - b) - k * h * (1.0f - h);
    }
    static float ellipsoid(const Vec3f& p, const Vec3f& r) {
        const float k0 = glm::length(p / r), k1 = glm::length(p / (r * r));
        return k1 > 0 ? k0 * (k0 - 1.0f) / k1 : -std::min({r.x, r.y, r.z});
    }
    /// A vertical cylinder of radius 0.42 from inside the cranium down to y = −1.9.
    static float neck(const Vec3f& p) {
        const float radial = glm::length(Vec2f(p.x, p.z + 0.08f)) - 0.42f;
        const float vertical = std::max(p.y - (-0.3f), -1.9f - p.y);
        return std::min(std::max(radial, vertical), 0.0f) +
               glm::length(Vec2f(std::max(radial, 0.0f), std::max(vertical, 0.0f)));
    }
};

} // namespace

TriangleMesh generateHeadMesh(const Sphere& cranium, int rings) {
    rings = std::max(rings, 8);
    const int segments = 2 * rings;
    const HeadShape shape;
    constexpr float kFar = 2.5f; // every direction leaves the head before this
    constexpr int kSteps = 100;  // finer than the head's thinnest part (the nose)
    // The surface along a direction from the cranium's centre: the outermost
    // root of the distance (the head is star-shaped about the centre).
    const auto surfaceAlong = [&](const Vec3f& dir) {
        float outside = kFar, inside = kFar;
        for (int s = 1; s <= kSteps; ++s) {
            inside = kFar * float(kSteps - s) / float(kSteps);
            if (shape.distance(inside * dir) < 0)
                break;
            outside = inside;
        }
        for (int k = 0; k < 24; ++k) {
            const float mid = 0.5f * (inside + outside);
            (shape.distance(mid * dir) < 0 ? inside : outside) = mid;
        }
        return 0.5f * (inside + outside) * dir;
    };

    // Vertices: the two poles and (rings − 1) rings of `segments`, in unit
    // cranium coordinates, with the distance's gradient as their normal.
    const std::size_t vertexCount = 2 + std::size_t(rings - 1) * std::size_t(segments);
    std::vector<Vec3f> unitPoints(vertexCount), normals(vertexCount);
    tbb::parallel_for(0, rings + 1, [&](int i) {
        const float theta = float(Pi) * float(i) / float(rings);
        const int count = i == 0 || i == rings ? 1 : segments;
        for (int j = 0; j < count; ++j) {
            const float phi = float(TwoPi) * float(j) / float(segments);
            const std::size_t v = i == 0        ? 0
                                  : i == rings ? vertexCount - 1
                                               : 1 + std::size_t(i - 1) * std::size_t(segments) +
                                                     std::size_t(j);
            unitPoints[v] = surfaceAlong(Vec3f(std::sin(theta) * std::sin(phi), std::cos(theta),
                                               std::sin(theta) * std::cos(phi)));
            normals[v] = shape.normal(unitPoints[v]);
        }
    });
    const auto ringVertex = [&](int i, int j) {
        return static_cast<std::uint32_t>(1 + (i - 1) * segments + (j % segments));
    };
    const auto bottom = static_cast<std::uint32_t>(vertexCount - 1);
    TriangleMesh mesh;
    for (int j = 0; j < segments; ++j) {
        mesh.triangles.push_back({0, ringVertex(1, j), ringVertex(1, j + 1)});
        for (int i = 1; i + 1 < rings; ++i) {
            const std::uint32_t a = ringVertex(i, j), b = ringVertex(i, j + 1),
                                c = ringVertex(i + 1, j), d = ringVertex(i + 1, j + 1);
            mesh.triangles.push_back({a, c, d});
            mesh.triangles.push_back({a, d, b});
        }
        mesh.triangles.push_back({ringVertex(rings - 1, j), bottom, ringVertex(rings - 1, j + 1)});
    }
    mesh.positions.reserve(vertexCount);
    for (const Vec3f& p : unitPoints)
        mesh.positions.push_back(cranium.center + cranium.radius * p);
    mesh.cornerNormals.reserve(3 * mesh.triangles.size());
    for (const auto& t : mesh.triangles)
        for (const std::uint32_t v : t)
            mesh.cornerNormals.push_back(normals[v]);
    return mesh;
}

} // namespace hairvox
