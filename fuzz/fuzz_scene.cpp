// libFuzzer target: the scene loader, parseSceneText() (render/scene.h).
//
// Arbitrary text either throws InputError (invalid JSON, a wrong type or range,
// an unknown key, ...) or yields a scene that passes Scene::validate() and
// prints itself. Anything else — a crash, a sanitizer report, another exception
// type — is a finding.
#include <hairvox/core/error.h>
#include <hairvox/pipeline/scene.h>

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const hairvox::Scene scene = hairvox::parseSceneText(text, "fuzz.json", "/nonexistent");
        scene.validate();
        std::ostringstream os;
        os << scene;
    } catch (const hairvox::InputError&) {
        // The expected outcome for malformed input.
    }
    return 0;
}
