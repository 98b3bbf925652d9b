// hairvox core: outputs are never half-written.
//
// Every output (.hair, .vdb, .exr, .png, caches, CSV) is written to a hidden
// temporary file in the destination directory — ".NAME.tmp-HOST-PID-N", unique
// among the processes of every machine sharing the directory — and renamed
// over the final name only once complete and flushed to disk. If writing throws (bad data, Ctrl-C),
// the temporary is removed and an existing file under the final name is left
// untouched.
#pragma once

#include <filesystem>
#include <functional>

namespace hairvox {

/// Calls `write(tmpPath)` to produce the file, then atomically renames it to
/// `finalPath`. Creates missing parent directories. Throws InputError naming
/// `finalPath` when the destination cannot be written.
void writeFileAtomically(const std::filesystem::path& finalPath,
                         const std::function<void(const std::filesystem::path& tmpPath)>& write);

/// What the name of each temporary of `finalPath` starts with: ".NAME.tmp-".
/// One left behind belongs to a process killed outright (SIGKILL, a node
/// lost); it is never an output.
std::string temporaryPrefix(const std::filesystem::path& finalPath);

/// Whether two paths name the same file: textually (absolute, normalised), or
/// the same existing file — what an output must not be of an input.
bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b);

} // namespace hairvox
