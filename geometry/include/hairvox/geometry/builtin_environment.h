// hairvox geometry: the environment maps built into the program — the
// shipped maps of data/hdri/ (Poly Haven, CC0; data/hdri/README.md), their
// EXR files compiled in, so that a scene lights with one by name
// ({"type": "environment", "builtin": "studio"}) without a file beside it,
// as Blender's look-development HDRIs ship inside Blender. The embedded
// default scene is lit this way (docs/scene.md, docs/environment.md).
#pragma once

#include <hairvox/film/image_file.h>

#include <span>
#include <string>
#include <string_view>

namespace hairvox {

struct BuiltinEnvironment {
    std::string_view name;              ///< what a scene names it by: "studio", "sky", "city"
    std::string_view description;       ///< a line for the report and the docs
    std::span<const unsigned char> exr; ///< the whole EXR file of data/hdri/<name>.exr

    /// The map as an EXR source, named "built-in map <name>".
    ExrSource source() const;
};

/// Every built-in map, in a fixed order.
std::span<const BuiltinEnvironment> builtinEnvironments();

/// The built-in map of that name, or nullptr.
const BuiltinEnvironment* findBuiltinEnvironment(std::string_view name);
/// The built-in map of that name; InputError listing the names if there is none.
const BuiltinEnvironment& builtinEnvironment(std::string_view name);

/// "studio, sky, city": the names, for messages.
std::string builtinEnvironmentNames();

} // namespace hairvox
