#include "test_util.h"

#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <unistd.h>

namespace hairvox {
namespace {

std::string readAll(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::size_t entriesIn(const std::filesystem::path& dir) {
    return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(dir),
                                                  std::filesystem::directory_iterator()));
}

TEST(CoreAtomicFile, WritesCompleteFileAndCreatesDirectories) {
    test::TempDir dir;
    const auto target = dir / "sub/dir/out.txt";
    writeFileAtomically(target, [](const std::filesystem::path& tmp) {
        EXPECT_NE(tmp.filename(), "out.txt");
        test::writeText(tmp, "complete");
    });
    EXPECT_EQ(readAll(target), "complete");
    EXPECT_EQ(entriesIn(target.parent_path()), 1u); // no temporary left behind
}

TEST(CoreAtomicFile, FailedWriteKeepsOldFileAndRemovesTemporary) {
    test::TempDir dir;
    const auto target = dir / "out.txt";
    test::writeText(target, "old");
    EXPECT_THROW(writeFileAtomically(target,
                                     [](const std::filesystem::path& tmp) {
                                         test::writeText(tmp, "half");
                                         throw InputError("disk on fire");
                                     }),
                 InputError);
    EXPECT_EQ(readAll(target), "old");
    EXPECT_EQ(entriesIn(dir.path()), 1u);
}

TEST(CoreAtomicFile, TemporaryNamesHoldTheHostAndTheProcess) {
    // Tasks on several machines write into one shared directory: process ids
    // repeat across machines, so the host is in the name too.
    test::TempDir dir;
    const auto target = dir / "frame.0001.exr";
    char host[256] = {};
    ASSERT_EQ(::gethostname(host, sizeof(host) - 1), 0);
    std::string name;
    writeFileAtomically(target, [&](const std::filesystem::path& tmp) {
        name = tmp.filename().string();
        test::writeText(tmp, "x");
    });
    EXPECT_EQ(temporaryPrefix(target), ".frame.0001.exr.tmp-");
    EXPECT_EQ(name.rfind(temporaryPrefix(target), 0), 0u) << name;
    EXPECT_TRUE(test::contains(name, strCat("-", host, "-", ::getpid(), "-"))) << name;
}

TEST(CoreAtomicFile, RefusesDirectoryTarget) {
    test::TempDir dir;
    EXPECT_THROW(writeFileAtomically(dir.path(), [](const std::filesystem::path&) {}), InputError);
}

} // namespace
} // namespace hairvox
