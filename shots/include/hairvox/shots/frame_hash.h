// hairvox shots: what a frame's images are made of, as one digest that each
// EXR records (attribute kFrameHashAttribute) — so that a finished frame is
// told from one to render again: `hairvox status` calls a frame whose EXR
// records another digest stale, and `render --frames` and the farm's tasks
// skip a frame whose EXR records its own.
//
// The digest covers every setting of the frame's scene as the render sees it
// (command-line overrides applied; docs/scene.md) except its name and its
// output paths — where the images go is not what they are — the contents
// of its groom and mesh files (not their names or times: a simulation cache
// rewritten with other strands makes its frames stale, one copied elsewhere
// does not), the frame number and the hairvox version. Not the thread count:
// a render is the same bytes on any number of threads.
#pragma once

#include <hairvox/core/hash.h>
#include <hairvox/pipeline/scene.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

namespace hairvox::shots {

/// The EXR attributes a shot's frame carries.
inline constexpr const char* kFrameHashAttribute = "hairvox:frameHash";
inline constexpr const char* kFrameAttribute = "hairvox:frame";
inline constexpr const char* kShotAttribute = "hairvox:shot";

/// Content digests of input files, each file read once per object: the
/// frames of a turntable share their groom. A file is known by its path,
/// size, modification time and inode (a file rewritten in place between two
/// calls is read again).
class FileDigests {
public:
    /// InputError naming the file if it cannot be read.
    std::uint64_t of(const std::filesystem::path& file);

private:
    std::map<std::string, std::uint64_t> digests_;
};

/// Every field of the scene that changes a render's images or files but its
/// name and output paths (the input files by path; frameHash() adds their contents).
void hashSceneInto(Hasher& hasher, const Scene& scene);

/// The frame's digest (16 hex digits): hashSceneInto(), the input files'
/// contents, the frame number and the hairvox version.
std::string frameHash(const Scene& scene, int frame, FileDigests& files);

} // namespace hairvox::shots
