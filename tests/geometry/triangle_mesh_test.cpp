// Triangle meshes (geometry/triangle_mesh.h): the OBJ reader and its errors
// naming file and line, transforms, the mannequin head; the surface scene
// (geometry/surface_scene.h): hits, two-sided normals, occlusion, inside tests.
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/core/rng.h>
#include <hairvox/geometry/ray_scene.h>
#include <hairvox/geometry/surface_scene.h>
#include <hairvox/geometry/triangle_mesh.h>

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace hairvox {
namespace {

/// A unit cube centred on the origin, counter-clockwise seen from outside:
/// six quads (fanned into 12 triangles), with or without normals.
std::string cubeObj(bool normals) {
    std::string s = "# cube\n"
                    "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n"
                    "v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n";
    if (!normals)
        return s + "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 2 3 7 6\nf 1 5 8 4\n";
    s += "vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 0 1 0\nvn 1 0 0\nvn -1 0 0\n";
    return s + "f 1//1 4//1 3//1 2//1\nf 5//2 6//2 7//2 8//2\nf 1//3 2//3 6//3 5//3\n"
               "f 3//4 4//4 8//4 7//4\nf 2//5 3//5 7//5 6//5\nf 1//6 5//6 8//6 4//6\n";
}

std::string errorOf(const std::string& text) {
    try {
        parseObjMesh(text, "body.obj");
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

TEST(ObjMesh, ReadsQuadsAsTrianglesWithAndWithoutNormals) {
    for (const bool normals : {false, true}) {
        const LoadedMesh m = parseObjMesh(cubeObj(normals), "cube.obj");
        EXPECT_EQ(m.mesh.positions.size(), 8u);
        EXPECT_EQ(m.mesh.triangleCount(), 12u);
        EXPECT_EQ(m.mesh.cornerNormals.size(), normals ? 36u : 0u);
        EXPECT_TRUE(m.warnings.empty()) << m.warnings.front();
        EXPECT_EQ(m.mesh.bounds().min, Vec3f(-0.5f));
    }
}

TEST(ObjMesh, BadFilesNameTheFileAndTheLine) {
    const std::string cube = cubeObj(false);
    EXPECT_EQ(errorOf("v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n"),
              "body.obj: line 2: coordinate 2 is \"nan\": expected a finite number");
    EXPECT_EQ(errorOf("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 7\n"),
              "body.obj: line 5: vertex index 7 is out of range: 3 vertex(s) defined before this line");
    EXPECT_EQ(errorOf("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//4 2 3\n"),
              "body.obj: line 4: normal index 4 is out of range: 0 normal(s) defined before this line");
    EXPECT_EQ(errorOf("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"),
              "body.obj: line 4: a face needs at least 3 corners, this one has 2");
    EXPECT_EQ(errorOf("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n"),
              "body.obj: line 4: vertex index \"x\" is not an integer");
    EXPECT_EQ(errorOf("v 0 0 1e39\n"), "body.obj: line 1: coordinate 3 is \"1e39\": expected a finite number");
    EXPECT_EQ(errorOf("# nothing\n"), "body.obj: no triangle of non-zero area (0 vertices, 0 degenerate triangles)");
    // Every triangle degenerate: an error, not an empty surface.
    EXPECT_EQ(errorOf("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n"),
              "body.obj: no triangle of non-zero area (3 vertices, 2 degenerate triangles)");
    // A lone carriage return ends a line, for tinyobjloader and for the check.
    EXPECT_EQ(errorOf("v 0 0 0\nv 1 0 0\nv 0 1 0\n# x\rf 1 2 9\n"),
              "body.obj: line 4: vertex index 9 is out of range: 3 vertex(s) defined before this line");
    // Relative (negative) indices are valid OBJ.
    EXPECT_EQ(parseObjMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\n", "rel.obj").mesh.triangleCount(), 1u);
    // A missing file.
    try {
        readObjMesh("/nonexistent/body.obj");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent/body.obj"), std::string::npos) << e.what();
    }
}

// Coordinates are read correctly rounded, whatever their spelling: numbers
// that tinyobjloader's own parser misreads (found by fuzz_mesh: 1 followed by
// 400 zeros and e-399 read as infinity, 0.(400 zeros)1e400 as 0).
TEST(ObjMesh, LongNumbersAreReadCorrectlyRounded) {
    const std::string zeros(400, '0');
    const LoadedMesh m = parseObjMesh("v 1" + zeros + "e-399 0 0\nv 0." + zeros +
                                          "1e400 1 0\nv 0 0 1" + zeros + "e-400\nvn 0 0 1" +
                                          zeros + "e-399\nf 1//1 2//1 3//1\n",
                                      "long.obj");
    ASSERT_EQ(m.mesh.positions.size(), 3u);
    EXPECT_EQ(m.mesh.positions[0], Vec3f(10.0f, 0.0f, 0.0f));
    EXPECT_EQ(m.mesh.positions[1], Vec3f(0.1f, 1.0f, 0.0f));
    EXPECT_EQ(m.mesh.positions[2], Vec3f(0.0f, 0.0f, 1.0f));
    ASSERT_EQ(m.mesh.cornerNormals.size(), 3u);
    EXPECT_EQ(m.mesh.cornerNormals[0], Vec3f(0.0f, 0.0f, 1.0f));
    // Normals as long as single precision allows still normalise.
    const LoadedMesh big =
        parseObjMesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 3e38 3e38 0\nf 1//1 2//1 3//1\n", "big.obj");
    for (const Vec3f& n : big.mesh.cornerNormals)
        EXPECT_NEAR(glm::length(n), 1.0f, 1e-6f);
    // A triangle whose edges overflow single precision is refused.
    EXPECT_EQ(errorOf("v -3e38 0 0\nv 3e38 0 0\nv 0 3e38 0\nf 1 2 3\n"),
              "body.obj: a triangle's edges overflow single precision (coordinates near ±3.4e38): "
              "not a usable mesh");
}

TEST(ObjMesh, DegenerateTrianglesAreDroppedWithAWarning) {
    const LoadedMesh m = parseObjMesh(cubeObj(false) + "f 1 1 2\nf 1 2 1\n", "cube.obj");
    EXPECT_EQ(m.mesh.triangleCount(), 12u);
    ASSERT_EQ(m.warnings.size(), 1u);
    EXPECT_EQ(m.warnings[0], "cube.obj: dropped 2 triangle(s) of zero area");
}

TEST(ObjMesh, TransformScalesRotatesThenTranslates) {
    TriangleMesh m = parseObjMesh(cubeObj(true), "cube.obj").mesh;
    MeshTransform t;
    t.scale = Vec3f(2.0f, 1.0f, 1.0f);
    t.rotateDegrees = Vec3f(0.0f, 90.0f, 0.0f); // x → −z
    t.translate = Vec3f(0.0f, 0.0f, 10.0f);
    t.apply(m);
    const Bounds3f b = m.bounds();
    EXPECT_NEAR(b.min.x, -0.5f, 1e-5f);
    EXPECT_NEAR(b.max.x, 0.5f, 1e-5f);
    EXPECT_NEAR(b.min.z, 9.0f, 1e-5f);
    EXPECT_NEAR(b.max.z, 11.0f, 1e-5f);
    // The +x face's normal now points along −z.
    const SurfaceScene scene({}, {m});
    const auto hit = scene.intersect(Vec3f(0, 0, 0), Vec3f(0, 0, 1), 100.0f);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 9.0f, 1e-5f);
    EXPECT_NEAR(hit->normal.z, -1.0f, 1e-5f);
}

TEST(SurfaceScene, HitsOcclusionAndTwoSidedNormals) {
    const SurfaceScene scene({Sphere{Vec3f(0, 0, 5), 1.0f}},
                             {parseObjMesh(cubeObj(false), "cube.obj").mesh});
    EXPECT_EQ(scene.surfaceCount(), 2u);
    // From outside the cube along +z: the cube's −z face at 0.5, then the sphere.
    auto hit = scene.intersect(Vec3f(0, 0, -2), Vec3f(0, 0, 1), 100.0f);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->surface, 1u); // spheres first, then meshes
    EXPECT_NEAR(hit->t, 1.5f, 1e-5f);
    EXPECT_NEAR(hit->normal.z, -1.0f, 1e-6f);
    // From inside the cube: its +z face, normal facing back toward the origin.
    hit = scene.intersect(Vec3f(0, 0, 0), Vec3f(0, 0, 1), 100.0f);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->t, 0.5f, 1e-5f);
    EXPECT_NEAR(hit->geometricNormal.z, -1.0f, 1e-6f);
    // Past the cube: the sphere.
    hit = scene.intersect(Vec3f(0, 0, 1), Vec3f(0, 0, 1), 100.0f);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->surface, 0u);
    EXPECT_NEAR(hit->t, 3.0f, 1e-5f);
    EXPECT_TRUE(scene.occluded(Vec3f(0, 0, -2), Vec3f(0, 0, 1), 2.0f));
    EXPECT_FALSE(scene.occluded(Vec3f(0, 0, -2), Vec3f(0, 0, 1), 1.4f));
    EXPECT_FALSE(scene.occluded(Vec3f(0, 3, -2), Vec3f(0, 0, 1), 100.0f));
    EXPECT_TRUE(scene.contains(Vec3f(0.1f, 0.2f, 0.3f)));
    EXPECT_TRUE(scene.contains(Vec3f(0.0f, 0.0f, 5.5f)));
    EXPECT_FALSE(scene.contains(Vec3f(0.0f, 0.0f, 2.5f)));
    EXPECT_FALSE(scene.contains(Vec3f(3.0f, 0.0f, 0.0f)));
}

TEST(SurfaceScene, ABatchOfShadowSegmentsIsEachSegmentAlone) {
    // The batch (Embree's ray stream) and one segment at a time agree on every
    // segment: toward a directional light and a point light, from points all
    // around a mannequin head and a sphere, short and long, grazing included.
    const Sphere cranium{Vec3f(0.0f, 1.0f, 0.0f), 0.1f};
    const SurfaceScene scene({Sphere{Vec3f(0.3f, 1.0f, 0.0f), 0.05f}},
                             {generateHeadMesh(cranium, 48)});
    Pcg32 rng(4);
    std::vector<Vec3f> origins, dirs;
    std::vector<float> tMax;
    const Vec3f pointLight(0.2f, 1.4f, 0.5f);
    for (int i = 0; i < 3000; ++i) {
        const Vec3f p = cranium.center + Vec3f(rng.uniform(-0.3f, 0.3f), rng.uniform(-0.3f, 0.3f),
                                               rng.uniform(-0.3f, 0.3f));
        if (i % 2 == 0) {
            origins.push_back(p);
            dirs.push_back(glm::normalize(Vec3f(-0.6f, 0.65f, -0.45f)));
            tMax.push_back(i % 6 == 0 ? 0.05f : std::numeric_limits<float>::infinity());
        } else {
            origins.push_back(p);
            dirs.push_back(glm::normalize(pointLight - p));
            tMax.push_back(glm::length(pointLight - p));
        }
    }
    std::vector<std::uint8_t> blocked(origins.size());
    scene.occluded(origins, dirs, tMax, blocked);
    int count = 0;
    for (std::size_t i = 0; i < origins.size(); ++i) {
        ASSERT_EQ(blocked[i] != 0, scene.occluded(origins[i], dirs[i], tMax[i])) << "segment " << i;
        count += blocked[i];
    }
    EXPECT_GT(count, 100); // both answers are exercised
    EXPECT_LT(count, 2900);
}

TEST(SurfaceScene, ABatchOfRaysHitsWhatEachRayAloneHits) {
    // The batch (Embree's stream of coherent rays) and one ray at a time find
    // the same hit, bit for bit: camera-like fans of rays through a mannequin
    // head with normals and a sphere in front of it, from outside and from
    // inside the head, with and without a bound; misses included.
    const Sphere cranium{Vec3f(0.0f, 1.0f, 0.0f), 0.1f};
    const SurfaceScene scene({Sphere{Vec3f(0.05f, 1.0f, 0.2f), 0.03f}},
                             {generateHeadMesh(cranium, 48)});
    Pcg32 rng(5);
    std::vector<Vec3f> origins, dirs;
    for (int i = 0; i < 4000; ++i) {
        const bool inside = i % 5 == 0;
        const Vec3f eye = inside ? cranium.center : Vec3f(0.02f, 1.05f, 0.6f);
        origins.push_back(eye);
        const Vec3f toward =
            inside ? Vec3f(rng.uniform(-1.0f, 1.0f), rng.uniform(-1.0f, 1.0f),
                           rng.uniform(-1.0f, 1.0f))
                   : cranium.center +
                         Vec3f(rng.uniform(-0.2f, 0.2f), rng.uniform(-0.2f, 0.2f), 0.0f) - eye;
        dirs.push_back(normalizeOr(toward, Vec3f(0, 0, -1)));
    }
    int hits = 0;
    for (const float tMax : {std::numeric_limits<float>::infinity(), 0.55f}) {
        std::vector<std::optional<SurfaceHit>> batch(origins.size());
        scene.intersect(origins, dirs, tMax, batch);
        for (std::size_t i = 0; i < origins.size(); ++i) {
            const std::optional<SurfaceHit> alone = scene.intersect(origins[i], dirs[i], tMax);
            ASSERT_EQ(batch[i].has_value(), alone.has_value()) << "ray " << i;
            if (!alone)
                continue;
            ++hits;
            EXPECT_EQ(batch[i]->t, alone->t) << "ray " << i;
            EXPECT_EQ(batch[i]->surface, alone->surface) << "ray " << i;
            EXPECT_EQ(batch[i]->normal, alone->normal) << "ray " << i;
            EXPECT_EQ(batch[i]->geometricNormal, alone->geometricNormal) << "ray " << i;
        }
    }
    EXPECT_GT(hits, 2000); // hits and misses, sphere and mesh, are exercised
    EXPECT_LT(hits, 7900);
}

TEST(SurfaceScene, RaySceneMeetsTheSurfaceBeforeTheFibersBehindIt) {
    Groom groom;
    const Vec3f strand[2] = {{-1.0f, 0.0f, 1.0f}, {1.0f, 0.0f, 1.0f}}; // behind the cube's +z face
    groom.addStrand(strand);
    const auto surfaces = std::make_shared<const SurfaceScene>(
        std::vector<Sphere>{}, std::vector<TriangleMesh>{parseObjMesh(cubeObj(false), "c").mesh});
    const RayScene rays(groom, FiberScale{1e-3f, 1.0f}, surfaces);
    auto hit = rays.intersect(Vec3f(0, 0, -2), Vec3f(0, 0, 1), 100.0f);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->kind, RayHit::Kind::Surface);
    EXPECT_NEAR(hit->t, 1.5f, 1e-5f);
    hit = rays.intersect(Vec3f(0, 0, 0.6f), Vec3f(0, 0, 1), 100.0f);
    ASSERT_TRUE(hit);
    EXPECT_EQ(hit->kind, RayHit::Kind::Fiber);
    EXPECT_TRUE(rays.occluded(Vec3f(0, 0, 2), Vec3f(0, 0, -1), 3.0f));
}

TEST(MannequinHead, ClosedAroundItsCraniumWithAFaceAndNeck) {
    const Sphere cranium{Vec3f(0.0f, 1.0f, 0.0f), 0.1f};
    const TriangleMesh head = generateHeadMesh(cranium, 48);
    EXPECT_EQ(head.triangleCount(), 4u * 48u * 47u);
    EXPECT_EQ(head.cornerNormals.size(), 3 * head.triangleCount());
    const SurfaceScene scene({}, {head});
    EXPECT_TRUE(scene.contains(cranium.center));
    EXPECT_TRUE(scene.contains(cranium.center + Vec3f(0.0f, -0.15f, 0.0f))); // the neck
    EXPECT_FALSE(scene.contains(cranium.center + Vec3f(0.0f, 0.12f, 0.0f)));
    // The scalp is the cranium sphere: the procedural hair's roots sit on it.
    for (const Vec3f dir : {Vec3f(0, 1, 0), glm::normalize(Vec3f(0, 1, -1)), Vec3f(1, 0, 0)}) {
        const auto hit = scene.intersect(cranium.center + 0.5f * dir, -dir, 1.0f);
        ASSERT_TRUE(hit);
        EXPECT_NEAR(0.5f - hit->t, cranium.radius, 0.002f) << dir.x << " " << dir.y << " " << dir.z;
        EXPECT_GT(glm::dot(hit->normal, dir), 0.95f);
    }
    // A face: the nose stands out in front (+z) of the cranium sphere.
    const auto nose = scene.intersect(cranium.center + Vec3f(0.0f, -0.024f, 0.5f),
                                      Vec3f(0, 0, -1), 1.0f);
    ASSERT_TRUE(nose);
    EXPECT_GT(0.5f - nose->t, 1.01f * cranium.radius);
}

} // namespace
} // namespace hairvox
