#include <hairvox/core/atomic_file.h>
#include <hairvox/core/disk_cache.h>
#include <hairvox/core/error.h>
#include <hairvox/core/hash.h>
#include <hairvox/core/version.h>

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <iostream>
#include <sys/stat.h>
#include <unistd.h>

namespace hairvox {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'H', 'V', 'X', 'C', 'A', 'C', 'H', 'E'};
/// Bumped when the entry layout changes: entries of another version are other files.
constexpr std::uint32_t kFormatVersion = 1;
constexpr std::size_t kHeaderBytes = 8 + 4 + 4 + 8 + 8;
static_assert(DiskCache::kOverheadBytes == kHeaderBytes + 8);
/// Larger files are not read (a cache entry of hairvox is a grid or a
/// light's preparation: hundreds of MB at most).
constexpr std::uint64_t kMaxEntryBytes = 16ull << 30;

void checkKind(std::string_view kind) {
    const bool valid =
        !kind.empty() && kind.size() <= 32 &&
        kind.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-") == std::string_view::npos;
    if (!valid)
        throw std::invalid_argument(strCat("DiskCache: kind '", kind,
                                           "' should be 1 to 32 lowercase letters, digits or '-'"));
}

std::uint64_t entryDigest(std::string_view kind, std::uint64_t key) {
    return Hasher().string(kind).value(key).value(kFormatVersion).string(version()).digest();
}

/// The whole file, or nullopt if it cannot be opened; InputError for a read
/// error or a file larger than kMaxEntryBytes.
std::optional<std::vector<std::byte>> readWhole(const fs::path& path) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return std::nullopt;
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
        return std::nullopt;
    const auto size = static_cast<std::uint64_t>(st.st_size);
    if (size > kMaxEntryBytes)
        throw InputError(
            strCat(size, " bytes, over the ", kMaxEntryBytes, " a cache entry may hold"));
    std::vector<std::byte> bytes(size);
    std::size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            throw InputError(strCat("read error: ", std::strerror(errno)));
        if (n == 0) { // shorter than fstat said: changed while read
            bytes.resize(done);
            break;
        }
        done += static_cast<std::size_t>(n);
    }
    return bytes;
}

template <typename T>
T readAt(const std::vector<std::byte>& bytes, std::size_t offset) {
    T v;
    std::memcpy(&v, bytes.data() + offset, sizeof(T));
    return v;
}

} // namespace

DiskCache::DiskCache(fs::path directory)
    : directory_(std::move(directory)) {}

fs::path DiskCache::entryPath(std::string_view kind, std::uint64_t key) const {
    checkKind(kind);
    return directory_ / std::string(kind) / (hexDigest(entryDigest(kind, key)) + ".bin");
}

std::optional<std::vector<std::byte>> DiskCache::load(std::string_view kind,
                                                      std::uint64_t key) const {
    const fs::path path = entryPath(kind, key);
    const std::uint64_t digest = entryDigest(kind, key);
    std::optional<std::vector<std::byte>> bytes;
    std::string problem;
    try {
        bytes = readWhole(path);
    } catch (const InputError& e) {
        problem = e.what();
    }
    if (!bytes && problem.empty()) {
        misses_.fetch_add(1, std::memory_order_relaxed);
        return std::nullopt;
    }
    if (problem.empty()) {
        const std::vector<std::byte>& b = *bytes;
        if (b.size() < kOverheadBytes || std::memcmp(b.data(), kMagic, 8) != 0)
            problem = strCat(b.size(), " bytes, not a hairvox cache entry");
        else if (readAt<std::uint32_t>(b, 8) != kFormatVersion ||
                 readAt<std::uint64_t>(b, 16) != digest)
            problem = "an entry of another format or key";
        else if (readAt<std::uint64_t>(b, 24) != b.size() - kOverheadBytes)
            problem = strCat(b.size(), " bytes, truncated or extended (the header says ",
                             readAt<std::uint64_t>(b, 24) + kOverheadBytes, ")");
        else if (Hasher().bytes(b.data(), b.size() - 8).digest() !=
                 readAt<std::uint64_t>(b, b.size() - 8))
            problem = "checksum mismatch (corrupt)";
    }
    if (!problem.empty()) {
        corrupt_.fetch_add(1, std::memory_order_relaxed);
        misses_.fetch_add(1, std::memory_order_relaxed);
        std::cerr << "hairvox: warning: cache entry " << path.string() << ": " << problem
                  << "; removed, computed again\n";
        // Removed, so that store() writes the entry again (it keeps an entry
        // of the right size). Had another process just replaced it with an
        // intact one, that is computed once more, nothing worse.
        std::error_code ec;
        fs::remove(path, ec);
        return std::nullopt;
    }
    hits_.fetch_add(1, std::memory_order_relaxed);
    bytesRead_.fetch_add(bytes->size(), std::memory_order_relaxed);
    bytes->resize(bytes->size() - 8);
    bytes->erase(bytes->begin(), bytes->begin() + kHeaderBytes);
    return bytes;
}

bool DiskCache::store(std::string_view kind, std::uint64_t key,
                      std::span<const std::byte> payload) const {
    const fs::path path = entryPath(kind, key);
    const std::uint64_t size = payload.size() + kOverheadBytes;
    std::error_code ec;
    if (fs::file_size(path, ec) == size && !ec)
        return true; // another process stored it (load() removes a corrupt one)
    try {
        writeFileAtomically(path, [&](const fs::path& tmp) {
            const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
            if (fd < 0)
                throw InputError(strCat(tmp.string(), ": cannot create: ", std::strerror(errno)));
            struct Closer {
                int fd;
                ~Closer() { ::close(fd); }
            } closer{fd};
            Hasher checksum;
            const auto put = [&](const void* data, std::size_t n) {
                checksum.bytes(data, n);
                const auto* p = static_cast<const char*>(data);
                while (n > 0) {
                    const ssize_t w = ::write(fd, p, n);
                    if (w < 0 && errno == EINTR)
                        continue;
                    if (w <= 0)
                        throw InputError(
                            strCat(tmp.string(), ": cannot write: ", std::strerror(errno)));
                    p += w;
                    n -= static_cast<std::size_t>(w);
                }
            };
            const std::uint64_t digest = entryDigest(kind, key);
            const std::uint32_t zero = 0;
            const std::uint64_t payloadSize = payload.size();
            put(kMagic, 8);
            put(&kFormatVersion, 4);
            put(&zero, 4);
            put(&digest, 8);
            put(&payloadSize, 8);
            put(payload.data(), payload.size());
            const std::uint64_t sum = checksum.digest();
            put(&sum, 8);
        });
    } catch (const InputError& e) {
        storeFailures_.fetch_add(1, std::memory_order_relaxed);
        std::cerr << "hairvox: warning: cache entry not stored: " << e.what() << "\n";
        return false;
    }
    stored_.fetch_add(1, std::memory_order_relaxed);
    bytesWritten_.fetch_add(size, std::memory_order_relaxed);
    return true;
}

void DiskCache::discard(std::string_view kind, std::uint64_t key) const {
    corrupt_.fetch_add(1, std::memory_order_relaxed);
    std::error_code ec;
    fs::remove(entryPath(kind, key), ec);
}

DiskCache::Stats DiskCache::stats() const {
    Stats s;
    s.hits = hits_.load();
    s.misses = misses_.load();
    s.corrupt = corrupt_.load();
    s.stored = stored_.load();
    s.storeFailures = storeFailures_.load();
    s.bytesRead = bytesRead_.load();
    s.bytesWritten = bytesWritten_.load();
    return s;
}

DiskCache::Stats DiskCache::Stats::operator-(const Stats& o) const {
    return {hits - o.hits,
            misses - o.misses,
            corrupt - o.corrupt,
            stored - o.stored,
            storeFailures - o.storeFailures,
            bytesRead - o.bytesRead,
            bytesWritten - o.bytesWritten};
}

} // namespace hairvox
