// hairvox shots: which frames of a shot are finished. A frame is done when
// each output its scene names is there and its EXR is whole (every chunk
// present) and records the frame's own digest (frame_hash.h); missing when
// none is there; stale when some output is there but not the frame as it
// would be rendered now (another digest: the scene, an input file or hairvox
// changed; an EXR cut short; a PNG without its EXR...); blocked when an input
// file of the frame (a simulation cache's groom) cannot be read. A shot with
// no EXR output cannot record digests: its frames are done when their PNG is
// there, and never stale.
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/pipeline/scene.h>
#include <hairvox/shots/frame_hash.h>
#include <hairvox/shots/frame_set.h>
#include <hairvox/shots/shot.h>

#include <functional>
#include <string>
#include <vector>

namespace hairvox::shots {

enum class FrameState { Done, Missing, Stale, Blocked };

inline constexpr EnumNames<FrameState, 4> kFrameStateNames{{{
    {FrameState::Done, "done"},
    {FrameState::Missing, "missing"},
    {FrameState::Stale, "stale"},
    {FrameState::Blocked, "blocked"},
}}};
inline const char* toString(FrameState s) {
    return kFrameStateNames.name(s);
}

struct FrameStatus {
    int frame = 0;
    FrameState state = FrameState::Missing;
    std::string reason; ///< why stale or blocked (naming the file)
    std::string hash;   ///< the frame's digest now (empty when blocked)
};

/// The state of one frame whose scene (overrides applied) and digest are given.
FrameStatus frameStatus(const Scene& scene, int frame, const std::string& hash);

/// The state of each of the frames: the scene of each (Shot::frame, then
/// `adjust` when given: the command line's overrides), its digest, its outputs.
std::vector<FrameStatus> shotStatus(const Shot& shot, const FrameSet& frames,
                                    const std::function<void(Scene&)>& adjust = {});

/// The frames of `statuses` in the given state.
FrameSet framesIn(const std::vector<FrameStatus>& statuses, FrameState state);

} // namespace hairvox::shots
