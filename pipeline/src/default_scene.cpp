#include "default_scene_json.h"

#include <hairvox/pipeline/scene.h>

namespace hairvox {

std::string_view defaultSceneJson() {
    return generated::kDefaultSceneJson;
}

Scene defaultScene() {
    return parseSceneText(defaultSceneJson(), "default scene", {});
}

} // namespace hairvox
