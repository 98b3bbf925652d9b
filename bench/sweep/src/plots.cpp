#include "plots.h"

#include "plot_script.h"
#include "text.h"

#include <hairvox/core/error.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <spawn.h>
#include <sys/wait.h>

extern char** environ;

namespace hairvox::bench {

namespace {

constexpr const char* kPython = "/usr/bin/python3";

} // namespace

PlotResult drawPlots(const std::filesystem::path& outDir, const std::filesystem::path& workDir) {
    PlotResult result;
    if (!std::filesystem::exists(kPython)) {
        result.problem = strCat(kPython, " not found (install python3-matplotlib)");
        return result;
    }
    const std::filesystem::path script = workDir / "plot_sweep.py";
    writeTextFile(script, generated::kPlotSweepScript);
    std::string python = kPython, path = script.string(), out = outDir.string();
    char* argv[] = {python.data(), path.data(), out.data(), nullptr};
    pid_t pid = 0;
    if (const int rc = posix_spawn(&pid, kPython, nullptr, nullptr, argv, environ); rc != 0) {
        result.problem = strCat("cannot run ", kPython, ": ", std::strerror(rc));
        return result;
    }
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) {
            result.problem = strCat("waitpid: ", std::strerror(errno));
            return result;
        }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        result.problem = strCat(kPython, " ", script.filename().string(),
                                " failed (its message is above; is python3-matplotlib installed?)");
        return result;
    }
    for (const char* name : {"runtime_vs_error.png", "scaling.png", "frontier.png"}) {
        const std::filesystem::path p = outDir / name;
        if (std::filesystem::exists(p))
            result.written.push_back(p);
    }
    return result;
}

} // namespace hairvox::bench
