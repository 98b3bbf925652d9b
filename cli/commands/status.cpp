// hairvox status SHOT.json [--frames F] [--todo] [--json]
// Which frames of a shot are done, missing, stale or blocked (shots/frame_status.h),
// and the temporaries that renders killed outright left beside the outputs.
#include "../commands.h"

#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/shots/frame_status.h>
#include <hairvox/shots/shot.h>

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <set>

namespace hairvox::cli {

namespace {

namespace fs = std::filesystem;

struct StatusOptions {
    std::string shot;
    std::string frames;
    bool todo = false;
    bool json = false;
};

/// Hidden temporaries of the frames' outputs (writeFileAtomically's, left by
/// a render killed outright).
std::vector<fs::path> leftoverTemporaries(const shots::Shot& shot, const shots::FrameSet& frames) {
    std::set<fs::path> dirs;
    std::set<std::string> prefixes;
    for (int f : frames.frames()) {
        const Scene scene = shot.frame(f);
        for (const fs::path* out : {&scene.output.exr, &scene.output.png})
            if (!out->empty()) {
                dirs.insert(out->parent_path().empty() ? fs::path(".") : out->parent_path());
                prefixes.insert(temporaryPrefix(*out));
            }
    }
    std::vector<fs::path> found;
    for (const fs::path& dir : dirs) {
        std::error_code ec;
        for (const auto& entry : fs::directory_iterator(dir, ec)) {
            const std::string name = entry.path().filename().string();
            const std::size_t at = name.find(".tmp-");
            if (at != std::string::npos && prefixes.count(name.substr(0, at + 5)) > 0)
                found.push_back(entry.path());
        }
    }
    return found;
}

void runStatus(const StatusOptions& opt) {
    const shots::Shot shot = shots::Shot::load(opt.shot);
    const shots::FrameSet frames =
        opt.frames.empty() ? shot.frames() : shot.select(shots::FrameSet::parse(opt.frames));
    const std::vector<shots::FrameStatus> statuses = shots::shotStatus(shot, frames);
    using shots::FrameState;
    const shots::FrameSet done = shots::framesIn(statuses, FrameState::Done);
    const shots::FrameSet missing = shots::framesIn(statuses, FrameState::Missing);
    const shots::FrameSet stale = shots::framesIn(statuses, FrameState::Stale);
    const shots::FrameSet blocked = shots::framesIn(statuses, FrameState::Blocked);
    std::vector<int> todo = missing.frames();
    todo.insert(todo.end(), stale.frames().begin(), stale.frames().end());
    const shots::FrameSet toRender = shots::FrameSet::of(todo);
    if (opt.todo) { // for scripts: the frames a render would do
        std::cout << toRender.toString() << "\n";
        return;
    }
    const std::vector<fs::path> temporaries = leftoverTemporaries(shot, frames);
    if (opt.json) {
        nlohmann::json out;
        out["shot"] = opt.shot;
        out["frames"] = frames.toString();
        for (const auto& [name, set] : {std::pair{"done", &done}, std::pair{"missing", &missing},
                                        std::pair{"stale", &stale}, std::pair{"blocked", &blocked}})
            out[name] = set->toString();
        out["todo"] = toRender.toString();
        nlohmann::json list = nlohmann::json::array();
        for (const shots::FrameStatus& s : statuses)
            list.push_back({{"frame", s.frame},
                            {"state", shots::toString(s.state)},
                            {"reason", s.reason},
                            {"hash", s.hash}});
        out["detail"] = std::move(list);
        nlohmann::json temps = nlohmann::json::array();
        for (const fs::path& t : temporaries)
            temps.push_back(t.string());
        out["temporaries"] = std::move(temps);
        std::cout << out.dump(2) << "\n";
        return;
    }
    std::printf("%s: frames %s (%zu): %zu done, %zu missing, %zu stale, %zu blocked\n",
                opt.shot.c_str(), frames.toString().c_str(), frames.size(), done.size(),
                missing.size(), stale.size(), blocked.size());
    for (const auto& [name, set] : {std::pair{"done", &done}, std::pair{"missing", &missing},
                                    std::pair{"stale", &stale}, std::pair{"blocked", &blocked}})
        if (!set->empty())
            std::printf("  %-8s %s\n", name, set->toString().c_str());
    // Why each stale or blocked frame is so (the first few of each).
    std::size_t shown = 0;
    for (const shots::FrameStatus& s : statuses)
        if ((s.state == FrameState::Stale || s.state == FrameState::Blocked) && shown++ < 10)
            std::printf("    %d %s: %s\n", s.frame, shots::toString(s.state), s.reason.c_str());
    if (shown > 10)
        std::printf("    ... and %zu more\n", shown - 10);
    if (!temporaries.empty()) {
        std::printf("  %zu temporary file(s) of renders killed outright (not outputs; delete them "
                    "when no render of this shot runs):\n",
                    temporaries.size());
        for (std::size_t i = 0; i < temporaries.size() && i < 10; ++i)
            std::printf("    %s\n", temporaries[i].string().c_str());
    }
    if (!toRender.empty())
        std::printf("  to render: %s (hairvox render %s --frames %s, or hairvox submit %s)\n",
                    toRender.toString().c_str(), opt.shot.c_str(), toRender.toString().c_str(),
                    opt.shot.c_str());
}

} // namespace

void addStatusCommand(CLI::App& app) {
    auto opt = std::make_shared<StatusOptions>();
    CLI::App* cmd = app.add_subcommand(
        "status", "Which frames of a shot are done, missing, stale (rendered from other inputs) "
                  "or blocked (an input file missing)");
    cmd->add_option("shot", opt->shot, "Shot file: a scene with \"frames\" (docs/farm.md)")
        ->required();
    cmd->add_option("--frames", opt->frames,
                    "Frames to look at (1-240, 1-240x2, 7, lists); "
                    "default: the shot's");
    cmd->add_flag("--todo", opt->todo,
                  "Print only the frames to render (missing and stale), as --frames reads them");
    cmd->add_flag("--json", opt->json, "Machine-readable output");
    cmd->callback([opt] { runStatus(*opt); });
}

} // namespace hairvox::cli
