// Internal to hairvox shots: running another program (Slurm's sbatch,
// ffmpeg) and reading what it prints.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace hairvox::shots::detail {

struct ProcessResult {
    int exitCode = -1;  ///< -1 when ended by a signal
    std::string output; ///< stdout
    std::string errors; ///< stderr
};

/// The program's path on $PATH (or `name` itself when it holds a '/' and is
/// executable); nullopt if there is none.
std::optional<std::filesystem::path> findProgram(const std::string& name);

/// Runs argv[0] (found on $PATH) with argv, stdin from /dev/null, and waits
/// for it. InputError naming the program when it cannot be started.
ProcessResult runProcess(const std::vector<std::string>& argv);

/// `text` quoted for a POSIX shell: in single quotes, each ' as '\''.
std::string shellQuoted(const std::string& text);

} // namespace hairvox::shots::detail
