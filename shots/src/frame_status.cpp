#include <hairvox/core/error.h>
#include <hairvox/film/image_file.h>
#include <hairvox/shots/frame_status.h>

#include <filesystem>

namespace hairvox::shots {

namespace fs = std::filesystem;

FrameStatus frameStatus(const Scene& scene, int frame, const std::string& hash) {
    FrameStatus status{frame, FrameState::Missing, {}, hash};
    const fs::path& exr = scene.output.exr;
    const fs::path& png = scene.output.png;
    std::error_code ec;
    const bool hasExr = !exr.empty() && fs::exists(exr, ec);
    const bool hasPng = !png.empty() && fs::exists(png, ec);
    if (!hasExr && !hasPng)
        return status;
    status.state = FrameState::Stale;
    if (!exr.empty()) {
        if (!hasExr) {
            status.reason = strCat(png.string(), " is there without ", exr.string());
            return status;
        }
        ExrInfo info;
        try {
            info = readExrInfo(exr);
        } catch (const InputError& e) {
            status.reason = e.what();
            return status;
        }
        if (!info.complete) {
            status.reason = strCat(exr.string(), ": cut short (chunks missing)");
            return status;
        }
        const auto recorded = info.attributes.find(kFrameHashAttribute);
        if (recorded == info.attributes.end()) {
            status.reason = strCat(exr.string(), ": records no frame digest (", kFrameHashAttribute,
                                   "): not rendered as this shot's frame");
            return status;
        }
        if (recorded->second != hash) {
            status.reason = strCat(exr.string(),
                                   ": rendered from another scene, input file or "
                                   "hairvox version (digest ",
                                   recorded->second, ", now ", hash, ")");
            return status;
        }
    }
    if (!png.empty() && !hasPng) {
        status.reason = strCat(exr.string(), " is there without ", png.string());
        return status;
    }
    status.state = FrameState::Done;
    return status;
}

std::vector<FrameStatus> shotStatus(const Shot& shot, const FrameSet& frames,
                                    const std::function<void(Scene&)>& adjust) {
    std::vector<FrameStatus> out;
    FileDigests files;
    for (int f : frames.frames()) {
        Scene scene = shot.frame(f);
        if (adjust)
            adjust(scene);
        std::string hash;
        try {
            hash = frameHash(scene, f, files);
        } catch (const InputError& e) {
            out.push_back({f, FrameState::Blocked, e.what(), {}});
            continue;
        }
        out.push_back(frameStatus(scene, f, hash));
    }
    return out;
}

FrameSet framesIn(const std::vector<FrameStatus>& statuses, FrameState state) {
    std::vector<int> frames;
    for (const FrameStatus& s : statuses)
        if (s.state == state)
            frames.push_back(s.frame);
    return FrameSet::of(std::move(frames));
}

} // namespace hairvox::shots
