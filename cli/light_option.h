// hairvox CLI: --light-dir x,y,z | --light-pos x,y,z, the light of the
// transmittance commands.
#pragma once

#include <hairvox/core/error.h>
#include <hairvox/geometry/light.h>

#include <CLI/CLI.hpp>

#include <vector>

namespace hairvox::cli {

struct LightOption {
    std::vector<float> direction, position;

    void add(CLI::App* cmd) {
        CLI::Option* dir =
            cmd->add_option("--light-dir", direction,
                            "Directional light: x,y,z from the scene toward the light")
                ->delimiter(',')
                ->expected(3);
        cmd->add_option("--light-pos", position, "Point light position x,y,z")
            ->delimiter(',')
            ->expected(3)
            ->excludes(dir);
    }
    bool given() const { return !direction.empty() || !position.empty(); }
    Light resolve() const {
        if (!direction.empty())
            return Light::directional(Vec3f(direction[0], direction[1], direction[2]));
        if (!position.empty())
            return Light::point(Vec3f(position[0], position[1], position[2]));
        throw InputError("give the light: --light-dir x,y,z or --light-pos x,y,z");
    }
};

} // namespace hairvox::cli
