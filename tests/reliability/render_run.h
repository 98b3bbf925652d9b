// hairvox reliability tests: a small but complete `hairvox render` run — every
// stage (procedural groom, splat, tables, per-light cache, raster, shading, EXR
// and PNG) — that the kill and Ctrl-C tests interrupt at chosen moments.
#pragma once

#include "child_process.h"

#include <gtest/gtest.h>

#include <poll.h>
#include <sys/inotify.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

namespace hairvox::test {

/// The default scene with fewer strands and coarser voxels at 320² (about 2 s
/// on 2 cores), writing out.exr and out.png in the working directory.
inline std::string smallRenderScene() {
    return R"({
  "groom": { "procedural": { "style": "wavy", "strands": 3000, "points_per_strand": 32, "seed": 1 } },
  "fiber": { "diameter": 7e-5, "density_multiplier": 5, "sigma_a": [0.2, 0.3, 0.5] },
  "lights": [
    { "name": "key", "type": "directional", "direction": [-0.6, 0.65, -0.45], "intensity": 3.0 },
    { "name": "back", "type": "directional", "direction": [0.45, 0.3, 0.85], "intensity": 4.0 }
  ],
  "camera": { "position": [-0.55, 0.02, -0.72], "look_at": [-0.025, -0.125, -0.025], "fov": 40,
              "resolution": [320, 320] },
  "head": { "center": [0, 0, 0], "radius": 0.1 },
  "grid": { "voxel_size": 0.004 },
  "output": { "exr": "out.exr", "png": "out.png" }
})";
}

/// Runs `hairvox render SCENE --quiet` in `workDir` with its own table cache.
inline ChildOptions renderOptions(const std::filesystem::path& scene,
                                  const std::filesystem::path& workDir,
                                  const std::filesystem::path& cacheDir) {
    std::filesystem::create_directories(workDir);
    ChildOptions options;
    options.workDir = workDir;
    options.args = {"render", scene.string(), "--quiet"};
    options.env = {"HAIRVOX_CACHE_DIR=" + cacheDir.string()};
    return options;
}

/// Hidden temporaries of writeFileAtomically() in `dir` (".NAME.tmp-HOST-PID-N").
inline std::vector<std::string> temporaries(const std::filesystem::path& dir) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
        const std::string name = e.path().filename().string();
        if (name.front() == '.' && name.find(".tmp-") != std::string::npos)
            names.push_back(name);
    }
    return names;
}

inline bool hasTemporaryOf(const std::filesystem::path& dir, const std::string& finalName) {
    const std::vector<std::string> names = temporaries(dir);
    return std::any_of(names.begin(), names.end(), [&](const std::string& n) {
        return n.rfind("." + finalName + ".tmp-", 0) == 0;
    });
}

/// Polls until `ready()` or the child ends; true if `ready()` came first.
template <typename Ready>
bool waitFor(Child& child, Ready ready, double timeoutSeconds) {
    const auto deadline = Clock::now() + std::chrono::duration<double>(timeoutSeconds);
    while (Clock::now() < deadline) {
        if (ready())
            return true;
        siginfo_t info{};
        if (::waitid(P_PID, static_cast<id_t>(child.pid()), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
            info.si_pid == child.pid())
            return false; // ended (left for Child::poll() to reap)
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    return false;
}

/// Waits until a temporary of a file whose name starts with `finalName` (the
/// whole name, or a prefix such as "dual-scattering-" where a hash follows)
/// is created in `dir` or the child ends; true if the temporary came first.
/// Polling the directory misses a write that is over in less than the poll
/// interval (a small PNG is, a table cache too), so this waits on inotify's
/// creation event instead: it arrives when the file is created, before its
/// bytes are written, fsync'ed and renamed.
inline bool waitForTemporaryOf(Child& child, const std::filesystem::path& dir,
                               const std::string& finalName, double timeoutSeconds) {
    const int fd = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
    if (fd < 0 || ::inotify_add_watch(fd, dir.c_str(), IN_CREATE) < 0) {
        ADD_FAILURE() << "inotify on " << dir << ": " << std::strerror(errno);
        if (fd >= 0)
            ::close(fd);
        return false;
    }
    const std::string prefix = "." + finalName;
    bool created = hasTemporaryOf(dir, finalName);
    const auto deadline = Clock::now() + std::chrono::duration<double>(timeoutSeconds);
    alignas(inotify_event) std::array<char, 4096> buffer{};
    while (!created && Clock::now() < deadline) {
        pollfd p{fd, POLLIN, 0};
        if (::poll(&p, 1, 1) > 0) {
            const ssize_t n = ::read(fd, buffer.data(), buffer.size());
            for (ssize_t at = 0; at < n;) {
                inotify_event event{};
                std::memcpy(&event, buffer.data() + at, sizeof event);
                const char* name = buffer.data() + at + sizeof(inotify_event);
                const std::string createdName = event.len > 0 ? name : "";
                if (createdName.rfind(prefix, 0) == 0 &&
                    createdName.find(".tmp-") != std::string::npos)
                    created = true;
                at += static_cast<ssize_t>(sizeof(inotify_event) + event.len);
            }
            continue;
        }
        siginfo_t info{};
        if (::waitid(P_PID, static_cast<id_t>(child.pid()), &info, WEXITED | WNOHANG | WNOWAIT) == 0 &&
            info.si_pid == child.pid())
            break; // ended (left for Child::poll() to reap)
    }
    ::close(fd);
    return created;
}

} // namespace hairvox::test
