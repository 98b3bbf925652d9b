#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <string>
#include <unistd.h>

namespace hairvox {

namespace fs = std::filesystem;

namespace {

/// This machine's name as a temporary name may hold it: letters, digits,
/// '-' and '.' (anything else '_'); "host" if it has none.
std::string hostTag() {
    char name[256] = {};
    if (::gethostname(name, sizeof(name) - 1) != 0 || name[0] == '\0')
        return "host";
    std::string tag(name);
    for (char& c : tag)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '.')
            c = '_';
    return tag;
}

/// Unique among the processes of every machine that share the directory (a
/// render farm's tasks on a network file system): process ids repeat across
/// machines, so the host name is part of it.
fs::path temporaryPathFor(const fs::path& finalPath) {
    static std::atomic<unsigned> counter{0};
    static const std::string host = hostTag();
    const fs::path name =
        strCat(temporaryPrefix(finalPath), host, "-", ::getpid(), "-", counter.fetch_add(1));
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

std::string temporaryPrefix(const fs::path& finalPath) {
    return strCat(".", finalPath.filename().string(), ".tmp-");
}

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

bool sameFile(const std::filesystem::path& a, const std::filesystem::path& b) {
    std::error_code ec;
    if (std::filesystem::absolute(a, ec).lexically_normal() ==
        std::filesystem::absolute(b, ec).lexically_normal())
        return true;
    return std::filesystem::exists(a, ec) && std::filesystem::exists(b, ec) &&
           std::filesystem::equivalent(a, b, ec);
}

} // namespace hairvox
