#include <hairvox/core/error.h>
#include <hairvox/shots/frame_hash.h>
#include <hairvox/shots/frame_status.h>
#include <hairvox/shots/shot_render.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <vector>

namespace hairvox::shots {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A file's identity across spellings (the files need not exist yet).
std::string fileKey(const fs::path& p) {
    std::error_code ec;
    const fs::path canonical = fs::weakly_canonical(fs::absolute(p, ec), ec);
    return (ec ? fs::absolute(p, ec) : canonical).lexically_normal().string();
}

/// No two frames write one file, and no frame writes over an input file.
void checkFiles(const std::vector<Scene>& scenes, const FrameSet& frames) {
    std::map<std::string, std::string> inputs, outputs; // file key → what it is
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        const Scene& s = scenes[i];
        if (!s.groom.isProcedural())
            inputs.emplace(fileKey(s.groom.file), strCat("frame ", frames.frames()[i],
                                                         "'s groom file ", s.groom.file.string()));
        for (const MeshSource& m : s.meshes)
            if (!m.isMannequin())
                inputs.emplace(fileKey(m.file), strCat("frame ", frames.frames()[i],
                                                       "'s mesh file ", m.file.string()));
    }
    for (std::size_t i = 0; i < scenes.size(); ++i)
        for (const auto& [file, field] : {std::pair{&scenes[i].output.exr, "output.exr"},
                                          std::pair{&scenes[i].output.png, "output.png"}}) {
            if (file->empty())
                continue;
            const std::string what =
                strCat("frame ", frames.frames()[i], "'s ", field, " ", file->string());
            const std::string key = fileKey(*file);
            if (const auto in = inputs.find(key); in != inputs.end())
                throw InputError(strCat(what, " is ", in->second, "; it would be overwritten"));
            if (const auto [out, added] = outputs.emplace(key, what); !added)
                throw InputError(strCat(what, " and ", out->second,
                                        " are the same file; one would overwrite the other"));
        }
}

} // namespace

ShotRenderSummary renderShot(const Shot& shot, const FrameSet& frames,
                             const ShotRenderOptions& options,
                             const std::function<void(const FrameReport&)>& onFrame) {
    const auto start = Clock::now();
    shot.select(frames);
    // Every frame made and checked before the first render.
    std::vector<Scene> scenes;
    scenes.reserve(frames.size());
    for (int f : frames.frames()) {
        scenes.push_back(shot.frame(f));
        if (options.adjust) {
            try {
                options.adjust(scenes.back());
            } catch (const InputError& e) {
                throw InputError(strCat(scenes.back().name, ": ", e.what()));
            }
        }
    }
    checkFiles(scenes, frames);

    // The disk cache keeps what frames share: not a per-frame groom's grid,
    // nor a preparation of a light that moves or lights a per-frame groom or mesh.
    PipelineOptions pipeline = options.pipeline;
    pipeline.diskCacheStoresGrid = !shot.groomVaries();
    for (std::size_t l = 0; l < scenes.front().lights.size(); ++l) {
        const bool orbits = l < shot.lightOrbits().size() && shot.lightOrbits()[l] &&
                            shot.lightOrbits()[l]->degreesPerFrame != 0;
        if (orbits || shot.groomVaries() || shot.meshesVary())
            pipeline.diskCacheSkipsLights.insert(scenes.front().lights[l].name);
    }

    ShotRenderSummary summary;
    FrameReuse reuse;
    FileDigests files;
    for (std::size_t i = 0; i < scenes.size(); ++i) {
        const Scene& scene = scenes[i];
        const int f = frames.frames()[i];
        const auto frameStart = Clock::now();
        const DiskCache::Stats cacheBefore =
            options.pipeline.diskCache ? options.pipeline.diskCache->stats() : DiskCache::Stats{};
        FrameReport report;
        report.frame = f;
        report.index = i + 1;
        report.count = scenes.size();
        report.scene = &scene;
        std::unique_ptr<SceneRender> render;
        try {
            const std::string hash = frameHash(scene, f, files);
            if (!options.force && frameStatus(scene, f, hash).state == FrameState::Done) {
                report.outcome = FrameReport::Outcome::UpToDate;
            } else {
                PipelineOptions frame = pipeline;
                frame.outputAttributes[kFrameHashAttribute] = hash;
                frame.outputAttributes[kFrameAttribute] = std::to_string(f);
                frame.outputAttributes[kShotAttribute] = shot.name();
                render = std::make_unique<SceneRender>(renderScene(scene, frame, true, &reuse));
                report.render = render.get();
            }
        } catch (const Interrupted& e) {
            throw Interrupted(strCat(e.what(), "; frame ", f, " (", i + 1, " of ", scenes.size(),
                                     "), the rest not rendered"));
        } catch (const std::exception& e) {
            report.outcome = FrameReport::Outcome::Failed;
            report.error = e.what();
            report.internalError = dynamic_cast<const InputError*>(&e) == nullptr;
        }
        report.seconds = secondsSince(frameStart);
        if (options.pipeline.diskCache)
            report.cache = options.pipeline.diskCache->stats() - cacheBefore;
        switch (report.outcome) {
        case FrameReport::Outcome::Rendered:
            ++summary.rendered;
            break;
        case FrameReport::Outcome::UpToDate:
            ++summary.upToDate;
            break;
        case FrameReport::Outcome::Failed:
            summary.internalError = summary.internalError || report.internalError;
            break;
        }
        if (report.outcome == FrameReport::Outcome::Failed) {
            std::vector<int> failed = summary.failed.frames();
            failed.push_back(f);
            summary.failed = FrameSet::of(std::move(failed));
        }
        if (onFrame)
            onFrame(report);
    }
    summary.seconds = secondsSince(start);
    return summary;
}

} // namespace hairvox::shots
