#include "dual_scattering_fragment_shader.h"
#include "json_reader.h"

#include <hairvox/core/error.h>
#include <hairvox/geometry/builtin_environment.h>
#include <hairvox/pipeline/scene.h>
#include <hairvox/volumetric/spherical_harmonics.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <iterator>

namespace hairvox {

using json::JsonObject;
using json::JsonValue;
using json::Range;

namespace {

// Valid ranges of the scene's own fields, used by the JSON reader (with the
// JSON path) and by Scene::validate() (with the field name).
constexpr Range kCoordinate{-1e6, 1e6};
constexpr Range kLightColor{0.0, 1000.0};
constexpr Range kLightIntensity{0.0, 1e6};
constexpr Range kFovDegrees{0.1, 170.0};
constexpr Range kHeadRadius{1e-6, 1e4};
constexpr Range kAlbedo{0.0, 1.0};
constexpr Range kVoxelSize{0.0, 1000.0, true};
constexpr Range kFiberSampleSpacing{0.0, 4.0};
constexpr std::uint64_t kMaxExactRays = 65536;
/// output.layers: more names than any scene has layers (27 + 8 per light).
constexpr std::size_t kMaxLayers = 256;
constexpr Range kExactRadius{0.0, 1000.0};
constexpr Range kBackground{0.0, 1e6};
constexpr Range kShadingTolerance{0.0, 1.0};
constexpr Range kTailTransmittance{0.0, 1.0};
constexpr Range kExposure{-20.0, 20.0};
constexpr Range kTimeLimit{0.0, 1e7};
constexpr Range kPathsPerCell{0.0, 1e4, true};
constexpr Range kDegrees{-360.0, 360.0};
constexpr Range kAny{-1e30, 1e30};
constexpr Range kMeshScale{-1e6, 1e6};
constexpr std::size_t kMaxLightNameLength = 32;
constexpr std::uint32_t kMaxEnvironmentLights = 1024;
constexpr std::uintmax_t kMaxSceneFileBytes = 16u << 20;

/// Calls `check` (an owner's validate()) and re-throws its InputError under
/// the JSON path of the value that was just read.
template <typename At, typename F>
void checkAt(const At& at, F&& check) {
    try {
        check();
    } catch (const InputError& e) {
        at.fail(e.what());
    }
}

void requireInRange(const std::string& field, double x, const Range& range) {
    if (!range.contains(x))
        throw InputError(strCat(field, " = ", x, ": expected a number ", range.describe()));
}

void requireInRange(const std::string& field, const Vec3f& v, const Range& range) {
    for (int c = 0; c < 3; ++c)
        requireInRange(field, double(v[c]), range);
}

void requireInRange(const std::string& field, const Rgb& v, const Range& range) {
    for (int c = 0; c < 3; ++c)
        requireInRange(field, double(v[c]), range);
}

constexpr const char* kLightNameRule = "a name of 1 to 32 letters, digits, '_' or '-'";

/// Light names prefix EXR layer names, which must not contain '.'.
bool isValidLightName(const std::string& name) {
    if (name.empty() || name.size() > kMaxLightNameLength)
        return false;
    return std::all_of(name.begin(), name.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
               c == '_' || c == '-';
    });
}

// --- groom -----------------------------------------------------------------

ProceduralGroomParams parseProcedural(JsonObject obj) {
    ProceduralGroomParams p;
    // Each value is checked by ProceduralGroomParams::validate() right after it
    // is set (the others are still valid), so a range error names its own path.
    auto set = [&](std::string_view key, auto assign) {
        const JsonValue v = obj[key];
        if (!v.present())
            return;
        assign(v);
        checkAt(v, [&] { p.validate(); });
    };
    set("style", [&](const JsonValue& v) { p.style = v.oneOf(kGroomStyleNames); });
    set("strands", [&](const JsonValue& v) {
        p.strands = static_cast<std::uint32_t>(v.integer(1, 10'000'000));
    });
    set("points_per_strand", [&](const JsonValue& v) {
        p.pointsPerStrand = static_cast<std::uint32_t>(v.integer(2, 4096));
    });
    set("seed", [&](const JsonValue& v) {
        p.seed = v.integer(0, std::numeric_limits<std::uint64_t>::max());
    });
    set("length", [&](const JsonValue& v) { p.length = v.numberF(kAny); });
    set("length_variation", [&](const JsonValue& v) { p.lengthVariation = v.numberF(kAny); });
    set("wave_amplitude", [&](const JsonValue& v) { p.waveAmplitude = v.numberF(kAny); });
    set("wave_length", [&](const JsonValue& v) { p.waveLength = v.numberF(kAny); });
    set("curl_radius", [&](const JsonValue& v) { p.curlRadius = v.numberF(kAny); });
    set("curl_pitch", [&](const JsonValue& v) { p.curlPitch = v.numberF(kAny); });
    set("clump_strength", [&](const JsonValue& v) { p.clumpStrength = v.numberF(kAny); });
    set("colors", [&](const JsonValue& v) {
        p.colors.clear();
        for (const JsonValue& c : v.array(1, kMaxFiberTypes))
            p.colors.push_back(c.rgb(kAlbedo));
    });
    set("head_center", [&](const JsonValue& v) { p.headCenter = v.vec3(kCoordinate); });
    set("head_radius", [&](const JsonValue& v) { p.headRadius = v.numberF(kAny); });
    obj.finish();
    const std::uint64_t points = std::uint64_t(p.strands) * p.resolvedPointsPerStrand();
    if (points > kMaxProceduralPoints)
        obj["strands"].fail(strCat(p.strands, " strands x ", p.resolvedPointsPerStrand(),
                                   " points = ", points, " points: expected at most ",
                                   kMaxProceduralPoints));
    return p;
}

/// A file named in the scene: a non-empty path, resolved against the scene
/// file's directory unless absolute.
std::filesystem::path scenePath(const JsonValue& v, const std::filesystem::path& baseDir) {
    const std::string name = v.string();
    if (name.empty())
        v.failExpected("a non-empty path");
    const std::filesystem::path path(name);
    return path.is_absolute() ? path : baseDir / path;
}

GroomSource parseGroom(JsonObject obj, const std::filesystem::path& baseDir) {
    GroomSource g;
    const JsonValue file = obj["file"];
    const JsonValue procedural = obj["procedural"];
    if (file.present() == procedural.present())
        obj.fail("expected exactly one of \"file\" and \"procedural\"");
    if (file.present()) {
        g.file = scenePath(file, baseDir);
    } else {
        g.procedural = parseProcedural(procedural.object());
    }
    if (const JsonValue v = obj["thickness"]; v.present())
        g.thickness = v.oneOf(kGroomThicknessNames);
    if (const JsonValue v = obj["color"]; v.present())
        g.color = v.oneOf(kGroomColorNames);
    obj.finish();
    return g;
}

// --- fiber -------------------------------------------------------------------

void parseFiber(JsonObject obj, Scene& scene) {
    const auto setScale = [&](std::string_view key, float FiberScale::*field) {
        const JsonValue v = obj[key];
        if (!v.present())
            return;
        scene.fiberScale.*field = v.numberF(kAny);
        checkAt(v, [&] { scene.fiberScale.validate(); });
    };
    setScale("diameter", &FiberScale::diameter);
    setScale("density_multiplier", &FiberScale::densityMultiplier);

    FiberParams& f = scene.fiber;
    auto set = [&](std::string_view key, auto assign) {
        const JsonValue v = obj[key];
        if (!v.present())
            return;
        assign(v);
        checkAt(v, [&] { f.validate(); });
    };
    set("eta", [&](const JsonValue& v) { f.eta = v.numberF(kAny); });
    const JsonValue melanin = obj["melanin"];
    const int absorptionKeys =
        int(obj.has("sigma_a")) + int(melanin.present()) + int(obj.has("color"));
    if (absorptionKeys > 1)
        obj.fail("give one of sigma_a, melanin and color, not several");
    set("sigma_a", [&](const JsonValue& v) { f.sigma_a = v.rgb(kAny); });
    set("color",
        [&](const JsonValue& v) { f.sigma_a = FiberParams::sigmaFromColor(v.rgb(kAlbedo)); });
    if (melanin.present()) {
        JsonObject m = melanin.object();
        const JsonValue eu = m["eumelanin"], pheo = m["pheomelanin"];
        const float c_eu = eu.present() ? eu.numberF(kAny) : 0.0f;
        const float c_pheo = pheo.present() ? pheo.numberF(kAny) : 0.0f;
        m.finish();
        checkAt(melanin, [&] { f.sigma_a = FiberParams::sigmaFromMelanin(c_eu, c_pheo); });
        checkAt(melanin, [&] { f.validate(); });
    }
    set("alpha_R", [&](const JsonValue& v) { f.alpha_R = radians(v.numberF(kDegrees)); });
    set("beta_R", [&](const JsonValue& v) { f.beta_R = radians(v.numberF(kDegrees)); });
    set("eccentricity", [&](const JsonValue& v) { f.eccentricity = v.numberF(kAny); });
    set("caustic_width",
        [&](const JsonValue& v) { f.causticWidth = radians(v.numberF(kDegrees)); });
    set("caustic_gain", [&](const JsonValue& v) { f.causticGain = v.numberF(kAny); });
    set("caustic_fade", [&](const JsonValue& v) { f.causticFade = v.numberF(kAny); });
    set("caustic_max_width", [&](const JsonValue& v) { f.causticMaxWidth = v.numberF(kAny); });
    obj.finish();
}

void parseDualScattering(JsonObject obj, Scene& scene) {
    DualScatteringParams& d = scene.dualScattering;
    for (const char* key : {"d_f", "d_b"}) {
        const JsonValue v = obj[key];
        if (!v.present())
            continue;
        (key[2] == 'f' ? d.d_f : d.d_b) = v.numberF(kAny);
        checkAt(v, [&] { d.validate(); });
    }
    if (const JsonValue v = obj["environment_lights"]; v.present())
        scene.environmentLights = static_cast<std::uint32_t>(v.integer(1, kMaxEnvironmentLights));
    obj.finish();
}

// --- lights, camera, head ----------------------------------------------------

/// A light's "name", or `fallback`.
std::string parseLightName(JsonObject& obj, std::string fallback) {
    if (const JsonValue v = obj["name"]; v.present()) {
        fallback = v.string();
        if (!isValidLightName(fallback))
            v.failExpected(kLightNameRule);
    }
    return fallback;
}

/// A directional or point light (its "type" already read).
Light parseLight(JsonObject obj, Light::Kind kind, std::size_t index) {
    Light light;
    light.name = parseLightName(obj, strCat("light", index));
    if (kind == Light::Kind::Directional) {
        const JsonValue v = obj.required("direction", "a vector toward the light");
        const Vec3f d = v.vec3(kCoordinate);
        if (!(glm::length(d) > 0))
            v.failExpected("a non-zero vector from the scene toward the light");
        light.kind = Light::Kind::Directional;
        light.direction = glm::normalize(d);
    } else {
        light.kind = Light::Kind::Point;
        light.position = obj.required("position", "the light's position").vec3(kCoordinate);
    }
    if (const JsonValue v = obj["color"]; v.present())
        light.color = v.rgb(kLightColor);
    if (const JsonValue v = obj["intensity"]; v.present())
        light.intensity = v.numberF(kLightIntensity);
    obj.finish();
    return light;
}

EnvironmentLight parseEnvironment(JsonObject obj, const std::filesystem::path& baseDir) {
    EnvironmentLight env;
    env.name = parseLightName(obj, env.name);
    if (const JsonValue v = obj["file"]; v.present())
        env.file = scenePath(v, baseDir);
    if (const JsonValue v = obj["builtin"]; v.present()) {
        env.builtin = v.string();
        if (!env.file.empty())
            v.failExpected("either \"file\" or \"builtin\", not both");
        if (!findBuiltinEnvironment(env.builtin))
            v.failExpected(strCat("one of ", builtinEnvironmentNames()));
    }
    if (const JsonValue v = obj["color"]; v.present())
        env.color = v.rgb(kLightColor);
    if (const JsonValue v = obj["intensity"]; v.present())
        env.intensity = v.numberF(kLightIntensity);
    if (const JsonValue v = obj["rotation"]; v.present())
        env.rotation = v.numberF(kDegrees);
    if (const JsonValue v = obj["visible"]; v.present())
        env.visible = v.boolean();
    obj.finish();
    return env;
}

CameraParams parseCamera(JsonObject obj) {
    CameraParams c;
    c.position = obj.required("position", "an array of 3 numbers").vec3(kCoordinate);
    c.lookAt = obj.required("look_at", "an array of 3 numbers").vec3(kCoordinate);
    if (const JsonValue v = obj["up"]; v.present())
        c.up = v.vec3(kCoordinate);
    if (const JsonValue v = obj["fov"]; v.present())
        c.fovY = v.numberF(kFovDegrees);
    if (const JsonValue v = obj["resolution"]; v.present()) {
        const std::vector<JsonValue> wh = v.array(2, 2);
        c.width = static_cast<std::uint32_t>(wh[0].integer(1, kMaxResolution));
        c.height = static_cast<std::uint32_t>(wh[1].integer(1, kMaxResolution));
        if (std::uint64_t(c.width) * c.height > kMaxPixels)
            v.fail(strCat(c.width, " x ", c.height, ": expected at most ", kMaxPixels, " pixels"));
    }
    obj.finish();
    checkAt(obj, [&] { Camera camera(c); });
    return c;
}

Head parseHead(JsonObject obj) {
    Head h;
    if (const JsonValue v = obj["center"]; v.present())
        h.sphere.center = v.vec3(kCoordinate);
    if (const JsonValue v = obj["radius"]; v.present())
        h.sphere.radius = v.numberF(kHeadRadius);
    if (const JsonValue v = obj["color"]; v.present())
        h.albedo = v.rgb(kAlbedo);
    obj.finish();
    return h;
}

MeshTransform parseMeshTransform(JsonObject obj) {
    MeshTransform t;
    if (const JsonValue v = obj["scale"]; v.present()) {
        t.scale = v.isNumber() ? Vec3f(v.numberF(kMeshScale)) : v.vec3(kMeshScale);
        if (t.scale.x * t.scale.y * t.scale.z == 0.0f)
            v.failExpected("a non-zero scale (a number or 3 numbers)");
    }
    if (const JsonValue v = obj["rotate"]; v.present())
        t.rotateDegrees = v.vec3(kDegrees);
    if (const JsonValue v = obj["translate"]; v.present())
        t.translate = v.vec3(kCoordinate);
    obj.finish();
    return t;
}

MeshSource parseMesh(JsonObject obj, const std::filesystem::path& baseDir) {
    MeshSource m;
    const JsonValue file = obj["file"];
    const JsonValue mannequin = obj["mannequin"];
    if (file.present() == mannequin.present())
        obj.fail(
            "expected exactly one of \"file\" (an OBJ mesh) and \"mannequin\" (a generated head)");
    if (file.present()) {
        m.file = scenePath(file, baseDir);
    } else {
        JsonObject head = mannequin.object();
        if (const JsonValue v = head["center"]; v.present())
            m.mannequin.center = v.vec3(kCoordinate);
        if (const JsonValue v = head["radius"]; v.present())
            m.mannequin.radius = v.numberF(kHeadRadius);
        if (const JsonValue v = head["rings"]; v.present())
            m.mannequinRings = static_cast<int>(v.integer(8, 1024));
        head.finish();
    }
    if (const JsonValue v = obj["transform"]; v.present())
        m.transform = parseMeshTransform(v.object());
    if (const JsonValue v = obj["color"]; v.present())
        m.albedo = v.rgb(kAlbedo);
    obj.finish();
    return m;
}

std::filesystem::path parseOutputPath(const JsonValue& v, const std::filesystem::path& fallback) {
    if (!v.present())
        return fallback;
    if (v.isNull())
        return {};
    const std::string s = v.string();
    if (s.empty() || s.back() == '/')
        v.failExpected("a file path or null (not written)");
    return s;
}

OutputSettings parseOutput(JsonObject obj, const std::string& stem) {
    OutputSettings o;
    o.exr = parseOutputPath(obj["exr"], std::filesystem::path("out") / (stem + ".exr"));
    o.png = parseOutputPath(obj["png"], std::filesystem::path("out") / (stem + ".png"));
    if (const JsonValue v = obj["exposure"]; v.present())
        o.exposure = v.numberF(kExposure);
    if (const JsonValue v = obj["tone_map"]; v.present())
        o.toneMap = v.oneOf(kToneMapNames);
    if (const JsonValue v = obj["exr_zip_level"]; v.present())
        o.exrZipLevel = static_cast<int>(v.integer(1, 9));
    if (const JsonValue v = obj["exr_compression"]; v.present())
        o.exrCompression = v.oneOf(kExrCompressionNames);
    if (const JsonValue v = obj["layers"]; v.present()) {
        if (!v.isString()) {
            o.layers.emplace();
            for (const JsonValue& name : v.array(0, kMaxLayers))
                o.layers->push_back(name.string());
        } else if (const std::string s = v.string(); s == "none") {
            o.layers.emplace();
        } else if (s != "all") {
            v.failExpected("\"all\", \"none\" or an array of layer names");
        }
    }
    obj.finish();
    return o;
}

} // namespace

ExrSource EnvironmentLight::source() const {
    return builtin.empty() ? ExrSource::file(file) : builtinEnvironment(builtin).source();
}

std::string EnvironmentLight::sourceName() const {
    return isUniform() ? std::string("uniform") : source().name;
}

void Scene::validate() const {
    if (groom.isProcedural()) {
        groom.procedural.validate();
        if (std::uint64_t(groom.procedural.strands) * groom.procedural.resolvedPointsPerStrand() >
            kMaxProceduralPoints)
            throw InputError(
                strCat("groom.procedural: more than ", kMaxProceduralPoints, " points"));
    }
    fiberScale.validate();
    fiber.validate();
    dualScattering.validate();

    if (lights.size() > kMaxLights)
        throw InputError(strCat(lights.size(), " lights: expected at most ", kMaxLights));
    for (std::size_t i = 0; i < lights.size(); ++i) {
        const Light& l = lights[i];
        const std::string field = strCat("lights[", i, "]");
        if (!isValidLightName(l.name))
            throw InputError(strCat(field, ".name \"", l.name, "\": expected ", kLightNameRule));
        for (std::size_t j = 0; j < i; ++j)
            if (lights[j].name == l.name)
                throw InputError(strCat(field, ".name \"", l.name, "\": used by lights[", j,
                                        "] too; light names must be unique"));
        if (l.kind == Light::Kind::Directional) {
            if (!isFinite(l.direction) || std::abs(glm::length(l.direction) - 1.0f) > 1e-4f)
                throw InputError(strCat(field, ".direction: expected a unit vector"));
        } else {
            requireInRange(field + ".position", l.position, kCoordinate);
        }
        requireInRange(field + ".color", l.color, kLightColor);
        requireInRange(field + ".intensity", l.intensity, kLightIntensity);
    }

    if (environment) {
        const EnvironmentLight& e = *environment;
        if (!isValidLightName(e.name))
            throw InputError(
                strCat("environment.name \"", e.name, "\": expected ", kLightNameRule));
        for (std::size_t j = 0; j < lights.size(); ++j)
            if (lights[j].name == e.name)
                throw InputError(strCat("environment.name \"", e.name, "\": used by lights[", j,
                                        "] too; light names must be unique"));
        requireInRange("environment.color", e.color, kLightColor);
        requireInRange("environment.intensity", e.intensity, kLightIntensity);
        requireInRange("environment.rotation", e.rotation, kDegrees);
    }
    if (environmentLights < 1 || environmentLights > kMaxEnvironmentLights)
        throw InputError(strCat("dual_scattering.environment_lights = ", environmentLights,
                                ": expected an integer in [1, ", kMaxEnvironmentLights, "]"));

    const Camera cam(camera); // checks the frame, field of view and resolution
    if (head) {
        requireInRange("head.center", head->sphere.center, kCoordinate);
        requireInRange("head.radius", head->sphere.radius, kHeadRadius);
        requireInRange("head.color", head->albedo, kAlbedo);
        if (glm::distance(camera.position, head->sphere.center) <= head->sphere.radius)
            throw InputError("camera.position is inside the head sphere");
    }
    if (meshes.size() > kMaxMeshes)
        throw InputError(strCat(meshes.size(), " meshes: expected at most ", kMaxMeshes));
    for (std::size_t i = 0; i < meshes.size(); ++i) {
        const MeshSource& m = meshes[i];
        const std::string field = strCat("meshes[", i, "]");
        if (m.isMannequin()) {
            requireInRange(field + ".mannequin.center", m.mannequin.center, kCoordinate);
            requireInRange(field + ".mannequin.radius", m.mannequin.radius, kHeadRadius);
            if (m.mannequinRings < 8 || m.mannequinRings > 1024)
                throw InputError(strCat(field, ".mannequin.rings = ", m.mannequinRings,
                                        ": expected an integer in [8, 1024]"));
        }
        requireInRange(field + ".transform.scale", m.transform.scale, kMeshScale);
        if (m.transform.scale.x * m.transform.scale.y * m.transform.scale.z == 0.0f)
            throw InputError(strCat(field, ".transform.scale: expected non-zero components"));
        requireInRange(field + ".transform.rotate", m.transform.rotateDegrees, kDegrees);
        requireInRange(field + ".transform.translate", m.transform.translate, kCoordinate);
        requireInRange(field + ".color", m.albedo, kAlbedo);
    }
    if (voxelSize)
        requireInRange("grid.voxel_size", *voxelSize, kVoxelSize);
    if (fiberSampleSpacing)
        requireInRange("grid.fiber_sample_spacing", *fiberSampleSpacing, kFiberSampleSpacing);
    if (exact.rays < 1 || exact.rays > kMaxExactRays)
        throw InputError(strCat("global_term.exact.rays = ", exact.rays,
                                ": expected an integer in [1, ", kMaxExactRays, "]"));
    requireInRange("global_term.exact.radius", exact.radius, kExactRadius);
    requireInRange("background", background, kBackground);
    requireInRange("shading_tolerance", shadingTolerance, kShadingTolerance);
    requireInRange("tail_transmittance", tailTransmittance, kTailTransmittance);
    try {
        pathTrace.validate();
        volumetric.validate();
    } catch (const InputError& e) {
        throw InputError(strCat("integrator: ", e.what()));
    }
    requireInRange("output.exposure", output.exposure, kExposure);
    if (output.exrZipLevel < 1 || output.exrZipLevel > 9)
        throw InputError(strCat("output.exr_zip_level = ", output.exrZipLevel,
                                " should be in the range [1, 9]"));
    if (!output.exr.empty() && output.exr.lexically_normal() == output.png.lexically_normal())
        throw InputError(strCat("output.exr and output.png are both \"", output.exr.string(),
                                "\": the EXR and the PNG need different paths"));
    if (output.layers) {
        if (integrator == Integrator::Path)
            throw InputError("output.layers: the path integrator writes every layer (--continue "
                             "reads them back); give \"all\" or leave it out");
        const std::vector<RasterLayer> known = layersOf(*this);
        const auto& names = *output.layers;
        for (std::size_t i = 0; i < names.size(); ++i) {
            const std::string field = strCat("output.layers[", i, "] \"", names[i], "\"");
            if (std::none_of(known.begin(), known.end(),
                             [&](const RasterLayer& l) { return l.name == names[i]; })) {
                std::string valid;
                for (const RasterLayer& l : known)
                    valid += (valid.empty() ? "" : ", ") + l.name;
                throw InputError(strCat(field,
                                        ": not a layer of this scene; expected \"all\", "
                                        "\"none\" or some of: ",
                                        valid));
            }
            if (std::find(names.begin(), names.begin() + std::ptrdiff_t(i), names[i]) !=
                names.begin() + std::ptrdiff_t(i))
                throw InputError(strCat(field, " is named twice"));
        }
    }
}

std::vector<RasterLayer> layersOf(const Scene& scene) {
    return rasterLayers(
        detail::hairShaderLayout(scene.lights, scene.integrator == Integrator::Volumetric));
}

Scene parseScene(const nlohmann::json& document, const std::string& sourceName,
                 const std::filesystem::path& baseDir) {
    Scene scene;
    scene.name = sourceName;
    JsonObject root = JsonValue(&document, "", sourceName).object();

    scene.groom = parseGroom(root.required("groom", "an object").object(), baseDir);
    if (const JsonValue v = root["fiber"]; v.present())
        parseFiber(v.object(), scene);
    if (const JsonValue v = root["dual_scattering"]; v.present())
        parseDualScattering(v.object(), scene);

    const JsonValue lights = root.required("lights", "an array of lights");
    std::vector<std::string> names; // in the file's order, the environment's too
    std::size_t environmentIndex = 0;
    for (const JsonValue& l : lights.array(0, kMaxLights)) {
        JsonObject obj = l.object();
        const std::string type =
            obj.required("type", "\"directional\", \"point\" or \"environment\"")
                .oneOf({"directional", "point", "environment"});
        if (type == "environment") {
            if (scene.environment)
                l.fail(strCat("a second environment light (the first is lights ", environmentIndex,
                              "): a scene has at most one; combine the maps into one"));
            environmentIndex = names.size();
            scene.environment = parseEnvironment(obj, baseDir);
            names.push_back(scene.environment->name);
        } else {
            scene.lights.push_back(parseLight(obj, *kLightKindNames.parse(type), names.size()));
            names.push_back(scene.lights.back().name);
        }
    }
    for (std::size_t i = 0; i < names.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            if (names[i] == names[j])
                lights.fail(strCat("lights ", j, " and ", i, " are both named \"", names[i],
                                   "\"; light names must be unique"));

    scene.camera = parseCamera(root.required("camera", "an object").object());
    if (const JsonValue v = root["head"]; v.present() && !v.isNull())
        scene.head = parseHead(v.object());
    if (const JsonValue v = root["meshes"]; v.present())
        for (const JsonValue& m : v.array(0, kMaxMeshes))
            scene.meshes.push_back(parseMesh(m.object(), baseDir));

    if (const JsonValue v = root["grid"]; v.present()) {
        JsonObject grid = v.object();
        if (const JsonValue s = grid["voxel_size"]; s.present() && !s.isString())
            scene.voxelSize = s.numberF(kVoxelSize);
        else if (s.present() && s.string() != "auto")
            s.failExpected(strCat("\"auto\" or a number ", kVoxelSize.describe()));
        if (const JsonValue s = grid["fiber_sample_spacing"]; s.present())
            scene.fiberSampleSpacing = s.numberF(kFiberSampleSpacing);
        grid.finish();
    }
    if (const JsonValue v = root["global_term"]; v.present()) {
        JsonObject gt = v.object();
        if (const JsonValue m = gt["mode"]; m.present())
            scene.globalTermMode = m.oneOf(kGlobalTermModeNames);
        if (const JsonValue e = gt["exact"]; e.present()) {
            JsonObject exact = e.object();
            if (const JsonValue r = exact["rays"]; r.present())
                scene.exact.rays = static_cast<std::uint32_t>(r.integer(1, kMaxExactRays));
            if (const JsonValue r = exact["radius"]; r.present())
                scene.exact.radius = r.numberF(kExactRadius);
            if (const JsonValue r = exact["seed"]; r.present())
                scene.exact.seed = r.integer(0, std::numeric_limits<std::uint64_t>::max());
            exact.finish();
        }
        gt.finish();
    }
    if (const JsonValue v = root["integrator"]; v.present()) {
        if (v.isString()) {
            scene.integrator = v.oneOf(kIntegratorNames);
        } else {
            JsonObject in = v.object();
            scene.integrator =
                in.required("type", "\"dual_scattering\", \"path\" or \"volumetric\"")
                    .oneOf(kIntegratorNames);
            PathTraceSettings& pt = scene.pathTrace;
            VolumetricSettings& vol = scene.volumetric;
            // A key applies to the integrators it names; each value is checked
            // against its integrator's ranges as it is read.
            using Owners = std::vector<Integrator>;
            const auto set = [&](std::string_view key, const Owners& owners, auto assign) {
                const JsonValue x = in[key];
                if (!x.present())
                    return;
                if (std::find(owners.begin(), owners.end(), scene.integrator) == owners.end()) {
                    std::string owning;
                    for (const Integrator o : owners)
                        owning += strCat(owning.empty() ? "" : " and ", "\"", toString(o), "\"");
                    x.fail(strCat("applies to the ", owning, " integrator",
                                  owners.size() > 1 ? "s" : "", " only (\"type\")"));
                }
                assign(x);
                checkAt(x, [&] {
                    if (scene.integrator == Integrator::Path)
                        pt.validate();
                    else
                        vol.validate();
                });
            };
            const Owners path{Integrator::Path}, volumetric{Integrator::Volumetric};
            const Owners traced{Integrator::Path, Integrator::Volumetric};
            set("spp", path, [&](const JsonValue& x) {
                pt.spp = static_cast<std::uint32_t>(x.integer(1, 1'000'000));
            });
            set("time_limit", path,
                [&](const JsonValue& x) { pt.timeLimit = x.number(kTimeLimit); });
            const auto depth = [&](const JsonValue& x) {
                return static_cast<std::uint32_t>(x.integer(1, 100'000));
            };
            set("max_depth", traced, [&](const JsonValue& x) {
                (scene.integrator == Integrator::Path ? pt.maxDepth : vol.maxDepth) = depth(x);
            });
            set("roulette_depth", traced, [&](const JsonValue& x) {
                (scene.integrator == Integrator::Path ? pt.rouletteDepth : vol.rouletteDepth) =
                    depth(x);
            });
            set("seed", traced, [&](const JsonValue& x) {
                (scene.integrator == Integrator::Path ? pt.seed : vol.seed) =
                    x.integer(0, std::numeric_limits<std::uint64_t>::max());
            });
            set("paths", volumetric,
                [&](const JsonValue& x) { vol.paths = x.integer(1, 1ull << 40); });
            set("paths_per_cell", volumetric,
                [&](const JsonValue& x) { vol.pathsPerCell = x.numberF(kPathsPerCell); });
            set("cell_voxels", volumetric, [&](const JsonValue& x) {
                vol.cache.cellVoxels = static_cast<int>(x.integer(1, 16));
            });
            set("sh_order", volumetric, [&](const JsonValue& x) {
                vol.cache.shOrder = static_cast<int>(x.integer(1, SphericalHarmonics::kMaxOrder));
            });
            set("denoise", volumetric,
                [&](const JsonValue& x) { vol.cache.denoise = x.boolean(); });
            set("gradients", volumetric,
                [&](const JsonValue& x) { vol.cache.gradients = x.boolean(); });
            set("transport", volumetric,
                [&](const JsonValue& x) { vol.transport = x.oneOf(kVolumetricTransportNames); });
            in.finish();
        }
    }
    if (const JsonValue v = root["shading_rate"]; v.present())
        scene.shadingRate = v.oneOf(kShadingRateNames);
    if (const JsonValue v = root["shading_tolerance"]; v.present()) {
        if (scene.shadingRate != ShadingRate::Adaptive)
            v.fail("applies to the adaptive shading rate only (\"shading_rate\": \"adaptive\")");
        scene.shadingTolerance = v.numberF(kShadingTolerance);
    }
    if (const JsonValue v = root["tail_transmittance"]; v.present()) {
        if (scene.shadingRate == ShadingRate::Vertex)
            v.fail("applies to the fragment and adaptive shading rates (the vertex rate "
                   "interpolates all the hair)");
        scene.tailTransmittance = v.numberF(kTailTransmittance);
    }
    if (const JsonValue v = root["background"]; v.present())
        scene.background = v.rgb(kBackground);

    const std::string stem = std::filesystem::path(sourceName).stem().string();
    const nlohmann::json noOutput = nlohmann::json::object();
    const JsonValue output = root["output"];
    scene.output = parseOutput(output.present() ? output.object()
                                                : JsonObject(noOutput, "/output", sourceName),
                               stem.empty() ? "render" : stem);
    root.finish();

    try {
        scene.validate();
    } catch (const InputError& e) {
        throw InputError(strCat(sourceName, ": ", e.what()));
    }
    return scene;
}

Scene parseSceneText(std::string_view text, const std::string& sourceName,
                     const std::filesystem::path& baseDir) {
    nlohmann::json document;
    try {
        document = nlohmann::json::parse(text.begin(), text.end());
    } catch (const nlohmann::json::exception& e) {
        // e.what() reads "[json.exception.parse_error.101] parse error at line 3, column 5: ...";
        // a number too large for a double is an out_of_range.406 from the parser.
        const std::string what = e.what();
        const std::size_t at = what.find("] ");
        throw InputError(strCat(
            sourceName, ": invalid JSON: ", at == std::string::npos ? what : what.substr(at + 2)));
    }
    return parseScene(document, sourceName, baseDir);
}

Scene loadScene(const std::filesystem::path& path) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec)
        throw InputError(strCat(path.string(), ": cannot read scene file: ", ec.message()));
    if (size > kMaxSceneFileBytes)
        throw InputError(strCat(path.string(), ": ", size, " bytes: a scene file is at most ",
                                kMaxSceneFileBytes, " bytes"));
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in && !in.eof())
        throw InputError(strCat(path.string(), ": cannot read scene file"));
    return parseSceneText(text, path.string(), path.parent_path());
}

std::ostream& operator<<(std::ostream& os, const Scene& s) {
    os << "Scene(" << s.name << ": groom=";
    if (s.groom.isProcedural())
        os << s.groom.procedural;
    else
        os << s.groom.sourceName() << " (thickness " << toString(s.groom.thickness) << ", color "
           << toString(s.groom.color) << ")";
    os << ", " << s.fiberScale << ", " << s.fiber << ", " << s.dualScattering << ", "
       << s.lights.size() << " lights";
    for (const Light& l : s.lights)
        os << " " << l;
    if (s.environment)
        os << ", environment(" << s.environment->name << ", " << s.environment->sourceName()
           << ", color=" << s.environment->color << ", intensity=" << s.environment->intensity
           << ", rotation=" << s.environment->rotation
           << ", visible=" << (s.environment->visible ? "true" : "false") << ")";
    os << ", " << s.camera;
    if (s.head)
        os << ", head(center=" << s.head->sphere.center << ", r=" << s.head->sphere.radius
           << ", albedo=" << s.head->albedo << ")";
    for (const MeshSource& m : s.meshes) {
        if (m.isMannequin())
            os << ", mesh(mannequin center=" << m.mannequin.center << ", r=" << m.mannequin.radius;
        else
            os << ", mesh(" << m.file.string();
        os << ", albedo=" << m.albedo << ")";
    }
    os << ", mode=" << s.globalTermMode
       << ", voxel=" << (s.voxelSize ? strCat(*s.voxelSize) : std::string("auto"))
       << ", exact(rays=" << s.exact.rays << ", r=" << s.exact.radius << "), rate=" << s.shadingRate
       << " (tolerance " << s.shadingTolerance << ", tail " << s.tailTransmittance << ")"
       << ", background=" << s.background << ", exr='" << s.output.exr.string() << "', png='"
       << s.output.png.string() << "', exposure=" << s.output.exposure
       << ", tone_map=" << toString(s.output.toneMap) << ")";
    return os;
}

} // namespace hairvox
