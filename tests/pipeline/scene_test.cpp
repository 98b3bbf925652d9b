#include "scene_test_util.h"
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/pipeline/scene.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

namespace hairvox {
namespace {

/// A small valid scene; tests break one field at a time.
nlohmann::json validScene() {
    return nlohmann::json::parse(R"({
      "groom": {"procedural": {"style": "straight", "strands": 100}},
      "lights": [
        {"type": "directional", "direction": [0, 1, 0]},
        {"type": "point", "position": [1, 1, 1], "intensity": 2}
      ],
      "camera": {"position": [0, 0, 1], "look_at": [0, 0, 0], "resolution": [64, 48]}
    })");
}

std::string errorOf(const nlohmann::json& j) {
    return test::sceneErrorOf(j);
}

TEST(Scene, ValidSceneGetsDefaults) {
    const Scene s = parseScene(validScene(), "dir/scene.json", "/scenes");
    EXPECT_TRUE(s.groom.isProcedural());
    EXPECT_EQ(s.groom.procedural.style, GroomStyle::Straight);
    EXPECT_EQ(s.groom.procedural.strands, 100u);
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].name, "light0");
    EXPECT_EQ(s.lights[1].kind, Light::Kind::Point);
    EXPECT_EQ(s.lights[1].intensity, 2.0f);
    EXPECT_EQ(s.camera.width, 64u);
    EXPECT_EQ(s.camera.height, 48u);
    EXPECT_FALSE(s.head.has_value());
    EXPECT_FALSE(s.voxelSize.has_value());
    EXPECT_EQ(s.globalTermMode, GlobalTermMode::Grid);
    EXPECT_EQ(s.shadingRate, ShadingRate::Fragment);
    EXPECT_EQ(s.output.exr, std::filesystem::path("out/scene.exr"));
    EXPECT_EQ(s.output.png, std::filesystem::path("out/scene.png"));
    EXPECT_FLOAT_EQ(s.fiber.eta, 1.55f);
}

TEST(Scene, EveryFeatureParses) {
    nlohmann::json j = validScene();
    j["groom"] = {{"file", "grooms/a.hair"}};
    j["fiber"] = {{"diameter", 8e-5},
                  {"density_multiplier", 2},
                  {"eta", 1.6},
                  {"melanin", {{"eumelanin", 0.3}, {"pheomelanin", 0.1}}},
                  {"alpha_R", -6},
                  {"beta_R", 8},
                  {"eccentricity", 0.9},
                  {"caustic_width", 12},
                  {"caustic_gain", 1},
                  {"caustic_fade", 0.25},
                  {"caustic_max_width", 0.4}};
    j["dual_scattering"] = {{"d_f", 0.6}, {"d_b", 0.5}};
    j["lights"][0]["name"] = "key";
    j["lights"][0]["color"] = {1, 0.9, 0.8};
    j["head"] = {{"center", {0, 0, -0.5}}, {"radius", 0.1}, {"color", {0.5, 0.4, 0.3}}};
    j["grid"] = {{"voxel_size", 0.002}, {"fiber_sample_spacing", 0.5}};
    j["global_term"] = {{"mode", "exact"},
                        {"exact", {{"rays", 8}, {"radius", 0.001}, {"seed", 5}}}};
    j["shading_rate"] = "vertex";
    j["background"] = {0.1, 0.1, 0.1};
    j["output"] = {{"exr", "a/b.exr"},    {"png", nullptr},     {"exposure", 1.5},
                   {"tone_map", "clamp"}, {"exr_zip_level", 6}, {"exr_compression", "rle"}};
    const Scene s = parseScene(j, "scene.json", "/scenes");
    EXPECT_EQ(s.groom.file, std::filesystem::path("/scenes/grooms/a.hair"));
    EXPECT_FLOAT_EQ(s.fiberScale.diameter, 8e-5f);
    EXPECT_FLOAT_EQ(s.fiberScale.densityMultiplier, 2.0f);
    EXPECT_NEAR(s.fiber.sigma_a.r, 0.3f * 0.419f + 0.1f * 0.187f, 1e-6f);
    EXPECT_NEAR(degrees(s.fiber.alpha_R), -6.0f, 1e-5f);
    EXPECT_NEAR(degrees(s.fiber.causticWidth), 12.0f, 1e-5f);
    EXPECT_FLOAT_EQ(s.dualScattering.d_b, 0.5f);
    EXPECT_EQ(s.lights[0].name, "key");
    ASSERT_TRUE(s.head.has_value());
    EXPECT_FLOAT_EQ(s.head->sphere.center.z, -0.5f);
    EXPECT_FLOAT_EQ(*s.voxelSize, 0.002f);
    EXPECT_FLOAT_EQ(*s.fiberSampleSpacing, 0.5f);
    EXPECT_EQ(s.globalTermMode, GlobalTermMode::Exact);
    EXPECT_EQ(s.exact.rays, 8u);
    EXPECT_EQ(s.exact.seed, 5u);
    EXPECT_EQ(s.output.exrZipLevel, 6);
    EXPECT_EQ(s.output.exrCompression, ExrCompression::Rle);
    EXPECT_EQ(s.shadingRate, ShadingRate::Vertex);
    EXPECT_TRUE(s.output.png.empty());
    EXPECT_EQ(s.output.toneMap, ToneMap::Clamp);
    j["output"]["exr_zip_level"] = 10;
    EXPECT_THROW(parseScene(j, "scene.json", "/scenes"), InputError);
    j["output"]["exr_zip_level"] = 1;
    j["output"]["exr_compression"] = "piz";
    try {
        parseScene(j, "scene.json", "/scenes");
        ADD_FAILURE() << "an unknown compression was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("exr_compression"), std::string::npos) << e.what();
    }
}

TEST(Scene, OutputLayersNameLayersOfTheScene) {
    nlohmann::json j = validScene();
    EXPECT_FALSE(parseScene(j, "scene.json", "/").output.layers.has_value()); // all
    j["lights"][0]["name"] = "key";
    j["output"]["layers"] = {"Z", "key.V", "direct_TT", "light1.sigma_f"};
    const Scene s = parseScene(j, "scene.json", "/");
    ASSERT_TRUE(s.output.layers.has_value());
    EXPECT_EQ(*s.output.layers,
              (std::vector<std::string>{"Z", "key.V", "direct_TT", "light1.sigma_f"}));
    j["output"]["layers"] = "none";
    EXPECT_TRUE(parseScene(j, "scene.json", "/").output.layers->empty());
    j["output"]["layers"] = "all";
    EXPECT_FALSE(parseScene(j, "scene.json", "/").output.layers.has_value());
    const auto fails = [&](const nlohmann::json& layers, const std::string& part) {
        j["output"]["layers"] = layers;
        const std::string e = errorOf(j);
        EXPECT_NE(e.find(part), std::string::npos) << layers.dump() << ": " << e;
    };
    fails("some", "/output/layers");
    fails(3, "/output/layers");
    fails({"Z", 1}, "/output/layers/1");
    fails({"key.v"}, "output.layers[0] \"key.v\": not a layer of this scene");
    fails({"key.v"}, "some of: direct_R, direct_TT");
    fails({"A"}, "not a layer"); // always written: not a choice
    fails({"Z", "Z"}, "output.layers[1] \"Z\" is named twice");
    j["output"]["layers"] = {"Z"};
    j["integrator"] = {{"type", "path"}};
    EXPECT_NE(errorOf(j).find("the path integrator writes every layer"), std::string::npos)
        << errorOf(j);
}

TEST(Scene, ShadingToleranceBelongsToTheAdaptiveRate) {
    nlohmann::json j = validScene();
    j["shading_rate"] = "adaptive";
    j["shading_tolerance"] = 0.1;
    const Scene s = parseScene(j, "scene.json", "/");
    EXPECT_EQ(s.shadingRate, ShadingRate::Adaptive);
    EXPECT_FLOAT_EQ(s.shadingTolerance, 0.1f);
    j["shading_tolerance"] = 2;
    EXPECT_NE(errorOf(j).find("/shading_tolerance"), std::string::npos) << errorOf(j);
    j["shading_tolerance"] = "0.1";
    EXPECT_NE(errorOf(j).find("/shading_tolerance"), std::string::npos) << errorOf(j);
    j["shading_rate"] = "fragment";
    j["shading_tolerance"] = 0.1;
    EXPECT_NE(errorOf(j).find("adaptive shading rate only"), std::string::npos) << errorOf(j);
}

TEST(Scene, TailTransmittanceBelongsToTheFragmentAndAdaptiveRates) {
    nlohmann::json j = validScene();
    EXPECT_FLOAT_EQ(parseScene(j, "scene.json", "/").tailTransmittance, kDefaultTailTransmittance);
    j["tail_transmittance"] = 0;
    EXPECT_FLOAT_EQ(parseScene(j, "scene.json", "/").tailTransmittance, 0.0f);
    j["shading_rate"] = "adaptive";
    j["tail_transmittance"] = 0.125;
    EXPECT_FLOAT_EQ(parseScene(j, "scene.json", "/").tailTransmittance, 0.125f);
    for (const nlohmann::json& bad : {nlohmann::json(1.5), nlohmann::json(-0.1),
                                      nlohmann::json("0.1"), nlohmann::json::array()}) {
        j["tail_transmittance"] = bad;
        EXPECT_NE(errorOf(j).find("/tail_transmittance"), std::string::npos) << errorOf(j);
    }
    j["shading_rate"] = "vertex";
    j["tail_transmittance"] = 0.1;
    EXPECT_NE(errorOf(j).find("fragment and adaptive shading rates"), std::string::npos)
        << errorOf(j);
}

TEST(Scene, DirectionalLightPointsTowardTheLightAndIsNormalised) {
    nlohmann::json j = validScene();
    j["lights"][0]["direction"] = {0, 0, 2};
    const Scene s = parseScene(j, "scene.json", "/");
    EXPECT_EQ(s.lights[0].direction, Vec3f(0, 0, 1));
    EXPECT_EQ(s.lights[0].pathFrom(Vec3f(5, 5, 5)).omega, Vec3f(0, 0, 1));
}

TEST(Scene, MissingFieldsNameTheirPath) {
    nlohmann::json j = validScene();
    j.erase("groom");
    EXPECT_EQ(errorOf(j), "scene.json: /groom: missing (expected an object)");
    j = validScene();
    j["camera"].erase("look_at");
    EXPECT_EQ(errorOf(j), "scene.json: /camera/look_at: missing (expected an array of 3 numbers)");
    j = validScene();
    j["lights"][1].erase("position");
    EXPECT_EQ(errorOf(j),
              "scene.json: /lights/1/position: missing (expected the light's position)");
    j = validScene();
    j["groom"] = nlohmann::json::object();
    EXPECT_EQ(errorOf(j),
              "scene.json: /groom: expected exactly one of \"file\" and \"procedural\"");
}

TEST(Scene, WrongTypesNameTheirPathAndTheExpectedType) {
    nlohmann::json j = validScene();
    j["lights"][1]["intensity"] = "bright";
    EXPECT_EQ(errorOf(j),
              "scene.json: /lights/1/intensity: expected a number in [0, 1e+06], got \"bright\"");
    j = validScene();
    j["camera"]["position"] = {0, 1};
    EXPECT_EQ(errorOf(j), "scene.json: /camera/position: expected an array of 3 numbers, each in "
                          "[-1e+06, 1e+06], got an array of 2 elements");
    j = validScene();
    j["lights"][0]["type"] = "spot";
    EXPECT_EQ(errorOf(j), "scene.json: /lights/0/type: expected one of \"directional\", "
                          "\"point\", \"environment\", got \"spot\"");
    j = validScene();
    j["groom"]["procedural"]["strands"] = 1.5;
    EXPECT_EQ(errorOf(j), "scene.json: /groom/procedural/strands: expected an integer in "
                          "[1, 10000000], got 1.5");
    j = validScene();
    j["lights"] = nlohmann::json::object();
    EXPECT_EQ(errorOf(j), "scene.json: /lights: expected an array of 0 to 16 elements, got an "
                          "object");
    j = validScene();
    j["grid"] = {{"voxel_size", "big"}};
    EXPECT_EQ(errorOf(j), "scene.json: /grid/voxel_size: expected \"auto\" or a number in (0, "
                          "1000], got \"big\"");
    j = validScene();
    j["grid"] = {{"fiber_sample_spacing", 5}};
    EXPECT_EQ(errorOf(j), "scene.json: /grid/fiber_sample_spacing: expected a number in [0, 4], "
                          "got 5");
}

TEST(Scene, OutOfRangeValuesNameTheirPathAndRange) {
    nlohmann::json j = validScene();
    j["camera"]["fov"] = 200;
    EXPECT_EQ(errorOf(j), "scene.json: /camera/fov: expected a number in [0.1, 170], got 200");
    j = validScene();
    j["camera"]["resolution"] = {0, 10};
    EXPECT_EQ(errorOf(j), "scene.json: /camera/resolution/0: expected an integer in [1, 16384], "
                          "got 0");
    j = validScene();
    j["camera"]["resolution"] = {16384, 16384};
    EXPECT_NE(errorOf(j).find("/camera/resolution: 16384 x 16384: expected at most"),
              std::string::npos);
    j = validScene();
    j["fiber"] = {{"eta", 5}};
    EXPECT_EQ(errorOf(j), "scene.json: /fiber/eta: eta = 5 should be in the range [1.1, 2.5]");
    j = validScene();
    j["fiber"] = {{"sigma_a", {0.1, -1, 0.1}}};
    EXPECT_NE(errorOf(j).find("scene.json: /fiber/sigma_a: sigma_a = -1 should be in the range"),
              std::string::npos);
    j = validScene();
    j["fiber"] = {{"beta_R", 0.1}};
    EXPECT_NE(errorOf(j).find("/fiber/beta_R: beta_R = 0.1"), std::string::npos);
    j = validScene();
    j["groom"]["procedural"]["length_variation"] = 2;
    EXPECT_NE(errorOf(j).find("/groom/procedural/length_variation: procedural groom: length "
                              "variation = 2 should be in the range [0, 0.9]"),
              std::string::npos);
    j = validScene();
    j["groom"]["procedural"]["strands"] = 5'000'000;
    j["groom"]["procedural"]["points_per_strand"] = 4096;
    EXPECT_NE(errorOf(j).find("/groom/procedural/strands: 5000000 strands x 4096 points"),
              std::string::npos);
    j = validScene();
    j["dual_scattering"] = {{"d_b", 1.5}};
    EXPECT_EQ(errorOf(j),
              "scene.json: /dual_scattering/d_b: d_b = 1.5 should be in the range [0, 1]");
    j = validScene();
    j["lights"][0]["direction"] = {0, 0, 0};
    EXPECT_NE(errorOf(j).find("/lights/0/direction: expected a non-zero vector"),
              std::string::npos);
    j = validScene();
    j["head"] = {{"radius", 2}};
    EXPECT_EQ(errorOf(j), "scene.json: camera.position is inside the head sphere");
    j = validScene();
    j["camera"]["up"] = {0, 0, 3};
    EXPECT_NE(errorOf(j).find("scene.json: /camera: camera: up"), std::string::npos);
}

TEST(Scene, UnknownKeysAreErrors) {
    nlohmann::json j = validScene();
    j["lihgts"] = nlohmann::json::array();
    EXPECT_EQ(errorOf(j).rfind("scene.json: /lihgts: unknown key (valid keys: groom, fiber", 0), 0u)
        << errorOf(j);
    j = validScene();
    j["camera"]["fovy"] = 30;
    EXPECT_NE(errorOf(j).find("scene.json: /camera/fovy: unknown key (valid keys in /camera: "
                              "position, look_at, up, fov, resolution)"),
              std::string::npos);
    j = validScene();
    j["groom"]["procedural"]["strand"] = 3;
    EXPECT_NE(errorOf(j).find("/groom/procedural/strand: unknown key"), std::string::npos);
    j = validScene();
    j["lights"][1]["direction"] = {0, 1, 0}; // meaningless for a point light
    EXPECT_NE(errorOf(j).find("/lights/1/direction: unknown key"), std::string::npos);
}

TEST(Scene, ConflictingAndDuplicateSettingsAreErrors) {
    nlohmann::json j = validScene();
    j["fiber"] = {{"sigma_a", {0.2, 0.3, 0.5}}, {"melanin", {{"eumelanin", 1}}}};
    EXPECT_EQ(errorOf(j),
              "scene.json: /fiber: give one of sigma_a, melanin and color, not several");
    j["fiber"] = {{"sigma_a", {0.2, 0.3, 0.5}}, {"color", {0.5, 0.4, 0.3}}};
    EXPECT_EQ(errorOf(j),
              "scene.json: /fiber: give one of sigma_a, melanin and color, not several");
    j = validScene();
    j["lights"][0]["name"] = "key";
    j["lights"][1]["name"] = "key";
    EXPECT_EQ(errorOf(j), "scene.json: /lights: lights 0 and 1 are both named \"key\"; light "
                          "names must be unique");
    j = validScene();
    j["lights"][0]["name"] = "key.light";
    EXPECT_NE(errorOf(j).find("/lights/0/name: expected a name of 1 to 32 letters"),
              std::string::npos);
}

TEST(Scene, SyntaxErrorsNameLineAndColumn) {
    try {
        parseSceneText("{\n  \"groom\": {,\n}", "broken.json", "/");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("broken.json: invalid JSON: parse error at line 2"),
                  std::string::npos)
            << e.what();
    }
}

TEST(Scene, HostileDocumentsGiveErrorsNotCrashes) {
    const std::string deep = std::string(100000, '[') + std::string(100000, ']');
    EXPECT_THROW(parseSceneText(deep, "deep.json", "/"), InputError);
    nlohmann::json j = validScene();
    j["camera"]["fov"] = nlohmann::json::parse(std::string(10000, '[') + std::string(10000, ']'));
    EXPECT_NE(errorOf(j).find("/camera/fov: expected a number in [0.1, 170], got an array of 1"),
              std::string::npos);
    j = validScene();
    j["background"] = {1e300, 0, 0};
    EXPECT_NE(errorOf(j).find("/background/0: expected a number in [0, 1e+06]"), std::string::npos);
    j = validScene();
    j["lights"][0]["name"] = std::string(1000, 'x');
    EXPECT_LT(errorOf(j).size(), 300u);
}

// Regression (issue 8, malformed-input corpus): nlohmann::json reports a
// number beyond double range as out_of_range, not parse_error; it escaped as an
// internal error (exit code 1).
TEST(Scene, NumberBeyondDoubleRangeIsAnInputError) {
    try {
        parseSceneText("{\"background\": [1e400, 0, 0]}", "big.json", "/");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("big.json: invalid JSON: number overflow"),
                  std::string::npos)
            << e.what();
    }
}

// Regression (issue 8, fuzzing with UBSan): an integer beyond uint64 (2^64
// parses as a double) was converted to uint64 before the range check failed —
// undefined behaviour (found by review, confirmed by fuzz_scene under UBSan).
TEST(Scene, IntegerBeyondUint64IsAnInputError) {
    nlohmann::json j = validScene();
    j["groom"]["procedural"]["seed"] = nlohmann::json::parse("18446744073709551616");
    EXPECT_NE(
        errorOf(j).find("/groom/procedural/seed: expected an integer in [0, 18446744073709551615]"),
        std::string::npos)
        << errorOf(j);
    j["groom"]["procedural"]["seed"] = 1e19; // an integral double within range
    EXPECT_EQ(errorOf(j), "");
    j["groom"]["procedural"]["seed"] = -1.0;
    EXPECT_NE(errorOf(j).find("/groom/procedural/seed"), std::string::npos);
}

TEST(Scene, LoadsFilesAndResolvesGroomPathsAgainstTheSceneFile) {
    test::TempDir dir;
    nlohmann::json j = validScene();
    j["groom"] = {{"file", "hair/a.tfx"}};
    test::writeText(dir / "my_scene.json", j.dump());
    const Scene s = loadScene(dir / "my_scene.json");
    EXPECT_EQ(s.groom.file, dir.path() / "hair/a.tfx");
    EXPECT_EQ(s.name, (dir / "my_scene.json").string());
    EXPECT_EQ(s.output.exr, std::filesystem::path("out/my_scene.exr"));
    EXPECT_THROW(loadScene(dir / "missing.json"), InputError);
}

TEST(Scene, ValidateChecksOverriddenFields) {
    Scene s = parseScene(validScene(), "scene.json", "/");
    s.camera.width = 0;
    EXPECT_THROW(s.validate(), InputError);
    s = parseScene(validScene(), "scene.json", "/");
    s.voxelSize = -1.0f;
    EXPECT_THROW(s.validate(), InputError);
    s = parseScene(validScene(), "scene.json", "/");
    s.lights[1].name = "light0";
    EXPECT_THROW(s.validate(), InputError);
}

TEST(Scene, MeshesAreReadAndCheckedFieldByField) {
    nlohmann::json j = validScene();
    j["meshes"] = nlohmann::json::parse(R"([
      {"file": "body.obj", "color": [0.5, 0.4, 0.3],
       "transform": {"scale": 2, "rotate": [0, 90, 0], "translate": [1, 2, 3]}},
      {"mannequin": {"center": [0, 1, 0], "radius": 0.2, "rings": 32}}
    ])");
    const Scene s = parseScene(j, "scene.json", "/scenes");
    ASSERT_EQ(s.meshes.size(), 2u);
    EXPECT_EQ(s.meshes[0].file, std::filesystem::path("/scenes/body.obj"));
    EXPECT_EQ(s.meshes[0].transform.scale, Vec3f(2.0f));
    EXPECT_EQ(s.meshes[0].transform.rotateDegrees, Vec3f(0.0f, 90.0f, 0.0f));
    EXPECT_EQ(s.meshes[0].albedo, Rgb(0.5f, 0.4f, 0.3f));
    EXPECT_TRUE(s.meshes[1].isMannequin());
    EXPECT_EQ(s.meshes[1].mannequin.radius, 0.2f);
    EXPECT_EQ(s.meshes[1].mannequinRings, 32);

    const auto errorWith = [](const char* mesh) {
        nlohmann::json bad = validScene();
        bad["meshes"] = nlohmann::json::array({nlohmann::json::parse(mesh)});
        return errorOf(bad);
    };
    EXPECT_EQ(errorWith(R"({"color": [1, 1, 1]})"),
              "scene.json: /meshes/0: expected exactly one of \"file\" (an OBJ mesh) and "
              "\"mannequin\" (a generated head)");
    EXPECT_EQ(errorWith(R"({"file": 3})"), "scene.json: /meshes/0/file: expected a string, got 3");
    EXPECT_NE(errorWith(R"({"file": "a.obj", "transform": {"scale": 0}})")
                  .find("/meshes/0/transform/scale"),
              std::string::npos);
    EXPECT_NE(errorWith(R"({"mannequin": {"rings": 4}})").find("/meshes/0/mannequin/rings"),
              std::string::npos);
    EXPECT_NE(errorWith(R"({"file": "a.obj", "colour": [1, 1, 1]})").find("colour"),
              std::string::npos);
    EXPECT_NE(errorWith(R"({"file": "a.obj", "color": [2, 0, 0]})").find("/meshes/0/color"),
              std::string::npos);
}

TEST(Scene, GroomAttributeRulesAndFiberColourAreRead) {
    nlohmann::json j = validScene();
    j["groom"] = {{"file", "x.hair"}, {"thickness", "scale"}, {"color", "ignore"}};
    j["fiber"] = {{"color", {0.5, 0.4, 0.3}}};
    const Scene s = parseScene(j, "scene.json", "/scenes");
    EXPECT_EQ(s.groom.thickness, GroomThickness::Scale);
    EXPECT_EQ(s.groom.color, GroomColor::Ignore);
    EXPECT_EQ(s.fiber.sigma_a, FiberParams::sigmaFromColor(Rgb(0.5f, 0.4f, 0.3f)));
    const Scene d = parseScene(validScene(), "scene.json", "/scenes");
    EXPECT_EQ(d.groom.thickness, GroomThickness::Auto);
    EXPECT_EQ(d.groom.color, GroomColor::Use);

    nlohmann::json c = validScene();
    c["groom"]["procedural"]["colors"] = {{0.8, 0.6, 0.4}, {0.1, 0.05, 0.02}};
    EXPECT_EQ(parseScene(c, "scene.json", "/scenes").groom.procedural.colors.size(), 2u);
    c["groom"]["procedural"]["colors"] = nlohmann::json::array();
    EXPECT_NE(errorOf(c).find("/groom/procedural/colors"), std::string::npos) << errorOf(c);
    c["groom"]["procedural"]["colors"] = {{0.8, 0.6, 2.0}};
    EXPECT_NE(errorOf(c).find("/groom/procedural/colors/0"), std::string::npos) << errorOf(c);

    j["groom"]["thickness"] = "radius";
    EXPECT_NE(errorOf(j).find("/groom/thickness"), std::string::npos) << errorOf(j);
    j["groom"]["thickness"] = "diameter";
    j["groom"]["color"] = true;
    EXPECT_NE(errorOf(j).find("/groom/color"), std::string::npos) << errorOf(j);
    j["groom"]["color"] = "use";
    j["fiber"]["color"] = {1.5, 0, 0};
    EXPECT_NE(errorOf(j).find("/fiber/color"), std::string::npos) << errorOf(j);
}

TEST(Scene, DefaultSceneIsTheShowcase) {
    const Scene s = defaultScene();
    EXPECT_TRUE(s.groom.isProcedural());
    EXPECT_EQ(s.groom.procedural.style, GroomStyle::Wavy);
    EXPECT_GE(s.groom.procedural.strands, 15000u);
    EXPECT_LE(s.groom.procedural.strands, 25000u);
    // Light blond (docs/scene.md): eumelanin 0.12, pheomelanin 0.2.
    EXPECT_EQ(s.fiber.sigma_a, FiberParams::sigmaFromMelanin(0.12f, 0.2f));
    // On a mannequin head whose cranium is the groom's head sphere.
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_TRUE(s.meshes[0].isMannequin());
    EXPECT_EQ(s.meshes[0].mannequin.center, s.groom.procedural.headCenter);
    EXPECT_EQ(s.meshes[0].mannequin.radius, s.groom.procedural.headRadius);
    // Lit as look development starts (issue 37): a built-in studio map, seen
    // behind the groom, and no other light.
    EXPECT_TRUE(s.lights.empty());
    ASSERT_TRUE(s.environment.has_value());
    EXPECT_EQ(s.environment->builtin, "studio");
    EXPECT_TRUE(s.environment->visible);
    EXPECT_EQ(s.camera.width, 1024u);
    EXPECT_EQ(s.camera.height, 1024u);
    EXPECT_EQ(s.globalTermMode, GlobalTermMode::Grid);
    EXPECT_EQ(s.output.exr, std::filesystem::path("out/default.exr"));
    EXPECT_EQ(s.output.png, std::filesystem::path("out/default.png"));
}

TEST(Scene, TheKeyAndBackSceneIsTheDefaultLookUnderTwoLights) {
    const Scene s = test::keyBackScene();
    const Scene d = defaultScene();
    EXPECT_EQ(s.groom.procedural.strands, d.groom.procedural.strands);
    EXPECT_EQ(s.fiber.sigma_a, d.fiber.sigma_a);
    EXPECT_EQ(s.camera.position, d.camera.position);
    EXPECT_FALSE(s.environment.has_value());
    ASSERT_EQ(s.lights.size(), 2u);
    // A back light: it shines from behind the hair toward the camera.
    bool backLit = false;
    for (const Light& l : s.lights)
        backLit |=
            glm::dot(l.direction, glm::normalize(s.camera.position - s.camera.lookAt)) < -0.3f;
    EXPECT_TRUE(backLit);
}

TEST(Scene, EmbeddedDefaultSceneMatchesTheDataFile) {
    std::ifstream in(test::dataDir() / "scenes/default.json");
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), std::string(defaultSceneJson()));
}

TEST(Scene, ExampleScenesParse) {
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(test::dataDir() / "scenes")) {
        if (entry.path().extension() != ".json")
            continue;
        SCOPED_TRACE(entry.path().string());
        EXPECT_NO_THROW(loadScene(entry.path()));
        ++count;
    }
    EXPECT_GE(count, 1);
}

} // namespace
} // namespace hairvox
