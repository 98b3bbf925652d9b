// The disk cache that a farm's render tasks share (core/disk_cache.h): what
// is stored is read back whole; a missing, truncated, corrupt or foreign entry
// is a miss (counted as corrupt when it is there), removed so that the next
// store writes it again; writers racing on one key leave an intact entry.
#include "test_util.h"

#include <hairvox/core/disk_cache.h>

#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <thread>
#include <vector>

namespace hairvox {
namespace {

namespace fs = std::filesystem;

std::vector<std::byte> payload(std::size_t n, unsigned seed) {
    std::vector<std::byte> p(n);
    for (std::size_t i = 0; i < n; ++i)
        p[i] = std::byte((i * 131u + seed * 7u) & 0xFF);
    return p;
}

std::string fileBytes(const fs::path& path) {
    return test::readBytes(path);
}

void writeFileBytes(const fs::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out << bytes;
}

TEST(CoreDiskCache, StoresAndLoadsWholePayloads) {
    test::TempDir dir;
    const DiskCache cache(dir / "cache");
    EXPECT_FALSE(cache.load("grid", 42).has_value());
    EXPECT_EQ(cache.stats().misses, 1u);
    EXPECT_EQ(cache.stats().corrupt, 0u);
    const auto p = payload(100000, 1);
    EXPECT_TRUE(cache.store("grid", 42, p));
    EXPECT_EQ(fs::file_size(cache.entryPath("grid", 42)), p.size() + DiskCache::kOverheadBytes);
    const auto loaded = cache.load("grid", 42);
    ASSERT_TRUE(loaded.has_value());
    EXPECT_TRUE(*loaded == p);
    // Another key or kind is another entry.
    EXPECT_FALSE(cache.load("grid", 43).has_value());
    EXPECT_FALSE(cache.load("light", 42).has_value());
    EXPECT_NE(cache.entryPath("grid", 42), cache.entryPath("light", 42));
    EXPECT_EQ(cache.entryPath("grid", 42).parent_path().filename(), "grid");
    const DiskCache::Stats s = cache.stats();
    EXPECT_EQ(s.hits, 1u);
    EXPECT_EQ(s.misses, 3u);
    EXPECT_EQ(s.stored, 1u);
    // An empty payload is a payload.
    EXPECT_TRUE(cache.store("light", 7, {}));
    ASSERT_TRUE(cache.load("light", 7).has_value());
    EXPECT_TRUE(cache.load("light", 7)->empty());
    // Kinds are names of directories: nothing else is accepted.
    EXPECT_THROW(cache.entryPath("../x", 1), std::invalid_argument);
    EXPECT_THROW(cache.entryPath("", 1), std::invalid_argument);
}

TEST(CoreDiskCache, ADamagedEntryIsAMissThatTheNextStoreReplaces) {
    test::TempDir dir;
    const DiskCache cache(dir / "cache");
    const auto p = payload(5000, 2);
    const fs::path entry = cache.entryPath("light", 9);
    const auto damaged = [&](const std::string& bytes, const char* what) {
        ASSERT_TRUE(cache.store("light", 9, p));
        const std::string intact = fileBytes(entry);
        ASSERT_EQ(intact.size(), p.size() + DiskCache::kOverheadBytes);
        writeFileBytes(entry, bytes.empty() ? std::string() : bytes);
        const std::uint64_t corrupt = cache.stats().corrupt;
        EXPECT_FALSE(cache.load("light", 9).has_value()) << what;
        EXPECT_EQ(cache.stats().corrupt, corrupt + 1) << what;
        EXPECT_FALSE(fs::exists(entry)) << what << ": a damaged entry is removed";
        ASSERT_TRUE(cache.store("light", 9, p)) << what;
        const auto again = cache.load("light", 9);
        ASSERT_TRUE(again.has_value()) << what;
        EXPECT_TRUE(*again == p) << what;
    };
    ASSERT_TRUE(cache.store("light", 9, p));
    const std::string intact = fileBytes(entry);
    std::string flipped = intact;
    flipped[DiskCache::kOverheadBytes / 2 + 2500] ^= 0x10; // one bit of the payload
    damaged(flipped, "a flipped bit");
    damaged(intact.substr(0, intact.size() - 100), "truncated");
    damaged(intact + "extra", "extended");
    damaged(std::string(intact.size(), 'x'), "not an entry");
    damaged(std::string(), "empty");
    std::string otherKey = intact;
    otherKey[16] ^= 0x01; // the digest in the header
    damaged(otherKey, "another key's header");
}

TEST(CoreDiskCache, AStoreKeepsAnIntactEntryAndAnUnwritableDirectoryIsNoError) {
    test::TempDir dir;
    const DiskCache cache(dir / "cache");
    ASSERT_TRUE(cache.store("grid", 1, payload(1000, 3)));
    const auto before = fs::last_write_time(cache.entryPath("grid", 1));
    EXPECT_TRUE(cache.store("grid", 1, payload(1000, 3)));
    EXPECT_EQ(fs::last_write_time(cache.entryPath("grid", 1)), before);
    EXPECT_EQ(cache.stats().stored, 1u) << "an entry that is there is not written again";

    // A cache below a regular file cannot be created: the result is still
    // the caller's, only not kept.
    test::writeText(dir / "file", "not a directory");
    const DiskCache blocked(dir / "file" / "cache");
    EXPECT_FALSE(blocked.store("grid", 1, payload(10, 1)));
    EXPECT_EQ(blocked.stats().storeFailures, 1u);
    EXPECT_FALSE(blocked.load("grid", 1).has_value());
}

TEST(CoreDiskCache, WritersAndReadersRacingOnOneKeyNeverSeeAPartialEntry) {
    test::TempDir dir;
    const auto p = payload(1 << 20, 4);
    std::atomic<bool> stop{false};
    std::atomic<int> bad{0}, hits{0};
    std::vector<std::thread> threads;
    // Writers that keep replacing the entry (each check-then-write may race
    // another's rename), readers that keep loading it.
    for (int w = 0; w < 2; ++w)
        threads.emplace_back([&] {
            const DiskCache cache(dir / "cache");
            for (int i = 0; i < 20; ++i) {
                std::error_code ec;
                fs::remove(cache.entryPath("grid", 5), ec); // so that the store writes
                cache.store("grid", 5, p);
            }
        });
    for (int r = 0; r < 2; ++r)
        threads.emplace_back([&] {
            const DiskCache cache(dir / "cache");
            while (!stop) {
                if (const auto loaded = cache.load("grid", 5)) {
                    ++hits;
                    if (!(*loaded == p))
                        ++bad;
                }
                if (cache.stats().corrupt > 0)
                    ++bad;
            }
        });
    threads[0].join();
    threads[1].join();
    stop = true;
    threads[2].join();
    threads[3].join();
    EXPECT_EQ(bad, 0) << "a reader saw a partial or corrupt entry";
    EXPECT_GT(hits, 0);
    // No temporary left behind.
    std::size_t files = 0;
    for (const auto& e : fs::directory_iterator(dir / "cache" / "grid")) {
        EXPECT_EQ(e.path().extension(), ".bin") << e.path();
        ++files;
    }
    EXPECT_LE(files, 1u);
}

} // namespace
} // namespace hairvox
