#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>

namespace hairvox {
namespace {

TEST(Cli, GenerateThenInfo) {
    test::TempDir dir;
    const auto out = dir / "w.hair";
    auto r = test::runHairvox("generate wavy --strands 100 --seed 3 -o '" + out.string() + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    r = test::runHairvox("info '" + out.string() + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("strands:             100"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("total fiber length"), std::string::npos) << r.output;
}

TEST(Cli, InfoOnRatboy) {
    const auto r =
        test::runHairvox("info --json '" + (test::dataDir() / "Ratboy_mohawk.tfx").string() + "'");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("\"strands\": 2228"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("\"points\": 71296"), std::string::npos) << r.output;
}

/// The subcommands `hairvox --help` lists (the indented words after "Subcommands:").
std::vector<std::string> listedSubcommands() {
    const std::string help = test::runHairvox("--help").output;
    std::vector<std::string> names;
    std::istringstream in(help.substr(help.find("Subcommands:")));
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
        std::istringstream words(line);
        std::string name;
        if (line.rfind("  ", 0) == 0 && words >> name)
            names.push_back(name);
    }
    return names;
}

TEST(Cli, HelpOnEverySubcommand) {
    const std::vector<std::string> subcommands = listedSubcommands();
    // Every command a user can type; a new one is covered by being listed.
    for (const char* known : {"bench", "compare", "generate", "info", "probe", "render", "tables",
                              "transmittance", "voxelize"})
        EXPECT_NE(std::find(subcommands.begin(), subcommands.end(), known), subcommands.end())
            << known;
    for (const std::string& sub : subcommands) {
        const auto r = test::runHairvox(sub + " --help");
        EXPECT_EQ(r.exitCode, 0) << sub << ": " << r.output;
        EXPECT_NE(r.output.find("Usage"), std::string::npos) << sub;
        EXPECT_NE(r.output.find(sub), std::string::npos) << sub << ": help of another command";
        EXPECT_NE(r.output.find("--help"), std::string::npos) << sub;
    }
    const auto top = test::runHairvox("--help");
    EXPECT_EQ(top.exitCode, 0);
    EXPECT_NE(top.output.find("Usage"), std::string::npos);
}

TEST(Cli, BadUsageAndBadInputExitWith2) {
    test::TempDir dir;
    EXPECT_EQ(test::runHairvox("").exitCode, 2);
    EXPECT_EQ(test::runHairvox("frobnicate").exitCode, 2);
    EXPECT_EQ(test::runHairvox("generate spiky -o x.hair").exitCode, 2);
    EXPECT_EQ(test::runHairvox("generate wavy --strands 0 -o x.hair").exitCode, 2);
    // Beyond a groom's 32-bit point index, and beyond the machine's memory:
    // refused before anything is allocated, naming the options.
    for (const char* huge : {"--strands 10000000 --points-per-strand 4096",
                             "--strands 10000000 --points-per-strand 400"}) {
        const auto g = test::runHairvox(std::string("generate wavy ") + huge + " -o '" +
                                        (dir / "huge.hair").string() + "'");
        EXPECT_EQ(g.exitCode, 2) << g.output;
        EXPECT_NE(g.output.find("points"), std::string::npos) << g.output;
        EXPECT_FALSE(std::filesystem::exists(dir / "huge.hair"));
    }
    test::writeText(dir / "bad.hair", "HAIR but not really");
    const auto r = test::runHairvox("info '" + (dir / "bad.hair").string() + "'");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.output.find("bad.hair"), std::string::npos) << r.output;
    EXPECT_EQ(test::runHairvox("info '" + (dir / "missing.tfx").string() + "'").exitCode, 2);
}

TEST(Cli, UnwritableOutputExitsWith2) {
    const auto r = test::runHairvox("generate wavy --strands 10 -o /proc/hairvox/x.hair");
    EXPECT_EQ(r.exitCode, 2) << r.output;
}

} // namespace
} // namespace hairvox
