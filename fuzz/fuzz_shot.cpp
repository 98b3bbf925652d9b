// libFuzzer target: the shot loader (shots/shot.h) and frame lists
// (shots/frame_set.h).
//
// Arbitrary text either throws InputError or yields a shot whose first and
// last frames are valid scenes; and as a frame list either throws InputError
// or yields frames that print back to the same set. Anything else — a crash,
// a sanitizer report, another exception type — is a finding.
#include <hairvox/core/error.h>
#include <hairvox/shots/frame_set.h>
#include <hairvox/shots/shot.h>

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const hairvox::shots::FrameSet frames = hairvox::shots::FrameSet::parse(text);
        if (!(hairvox::shots::FrameSet::parse(frames.toString()) == frames))
            std::abort(); // toString() must read back as the same set
    } catch (const hairvox::InputError&) {
    }
    const nlohmann::json document = nlohmann::json::parse(text, nullptr, false);
    if (document.is_discarded())
        return 0;
    try {
        const hairvox::shots::Shot shot =
            hairvox::shots::Shot::parse(document, "fuzz.json", "/nonexistent");
        shot.frame(shot.start()).validate();
        shot.frame(shot.end()).validate();
    } catch (const hairvox::InputError&) {
        // The expected outcome for malformed input (or a frame the orbits spoil).
    }
    return 0;
}
