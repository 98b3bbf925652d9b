// hairvox tests: shared helpers (temporary directories, crafted files, running the CLI).
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace hairvox::test {

/// A fresh directory removed at scope exit.
class TempDir {
public:
    TempDir();
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

private:
    std::filesystem::path path_;
};

/// Builds little-endian binary files field by field.
class ByteWriter {
public:
    template <typename T>
    ByteWriter& put(const T& value) {
        return putBytes(&value, sizeof(T));
    }
    ByteWriter& putBytes(const void* data, std::size_t size) {
        const std::size_t old = bytes.size();
        bytes.resize(old + size);
        std::memcpy(bytes.data() + old, data, size);
        return *this;
    }
    ByteWriter& zeros(std::size_t count) {
        bytes.insert(bytes.end(), count, 0);
        return *this;
    }
    void writeTo(const std::filesystem::path& path) const;

    std::vector<unsigned char> bytes;
};

void writeText(const std::filesystem::path& path, const std::string& text);
/// The file's bytes ("" if it cannot be read).
std::string readBytes(const std::filesystem::path& path);
/// The path in single quotes, for a command line of runHairvox().
std::string quoted(const std::filesystem::path& path);
/// Whether `text` contains `part`.
bool contains(const std::string& text, const std::string& part);

/// The repository's data/ directory.
std::filesystem::path dataDir();

struct CommandResult {
    int exitCode = -1;
    std::string output; ///< stdout and stderr interleaved
};

/// Runs the hairvox executable with `args` (shell-quoted by the caller).
CommandResult runHairvox(const std::string& args);
/// Runs a shell command line; exit code 127 means "command not found".
CommandResult runShell(const std::string& command);

/// Calls `check` once per SIMD target this CPU runs (Highway's dynamic
/// dispatch forced to each: AVX-512, AVX2, SSE4, the portable baseline),
/// with the target's name in the failures' trace.
void forEachSimdTarget(const std::function<void()>& check);

} // namespace hairvox::test
