// Issue 8: every file of the malformed-input corpus (data/malformed/, made by
// tests/reliability/make_corpora.py) gives a clear error and exit code 2 from
// the CLI, within a memory bound and a time bound: `hairvox info FILE` for
// grooms, `hairvox render SCENE.json` for scenes.
#include "child_process.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <utility>
#include <vector>

namespace hairvox {
namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kAddressSpaceBytes = std::uint64_t(1) << 30;
constexpr double kTimeLimitSeconds = 20;

fs::path corpusDir() { return test::dataDir() / "malformed"; }

/// expected.txt: "file<TAB>fragment of the error message" per line.
std::map<std::string, std::string> expectedMessages() {
    std::map<std::string, std::string> expected;
    std::ifstream in(corpusDir() / "expected.txt");
    for (std::string line; std::getline(in, line);) {
        if (line.empty() || line.front() == '#')
            continue;
        const std::size_t tab = line.find('\t');
        if (tab != std::string::npos)
            expected[line.substr(0, tab)] = line.substr(tab + 1);
    }
    return expected;
}

TEST(MalformedInput, CorpusAndExpectationsMatch) {
    const std::map<std::string, std::string> expected = expectedMessages();
    ASSERT_GE(expected.size(), 50u) << "expected.txt is missing or short";
    std::set<std::string> files;
    for (const fs::directory_entry& e : fs::directory_iterator(corpusDir()))
        if (e.path().filename() != "expected.txt")
            files.insert(e.path().filename().string());
    for (const std::string& f : files)
        EXPECT_TRUE(expected.count(f)) << f << " has no line in expected.txt";
    for (const auto& [f, fragment] : expected)
        EXPECT_TRUE(files.count(f)) << "expected.txt names " << f << ", which does not exist";
}

/// The CLI command that reads `file`: `info` for grooms, `render` for scenes.
test::ChildOptions commandFor(const fs::path& file, const fs::path& workDir) {
    test::ChildOptions options;
    options.workDir = workDir;
    options.addressSpace = kAddressSpaceBytes;
    options.env = {"HAIRVOX_CACHE_DIR=" + (workDir / "cache").string()};
    if (file.extension() == ".json")
        options.args = {"render", file.string(), "--quiet", "--width", "16", "--height", "16",
                        "-o", (workDir / "out.exr").string()};
    else
        options.args = {"info", file.string()};
    return options;
}

TEST(MalformedInput, EveryFileGivesAClearErrorAndExitCode2) {
    const std::map<std::string, std::string> expected = expectedMessages();
    ASSERT_FALSE(expected.empty());
    constexpr std::size_t kConcurrent = 4; // the children mostly wait on loading libraries
    double slowest = 0;
    std::string slowestFile;
    for (auto batch = expected.begin(); batch != expected.end();) {
        std::vector<std::pair<std::string, std::string>> files;
        std::vector<std::unique_ptr<test::TempDir>> dirs;
        std::vector<std::unique_ptr<test::Child>> children;
        for (; batch != expected.end() && files.size() < kConcurrent; ++batch) {
            files.push_back(*batch);
            dirs.push_back(std::make_unique<test::TempDir>());
            children.push_back(std::make_unique<test::Child>(
                commandFor(corpusDir() / batch->first, dirs.back()->path())));
        }
        for (std::size_t i = 0; i < files.size(); ++i) {
            const auto& [name, fragment] = files[i];
            const test::ChildResult r = children[i]->wait(kTimeLimitSeconds);
            SCOPED_TRACE(name + ": " + r.output);
            EXPECT_FALSE(r.timedOut) << "no answer within " << kTimeLimitSeconds << " s";
            EXPECT_TRUE(r.exited) << "ended by signal " << r.signal;
            EXPECT_EQ(r.exitCode, 2);
            EXPECT_NE(r.output.find("hairvox: error: "), std::string::npos);
            EXPECT_NE(r.output.find(fragment), std::string::npos) << "expected: " << fragment;
            EXPECT_EQ(r.output.find("internal error"), std::string::npos);
            EXPECT_EQ(r.output.find("Sanitizer"), std::string::npos);
            EXPECT_LT(r.output.size(), 1000u) << "the message should be short";
            EXPECT_FALSE(fs::exists(dirs[i]->path() / "out.exr"));
            if (r.seconds > slowest) {
                slowest = r.seconds;
                slowestFile = name;
            }
        }
    }
    std::printf("malformed corpus: %zu files, slowest %s in %.2f s, address space %s\n",
                expected.size(), slowestFile.c_str(), slowest,
                test::kSanitizedBuild ? "unbounded (sanitizer build)" : "limited to 1 GiB");
}

} // namespace
} // namespace hairvox
