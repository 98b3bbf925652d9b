// hairvox shots: a shot — a scene file (docs/scene.md) whose frames vary
// (docs/farm.md). On top of a scene's keys a shot has
//   "frames": {"start": 1, "end": 240}                       required: what makes it a shot
//   "camera": {..., "orbit": {"center": [x, y, z], "axis": [0, 1, 0],
//                             "degrees_per_frame": 1.5}}       a turntable
//   "lights": [{..., "orbit": {...}}]                        a light rotating the same way
//   "groom": {"file": "sim/groom.%04d.hair"}                 a groom per frame
//   "meshes": [{"file": "sim/body.####.obj"}]                a mesh per frame
//   "output": {"exr": "out/shot.%04d.exr", "png": "out/shot.####.png"}
// File names hold the frame number as printf ("%04d") or Nuke and Houdini
// ("####") write it (frame_pattern.h); absent outputs default to
// out/<shot>.####.exr and .png. Frame `start` is the scene as written; frame f
// turns the camera (position, look_at and up: the whole rig) and each
// orbiting light (a directional light's direction, a point light's position)
// by (f − start)·degrees_per_frame about `axis` through `center`,
// right-handed. `center` defaults to the camera's look_at (for a light: the
// origin), `axis` to +y.
//
// The shot keys are taken out of the JSON and each frame's scene is then read
// by the scene parser (parseScene) and validated as any scene is, so a shot
// accepts every scene key and nothing else. Errors name the file and the JSON
// path (/frames/end, /camera/orbit/axis) and, for what only one frame gets
// wrong (an orbit that takes the camera into the head), the frame.
#pragma once

#include <hairvox/core/vecmath.h>
#include <hairvox/pipeline/scene.h>
#include <hairvox/shots/frame_set.h>

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace hairvox::shots {

/// A rotation that grows with the frame: `degreesPerFrame` a frame about the
/// line through `center` along `axis` (a unit vector), right-handed.
struct Orbit {
    Vec3f center{0.0f};
    Vec3f axis{0.0f, 1.0f, 0.0f};
    double degreesPerFrame = 0;

    /// The rotation of `steps` frames: its angle reduced to [0, 360) degrees
    /// in double precision; a whole turn (or none) leaves every value as it is.
    double degrees(int steps) const;
    Vec3f point(const Vec3f& p, int steps) const;
    Vec3f direction(const Vec3f& d, int steps) const;
};

std::ostream& operator<<(std::ostream& os, const Orbit& orbit);

class Shot {
public:
    /// Reads a shot file (at most 16 MiB). InputError naming the file and
    /// the JSON path for anything wrong, including a scene key: frame
    /// `start` is parsed and validated here.
    static Shot load(const std::filesystem::path& file);
    /// A shot from a parsed document; `sourceName` prefixes messages and
    /// names the default outputs, `baseDir` resolves relative input files.
    static Shot parse(const nlohmann::json& document, const std::string& sourceName,
                      const std::filesystem::path& baseDir);

    const std::string& name() const { return name_; }
    int start() const { return start_; }
    int end() const { return end_; }
    /// start..end.
    FrameSet frames() const { return FrameSet::range(start_, end_); }
    /// The given frames that are the shot's; InputError naming `what` and
    /// the shot's range for one that is not.
    FrameSet select(const FrameSet& frames, std::string_view what = "--frames") const;

    const std::optional<Orbit>& cameraOrbit() const { return cameraOrbit_; }
    /// One per light of the scene (nullopt: the light stays).
    const std::vector<std::optional<Orbit>>& lightOrbits() const { return lightOrbits_; }

    /// Whether the groom file, or a mesh file, changes with the frame (a
    /// pattern in its name): then so do the grid and the lights' preparation.
    bool groomVaries() const { return groomVaries_; }
    bool meshesVary() const { return meshesVary_; }

    /// The scene of frame f (any integer, in the shot or not): patterns
    /// expanded, orbits applied, parsed and validated; its name is
    /// "<shot> frame <f>". InputError naming the shot, the frame and the field.
    Scene frame(int f) const;

private:
    /// frame(f) named `name` in its messages and report.
    Scene makeFrame(int f, const std::string& name) const;

    std::string name_;
    std::filesystem::path baseDir_;
    int start_ = 1, end_ = 1;
    bool groomVaries_ = false, meshesVary_ = false;
    std::shared_ptr<const nlohmann::json> scene_; ///< the document without the shot keys
    std::optional<Orbit> cameraOrbit_;
    std::vector<std::optional<Orbit>> lightOrbits_;
};

std::ostream& operator<<(std::ostream& os, const Shot& shot);

/// Whether the scene file is a shot (its top-level object has "frames").
/// False for a file that is not a JSON object; InputError if it cannot be read.
bool isShotFile(const std::filesystem::path& file);

} // namespace hairvox::shots
