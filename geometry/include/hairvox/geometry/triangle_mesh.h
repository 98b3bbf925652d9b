// hairvox geometry: triangle meshes — the bodies and heads hair sits on.
//
// A TriangleMesh is what the surface scene (geometry/surface_scene.h) hands
// to Embree: shared positions, triangles as index triples, and optional
// per-corner shading normals (OBJ lets a corner name its own normal, so they
// are stored per corner, not per vertex).
//
// Sources:
//  - readObjMesh(): a Wavefront OBJ file through tinyobjloader (Debian's
//    libtinyobjloader-dev). tinyobjloader reads "nan" as 0 and keeps
//    out-of-range indices with an unreliable line number, so the file is first
//    checked line by line (validateObjText): every vertex coordinate must parse
//    as a finite number and every face index must name an existing vertex or
//    normal, else an InputError names the file and the line. Polygons are
//    fanned into triangles; zero-area triangles are dropped with a warning.
//  - generateHeadMesh(): a mannequin head — cranium, face, chin and neck — whose
//    cranium is the procedural grooms' head sphere (strands/procedural.h), so
//    that the procedural hair's roots sit on it.
#pragma once

#include <hairvox/core/vecmath.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace hairvox {

struct TriangleMesh {
    std::vector<Vec3f> positions;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    /// Unit shading normals per triangle corner (3 per triangle), or empty:
    /// the triangles' geometric normals are used.
    std::vector<Vec3f> cornerNormals;

    std::size_t triangleCount() const { return triangles.size(); }
    bool empty() const { return triangles.empty(); }
    Bounds3f bounds() const;
    /// Of positions, triangles and normals (the path tracer's render hash).
    std::uint64_t contentHash() const;
};

/// Scale, then rotate (degrees about x, then y, then z), then translate.
struct MeshTransform {
    Vec3f scale{1.0f};          ///< each component finite and ≠ 0
    Vec3f rotateDegrees{0.0f};
    Vec3f translate{0.0f};

    bool isIdentity() const;
    /// Positions by the affine map, normals by its inverse transpose (renormalised).
    void apply(TriangleMesh& mesh) const;
};

struct LoadedMesh {
    TriangleMesh mesh;
    std::vector<std::string> warnings; ///< dropped degenerate triangles, ignored elements
};

inline constexpr std::uint64_t kMaxObjMeshBytes = 2ull << 30;
inline constexpr std::uint64_t kMaxMeshTriangles = 1ull << 28;

/// Reads a Wavefront OBJ mesh (v, vn, f; other elements are ignored). Throws
/// InputError naming the file — and the line, for a bad vertex or index — when
/// the file is missing, over kMaxObjMeshBytes, malformed, or has no triangle
/// of non-zero area.
LoadedMesh readObjMesh(const std::filesystem::path& path);
/// The same from text in memory; `name` is used in messages.
LoadedMesh parseObjMesh(std::string_view text, const std::string& name);

/// A closed mannequin head around the sphere `cranium`: the cranium itself
/// (where the procedural hair grows), a face and chin below its front (+z),
/// and a neck cut flat below. `rings` latitude rings (≥ 8) of 2·rings
/// vertices; 4·rings·(rings − 1) triangles.
TriangleMesh generateHeadMesh(const Sphere& cranium, int rings = 96);

} // namespace hairvox
