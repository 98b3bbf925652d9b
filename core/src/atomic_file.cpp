#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>

namespace hairvox {

namespace fs = std::filesystem;

namespace {

fs::path temporaryPathFor(const fs::path& finalPath) {
    static std::atomic<unsigned> counter{0};
    const fs::path name = strCat(".", finalPath.filename().string(), ".tmp-", ::getpid(), "-",
                                 counter.fetch_add(1));
    return finalPath.parent_path() / name;
}

/// Flushes the file's data to disk so that the rename never publishes a file
/// whose contents are still only in the page cache.
void syncFile(const fs::path& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        throw InputError(strCat(path.string(), ": cannot reopen to flush: ", std::strerror(errno)));
    const int rc = ::fsync(fd);
    ::close(fd);
    if (rc != 0)
        throw InputError(strCat(path.string(), ": cannot flush to disk: ", std::strerror(errno)));
}

} // namespace

void writeFileAtomically(const fs::path& finalPath,
                         const std::function<void(const fs::path& tmpPath)>& write) {
    if (finalPath.empty() || !finalPath.has_filename())
        throw InputError(strCat("output path '", finalPath.string(), "' does not name a file"));
    std::error_code ec;
    if (finalPath.has_parent_path()) {
        fs::create_directories(finalPath.parent_path(), ec);
        if (ec)
            throw InputError(strCat(finalPath.string(), ": cannot create directory ",
                                    finalPath.parent_path().string(), ": ", ec.message()));
    }
    if (fs::is_directory(finalPath, ec))
        throw InputError(strCat(finalPath.string(), ": is a directory"));

    const fs::path tmp = temporaryPathFor(finalPath);
    try {
        write(tmp);
        if (!fs::exists(tmp))
            throw std::logic_error(strCat("writer produced no file for ", finalPath.string()));
        syncFile(tmp);
        fs::rename(tmp, finalPath, ec);
        if (ec)
            throw InputError(strCat(finalPath.string(), ": cannot rename temporary file: ",
                                    ec.message()));
    } catch (...) {
        fs::remove(tmp, ec);
        throw;
    }
}

} // namespace hairvox
