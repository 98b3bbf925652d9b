#include <hairvox/core/error.h>
#include <hairvox/shots/frame_pattern.h>
#include <hairvox/shots/shot.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string_view>

namespace hairvox::shots {

namespace {

using nlohmann::json;

/// Shot files are scene files: the scene parser's limit.
constexpr std::uintmax_t kMaxShotFileBytes = 16u << 20;
/// Frames a shot may have (start..end).
constexpr std::int64_t kMaxShotFrames = 1000000;
/// |degrees_per_frame|: ten turns a frame is surely a typo.
constexpr double kMaxDegreesPerFrame = 3600;

/// What a JSON value is, for messages (long values cut).
std::string shown(const json& v) {
    std::string s = v.dump();
    if (s.size() > 40)
        s = s.substr(0, 37) + "...";
    return s;
}

[[noreturn]] void fail(const std::string& source, const std::string& path, std::string_view what) {
    throw InputError(strCat(source, ": ", path, ": ", what));
}

/// Throws for the first key of `object` not in `valid`, listing them.
void checkKeys(const json& object, const std::string& source, const std::string& path,
               std::initializer_list<std::string_view> valid) {
    for (const auto& [key, value] : object.items()) {
        if (std::find(valid.begin(), valid.end(), key) != valid.end())
            continue;
        std::string list;
        for (std::string_view v : valid)
            list += (list.empty() ? "" : ", ") + std::string(v);
        fail(source, path + "/" + key,
             strCat("unknown key (valid keys in ", path, ": ", list, ")"));
    }
}

int frameNumber(const json& v, const std::string& source, const std::string& path) {
    const bool integral =
        v.is_number_integer() || (v.is_number_float() && std::isfinite(v.get<double>()) &&
                                  v.get<double>() == std::floor(v.get<double>()));
    if (!integral || v.get<double>() < kMinFrame || v.get<double>() > kMaxFrame)
        fail(source, path,
             strCat("expected a whole frame number in [", kMinFrame, ", ", kMaxFrame, "], got ",
                    shown(v)));
    return static_cast<int>(v.get<double>());
}

Vec3f vec3(const json& v, const std::string& source, const std::string& path) {
    if (!v.is_array() || v.size() != 3 || !std::all_of(v.begin(), v.end(), [](const json& x) {
            return x.is_number() && std::isfinite(x.get<double>()) &&
                   std::abs(x.get<double>()) <= 1e7;
        }))
        fail(source, path, strCat("expected an array of 3 numbers in [-1e7, 1e7], got ", shown(v)));
    return {v[0].get<float>(), v[1].get<float>(), v[2].get<float>()};
}

/// An "orbit" object; `defaultCenter` when it gives none.
Orbit parseOrbit(const json& v, const std::string& source, const std::string& path,
                 const Vec3f& defaultCenter) {
    if (!v.is_object())
        fail(source, path,
             strCat("expected an object {\"center\", \"axis\", \"degrees_per_frame\"}, got ",
                    shown(v)));
    checkKeys(v, source, path, {"center", "axis", "degrees_per_frame"});
    Orbit orbit;
    orbit.center =
        v.contains("center") ? vec3(v["center"], source, path + "/center") : defaultCenter;
    if (v.contains("axis")) {
        const Vec3f axis = vec3(v["axis"], source, path + "/axis");
        const float length = glm::length(axis);
        if (!(length > 1e-6f))
            fail(source, path + "/axis", "expected a non-zero vector (the axis of rotation)");
        orbit.axis = axis / length;
    }
    if (!v.contains("degrees_per_frame"))
        fail(source, path + "/degrees_per_frame",
             "missing (the rotation from one frame to the next)");
    const json& d = v["degrees_per_frame"];
    if (!d.is_number() || !(std::abs(d.get<double>()) <= kMaxDegreesPerFrame))
        fail(source, path + "/degrees_per_frame",
             strCat("expected a number in [", -kMaxDegreesPerFrame, ", ", kMaxDegreesPerFrame,
                    "], got ", shown(d)));
    orbit.degreesPerFrame = d.get<double>();
    return orbit;
}

/// object[key] (a file name) for frame f; `where` prefixes messages ("shot.json: /output").
void expandIn(json& object, const char* key, int frame, const std::string& where) {
    if (object.is_object() && object.contains(key) && object[key].is_string())
        object[key] =
            expandFramePattern(object[key].get<std::string>(), frame, strCat(where, "/", key));
}

bool hasPattern(const json& object, const char* key) {
    return object.is_object() && object.contains(key) && object[key].is_string() &&
           hasFramePattern(object[key].get<std::string>());
}

} // namespace

double Orbit::degrees(int steps) const {
    const double d = std::fmod(degreesPerFrame * double(steps), 360.0);
    return d < 0 ? d + 360.0 : d;
}

namespace {

/// Rodrigues' rotation of v about the unit axis k by `deg` degrees.
glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& k, double deg) {
    const double a = deg * (3.14159265358979323846 / 180.0);
    const double c = std::cos(a), s = std::sin(a);
    return v * c + glm::cross(k, v) * s + k * (glm::dot(k, v) * (1 - c));
}

} // namespace

Vec3f Orbit::point(const Vec3f& p, int steps) const {
    const double deg = degrees(steps);
    if (deg == 0)
        return p;
    // In double: a point on the axis stays where it is, to float's precision.
    const glm::dvec3 c(center);
    return Vec3f(c + rotate(glm::dvec3(p) - c, glm::dvec3(axis), deg));
}

Vec3f Orbit::direction(const Vec3f& d, int steps) const {
    const double deg = degrees(steps);
    return deg == 0 ? d : Vec3f(rotate(glm::dvec3(d), glm::dvec3(axis), deg));
}

std::ostream& operator<<(std::ostream& os, const Orbit& o) {
    return os << "Orbit(center=" << o.center << ", axis=" << o.axis
              << ", degreesPerFrame=" << o.degreesPerFrame << ")";
}

Shot Shot::parse(const json& document, const std::string& sourceName,
                 const std::filesystem::path& baseDir) {
    if (!document.is_object())
        fail(sourceName, "/",
             strCat("expected a JSON object (a scene with \"frames\"), got ", shown(document)));
    Shot shot;
    shot.name_ = sourceName;
    shot.baseDir_ = baseDir;
    json scene = document;

    // "frames"
    if (!scene.contains("frames"))
        fail(sourceName, "/frames",
             "missing: a shot is a scene with \"frames\": {\"start\": 1, \"end\": 240}");
    const json frames = scene["frames"];
    scene.erase("frames");
    if (!frames.is_object())
        fail(sourceName, "/frames",
             strCat("expected an object {\"start\": 1, \"end\": 240}, got ", shown(frames)));
    checkKeys(frames, sourceName, "/frames", {"start", "end"});
    for (const char* key : {"start", "end"})
        if (!frames.contains(key))
            fail(sourceName, strCat("/frames/", key), "missing (the shot's first and last frame)");
    shot.start_ = frameNumber(frames["start"], sourceName, "/frames/start");
    shot.end_ = frameNumber(frames["end"], sourceName, "/frames/end");
    if (shot.end_ < shot.start_)
        fail(sourceName, "/frames/end",
             strCat(shot.end_, " is before /frames/start ", shot.start_));
    if (std::int64_t(shot.end_) - shot.start_ + 1 > kMaxShotFrames)
        fail(sourceName, "/frames/end",
             strCat("a shot has at most ", kMaxShotFrames, " frames; ", shot.start_, "-", shot.end_,
                    " has ", std::int64_t(shot.end_) - shot.start_ + 1));

    // The camera's orbit, about its look_at by default.
    if (scene.contains("camera") && scene["camera"].is_object() &&
        scene["camera"].contains("orbit")) {
        json& camera = scene["camera"];
        Vec3f lookAt(0.0f);
        if (camera.contains("look_at"))
            lookAt = vec3(camera["look_at"], sourceName, "/camera/look_at");
        shot.cameraOrbit_ = parseOrbit(camera["orbit"], sourceName, "/camera/orbit", lookAt);
        camera.erase("orbit");
    }
    // The lights' orbits, about the origin by default.
    if (scene.contains("lights") && scene["lights"].is_array()) {
        json& lights = scene["lights"];
        for (std::size_t i = 0; i < lights.size(); ++i) {
            std::optional<Orbit> orbit;
            if (lights[i].is_object() && lights[i].contains("orbit")) {
                orbit = parseOrbit(lights[i]["orbit"], sourceName, strCat("/lights/", i, "/orbit"),
                                   Vec3f(0.0f));
                lights[i].erase("orbit");
            }
            shot.lightOrbits_.push_back(orbit);
        }
    }

    // Outputs: one file per frame, so a pattern wherever there is more than one frame.
    const std::string stem = std::filesystem::path(sourceName).stem().string();
    if (!scene.contains("output"))
        scene["output"] = json::object();
    json& output = scene["output"];
    if (output.is_object()) {
        for (const char* key : {"exr", "png"}) {
            if (!output.contains(key))
                output[key] = strCat("out/", stem.empty() ? "shot" : stem, ".####.", key);
            if (output[key].is_string()) // a malformed pattern says so first
                expandFramePattern(output[key].get<std::string>(), shot.start_,
                                   strCat(sourceName, ": /output/", key));
            if (output[key].is_string() && shot.end_ > shot.start_ && !hasPattern(output, key))
                fail(sourceName, strCat("/output/", key),
                     strCat("\"", output[key].get<std::string>(),
                            "\" has no frame number, so every frame of ", shot.start_, "-",
                            shot.end_, " would write it; write one as %04d or ####"));
        }
    }
    shot.groomVaries_ = scene.contains("groom") && hasPattern(scene["groom"], "file");
    if (scene.contains("meshes") && scene["meshes"].is_array())
        for (const json& mesh : scene["meshes"])
            shot.meshesVary_ = shot.meshesVary_ || hasPattern(mesh, "file");
    shot.scene_ = std::make_shared<const json>(std::move(scene));
    // Every scene key is checked now, in the shot's name (each frame's own
    // values when it is made, in the frame's).
    (void)shot.makeFrame(shot.start_, sourceName);
    return shot;
}

Shot Shot::load(const std::filesystem::path& file) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(file, ec);
    if (ec)
        throw InputError(strCat(file.string(), ": cannot read shot file: ", ec.message()));
    if (size > kMaxShotFileBytes)
        throw InputError(strCat(file.string(), ": ", size, " bytes: a shot file is at most ",
                                kMaxShotFileBytes, " bytes"));
    std::ifstream in(file, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in && !in.eof())
        throw InputError(strCat(file.string(), ": cannot read shot file"));
    json document;
    try {
        document = json::parse(text);
    } catch (const json::exception& e) {
        const std::string what = e.what();
        const std::size_t at = what.find("] ");
        throw InputError(strCat(file.string(), ": invalid JSON: ",
                                at == std::string::npos ? what : what.substr(at + 2)));
    }
    return parse(document, file.string(), file.parent_path());
}

FrameSet Shot::select(const FrameSet& frames, std::string_view what) const {
    for (int f : frames.frames())
        if (f < start_ || f > end_)
            throw InputError(strCat(what, " ", frames.toString(), ": frame ", f, " is not one of ",
                                    name_, "'s frames ", start_, "-", end_));
    return frames;
}

Scene Shot::frame(int f) const {
    return makeFrame(f, strCat(name_, " frame ", f));
}

Scene Shot::makeFrame(int f, const std::string& name) const {
    json document = *scene_;
    // Frame numbers into the file names.
    if (document.contains("groom"))
        expandIn(document["groom"], "file", f, name + ": /groom");
    if (document.contains("meshes") && document["meshes"].is_array())
        for (std::size_t i = 0; i < document["meshes"].size(); ++i)
            expandIn(document["meshes"][i], "file", f, strCat(name, ": /meshes/", i));
    if (document.contains("output")) {
        expandIn(document["output"], "exr", f, name + ": /output");
        expandIn(document["output"], "png", f, name + ": /output");
    }
    Scene scene = parseScene(document, name, baseDir_);
    // The orbits turn the camera rig and the lights.
    const int steps = f - start_;
    if (cameraOrbit_) {
        CameraParams& c = scene.camera;
        c.position = cameraOrbit_->point(c.position, steps);
        c.lookAt = cameraOrbit_->point(c.lookAt, steps);
        c.up = cameraOrbit_->direction(c.up, steps);
    }
    for (std::size_t i = 0; i < lightOrbits_.size() && i < scene.lights.size(); ++i) {
        if (!lightOrbits_[i])
            continue;
        Light& light = scene.lights[i];
        if (light.kind == Light::Kind::Directional)
            light.direction = glm::normalize(lightOrbits_[i]->direction(light.direction, steps));
        else
            light.position = lightOrbits_[i]->point(light.position, steps);
    }
    try {
        scene.validate();
    } catch (const InputError& e) {
        throw InputError(strCat(name, ": ", e.what(),
                                cameraOrbit_ || !lightOrbits_.empty()
                                    ? " (after the orbits' rotation for this frame)"
                                    : ""));
    }
    return scene;
}

std::ostream& operator<<(std::ostream& os, const Shot& shot) {
    os << "Shot(" << shot.name() << ", frames " << shot.start() << "-" << shot.end();
    if (shot.cameraOrbit())
        os << ", camera " << *shot.cameraOrbit();
    for (std::size_t i = 0; i < shot.lightOrbits().size(); ++i)
        if (shot.lightOrbits()[i])
            os << ", light " << i << " " << *shot.lightOrbits()[i];
    return os << ")";
}

bool isShotFile(const std::filesystem::path& file) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(file, ec);
    if (ec)
        throw InputError(strCat(file.string(), ": cannot read scene file: ", ec.message()));
    if (size > kMaxShotFileBytes)
        return false; // the scene parser says what is wrong
    std::ifstream in(file, std::ios::binary);
    const json document = json::parse(in, nullptr, /*allow_exceptions=*/false);
    return document.is_object() && document.contains("frames");
}

} // namespace hairvox::shots
