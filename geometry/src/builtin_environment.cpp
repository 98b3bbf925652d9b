#include <hairvox/core/error.h>
#include <hairvox/geometry/builtin_environment.h>

#include <array>
#include <cstddef>

namespace hairvox {

namespace generated {
// geometry/src/builtin_environment_data.cpp.in, one per map.
extern const unsigned char kStudioExr[], kSkyExr[], kCityExr[];
extern const std::size_t kStudioExrSize, kSkyExrSize, kCityExrSize;
} // namespace generated

namespace {

const std::array<BuiltinEnvironment, 3>& table() {
    static const std::array<BuiltinEnvironment, 3> maps{{
        {"studio",
         "a photo studio with a softbox and a ring light (Poly Haven, CC0)",
         {generated::kStudioExr, generated::kStudioExrSize}},
        {"sky",
         "a clear sky with a hard sun a few pixels wide (Poly Haven, CC0)",
         {generated::kSkyExr, generated::kSkyExrSize}},
        {"city",
         "an overcast city, nearly uniform (Poly Haven, CC0)",
         {generated::kCityExr, generated::kCityExrSize}},
    }};
    return maps;
}

} // namespace

ExrSource BuiltinEnvironment::source() const {
    return ExrSource::memory(strCat("built-in map ", name), exr);
}

std::span<const BuiltinEnvironment> builtinEnvironments() {
    return table();
}

const BuiltinEnvironment* findBuiltinEnvironment(std::string_view name) {
    for (const BuiltinEnvironment& map : table())
        if (map.name == name)
            return &map;
    return nullptr;
}

const BuiltinEnvironment& builtinEnvironment(std::string_view name) {
    if (const BuiltinEnvironment* map = findBuiltinEnvironment(name))
        return *map;
    throw InputError(strCat("no built-in environment map \"", name, "\": expected one of ",
                            builtinEnvironmentNames()));
}

std::string builtinEnvironmentNames() {
    std::string names;
    for (const BuiltinEnvironment& map : table())
        names += (names.empty() ? "" : ", ") + std::string(map.name);
    return names;
}

} // namespace hairvox
