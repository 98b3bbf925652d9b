// hairvox core: a directory of cached results that many processes on many
// machines read and write at once — the render tasks of a shot on a farm,
// sharing fiber grids and per-light preparations through a network file
// system (docs/farm.md).
//
// An entry is a blob of bytes stored under a kind ("grid", "light") and a
// 64-bit key that the caller makes of everything the blob is computed from
// (contents, never file times). Its file, <dir>/<kind>/<digest>.bin, is named
// by a digest of the kind, the key, this format's version and the hairvox
// version — a build that may compute differently never reads another's
// entries — and holds
//   magic "HVXCACHE", u32 format version, u32 0, u64 digest, u64 payload size,
//   the payload, u64 checksum (core/hash.h) of everything before it.
// Written through writeFileAtomically() (a temporary unique per host and
// process, fsync, rename), so a reader sees no entry or a whole one; two
// writers of one key write the same bytes and the last rename wins. A reader
// checks the size, the header and the checksum before handing the payload
// out: a truncated, corrupt or foreign file is a miss (counted, and a warning
// on stderr), which the caller rebuilds and stores over it. Nothing is
// locked: writers that miss at once each compute the entry (what they would
// do without a cache), and one that finds an entry of the right size already
// there does not write it again. Entries are never evicted; the directory is
// the user's to delete.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace hairvox {

class DiskCache {
public:
    /// The directory is created when the first entry is stored.
    explicit DiskCache(std::filesystem::path directory);

    const std::filesystem::path& directory() const { return directory_; }

    /// The payload stored under (kind, key), checked; nullopt when there is
    /// none or it is not intact. `kind`: 1 to 32 lowercase letters, digits, '-'.
    std::optional<std::vector<std::byte>> load(std::string_view kind, std::uint64_t key) const;

    /// Stores the payload under (kind, key), atomically, unless an entry of
    /// its size is there already. A directory that cannot be written is not
    /// an error (a warning on stderr; false): the result is still valid, only
    /// the next process will compute it again.
    bool store(std::string_view kind, std::uint64_t key, std::span<const std::byte> payload) const;

    /// Removes the entry of (kind, key): its payload was intact but the
    /// caller could not use it (bytes of another build). The next store()
    /// writes it again.
    void discard(std::string_view kind, std::uint64_t key) const;

    /// The file of (kind, key).
    std::filesystem::path entryPath(std::string_view kind, std::uint64_t key) const;

    /// What this object did, for reports (thread-safe counters).
    struct Stats {
        std::uint64_t hits = 0, misses = 0, corrupt = 0, stored = 0, storeFailures = 0;
        std::uint64_t bytesRead = 0, bytesWritten = 0;
        Stats operator-(const Stats& o) const;
    };
    Stats stats() const;

    /// The checksum and header magic's size: an entry's file is the payload
    /// plus this many bytes.
    static constexpr std::size_t kOverheadBytes = 8 + 4 + 4 + 8 + 8 + 8;

private:
    std::filesystem::path directory_;
    mutable std::atomic<std::uint64_t> hits_{0}, misses_{0}, corrupt_{0}, stored_{0},
        storeFailures_{0}, bytesRead_{0}, bytesWritten_{0};
};

} // namespace hairvox
