// hairvox tests: helpers of the tests that parse scenes and read their renders
// (pipeline, pathtrace).
#pragma once

#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/core/rgb.h>
#include <hairvox/film/film.h>
#include <hairvox/pipeline/scene.h>

#include <nlohmann/json.hpp>

#include <string>

namespace hairvox::test {

/// The InputError message of parsing `j` as "scene.json" (in /scenes), or ""
/// if it parses.
inline std::string sceneErrorOf(const nlohmann::json& j) {
    try {
        parseScene(j, "scene.json", "/scenes");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

/// The default look under two directional lights, a key and a back light
/// (data/scenes/key_back.json: the embedded default scene's groom, mannequin
/// and camera before it was lit by an environment map), its outputs cleared:
/// the scene the model's accuracy and speed figures are measured on.
inline Scene keyBackScene() {
    Scene scene = loadScene(dataDir() / "scenes" / "key_back.json");
    scene.output.exr.clear();
    scene.output.png.clear();
    return scene;
}

/// The mean of the surface layer over the pixels the surfaces cover wholly (A = 1).
inline Rgb meanSurface(const Film& film) {
    Rgbd sum(0.0);
    double n = 0;
    for (std::size_t p = 0; p < film.pixelCount(); ++p)
        if (film.layer("A").scalar(p) > 0.999f) {
            sum += Rgbd(film.layer("surface").rgb(p));
            n += 1;
        }
    return Rgb(sum / n);
}

} // namespace hairvox::test
