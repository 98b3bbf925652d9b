// hairvox shots: the frames of a shot rendered one after another in one
// process (`hairvox render shot.json --frames 1-240`, and each task of a
// farm job): every frame's scene is made and checked, and every output
// against the others and the inputs, before the first render; a frame whose
// outputs are done (frame_status.h) is skipped unless forced, so that a run
// cut short and run again renders only what is missing — never a finished
// frame; the rest render through one FrameReuse (pipeline.h), which shares
// the fiber grid and the lights' preparation while the groom and lights stay
// (a turntable splats and prepares once), and through the disk cache when
// one is given (the farm's first frame of a task takes what another task
// prepared). Each EXR records the frame's digest, its number and the shot.
// A frame that fails (an unreadable groom of a simulation cache) is reported
// and the others go on; an interrupt stops the run.
#pragma once

#include <hairvox/core/disk_cache.h>
#include <hairvox/pipeline/pipeline.h>
#include <hairvox/shots/frame_set.h>
#include <hairvox/shots/shot.h>

#include <cstddef>
#include <functional>
#include <string>

namespace hairvox::shots {

struct ShotRenderOptions {
    PipelineOptions pipeline; ///< threads, progress, memory limit, the disk cache
    bool force = false;       ///< render the frames that are done too
    /// Applied to each frame's scene before its digest (the command line's
    /// overrides: they are part of what the frame is rendered from).
    std::function<void(Scene&)> adjust;
};

/// What happened to one frame, as it happens.
struct FrameReport {
    enum class Outcome { Rendered, UpToDate, Failed };

    int frame = 0;
    std::size_t index = 0, count = 0; ///< 1-based place in the run, and the run's frames
    Outcome outcome = Outcome::Rendered;
    double seconds = 0; ///< wall time of this frame (digest, check and render)
    const Scene* scene = nullptr;
    const SceneRender* render = nullptr; ///< when rendered
    DiskCache::Stats cache;              ///< what this frame took from and gave to the disk cache
    std::string error;                   ///< when failed
    bool internalError = false;          ///< failed by a bug, not by its input
};

struct ShotRenderSummary {
    std::size_t rendered = 0, upToDate = 0;
    FrameSet failed;
    bool internalError = false; ///< some frame failed by a bug
    double seconds = 0;
};

/// Renders `frames` (the shot's: Shot::select) in order, calling `onFrame`
/// after each. InputError before anything is rendered when a frame's scene
/// is invalid or two outputs (or an output and an input) are one file.
ShotRenderSummary renderShot(const Shot& shot, const FrameSet& frames,
                             const ShotRenderOptions& options,
                             const std::function<void(const FrameReport&)>& onFrame = {});

} // namespace hairvox::shots
