// The render, probe, transmittance and tables commands end to end.
#include "test_util.h"

#include <gtest/gtest.h>

namespace hairvox {
namespace {

using test::quoted;
using test::readBytes;

TEST(CliCommands, RenderDefaultSceneSmall) {
    test::TempDir dir;
    const auto exr = dir / "d.exr";
    const auto r = test::runHairvox("render --width 48 --height 48 --threads 2 -o " + quoted(exr) +
                                    " --png " + quoted(dir / "d.png"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(std::filesystem::exists(exr));
    EXPECT_TRUE(std::filesystem::exists(dir / "d.png"));
    for (const char* stage :
         {"load", "voxelize", "tables", "global term", "raster", "shade", "write"})
        EXPECT_NE(r.output.find(stage), std::string::npos) << stage << "\n" << r.output;
    EXPECT_NE(r.output.find("behind opaque"), std::string::npos) << r.output;
}

TEST(CliCommands, RenderRejectsBadSceneAndOptions) {
    test::TempDir dir;
    std::string scene = readBytes(test::dataDir() / "scenes" / "key_back.json");
    const std::string direction = "\"direction\": [-0.2, 0.55, 0.8]";
    ASSERT_NE(scene.find(direction), std::string::npos);
    scene.replace(scene.find(direction), direction.size(), "\"direction\": \"up\"");
    test::writeText(dir / "bad.json", scene);
    auto r = test::runHairvox("render " + quoted(dir / "bad.json"));
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("/lights/0/direction"), std::string::npos) << r.output;
    EXPECT_EQ(test::runHairvox("render --mode magic").exitCode, 2);
    EXPECT_EQ(test::runHairvox("render --width 0").exitCode, 2);
    EXPECT_EQ(test::runHairvox("render " + quoted(dir / "missing.json")).exitCode, 2);
}

TEST(CliCommands, ProbeSampleThenEvaluateEveryMode) {
    test::TempDir dir;
    const std::string groom = quoted(test::dataDir() / "Ratboy_mohawk.tfx");
    auto r = test::runHairvox("probe " + groom + " --sample-points 40 --seed 2 -o " +
                              quoted(dir / "in.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(readBytes(dir / "in.csv").rfind("x,y,z,tx,ty,tz,strand\n", 0), 0u);
    for (const char* mode : {"exact", "grid", "approx"}) {
        const auto out = dir / (std::string(mode) + ".csv");
        r = test::runHairvox("probe " + groom + " --points " + quoted(dir / "in.csv") +
                             " --light-dir 0,1,0.3 --mode " + mode +
                             " --rays 8 --radius 0.003 -o " + quoted(out));
        ASSERT_EQ(r.exitCode, 0) << mode << ": " << r.output;
        const std::string csv = readBytes(out);
        EXPECT_EQ(csv.rfind("x,y,z,tx,ty,tz,n,V,P_r,P_g,P_b,Ts_r,Ts_g,Ts_b,sf2_r,sf2_g,sf2_b\n", 0),
                  0u);
        EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 41);
    }
}

TEST(CliCommands, ProbeRejectsBadInput) {
    test::TempDir dir;
    const std::string groom = quoted(test::dataDir() / "Ratboy_mohawk.tfx");
    test::writeText(dir / "bad.csv", "x,y,z,tx,ty,tz\n0,0,zero,1,0,0\n");
    auto r = test::runHairvox("probe " + groom + " --points " + quoted(dir / "bad.csv") +
                              " --light-dir 0,1,0 -o " + quoted(dir / "o.csv"));
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.output.find("bad.csv:2"), std::string::npos) << r.output;
    test::writeText(dir / "ok.csv", "x,y,z,tx,ty,tz\n0,0,0,1,0,0\n");
    // No light, a zero light direction, both lights.
    EXPECT_EQ(test::runHairvox("probe " + groom + " --points " + quoted(dir / "ok.csv") + " -o " +
                               quoted(dir / "o.csv"))
                  .exitCode,
              2);
    EXPECT_EQ(test::runHairvox("probe " + groom + " --points " + quoted(dir / "ok.csv") +
                               " --light-dir 0,0,0 -o " + quoted(dir / "o.csv"))
                  .exitCode,
              2);
    EXPECT_EQ(test::runHairvox("probe " + groom + " --points " + quoted(dir / "ok.csv") +
                               " --light-dir 0,1,0 --light-pos 0,1,0 -o " + quoted(dir / "o.csv"))
                  .exitCode,
              2);
    EXPECT_FALSE(std::filesystem::exists(dir / "o.csv"));
}

TEST(CliCommands, TransmittanceWritesLitGrid) {
    test::TempDir dir;
    const auto vdb = dir / "lit.vdb";
    const auto r =
        test::runHairvox("transmittance " + quoted(test::dataDir() / "Ratboy_mohawk.tfx") +
                         " --light-pos 0,1.5,0.5 --voxel-size 0.008 -o " + quoted(vdb));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    ASSERT_TRUE(std::filesystem::exists(vdb));
    const auto print = test::runShell("vdb_print -l " + quoted(vdb) + " 2>&1");
    if (print.exitCode == 127)
        GTEST_SKIP() << "vdb_print is not installed";
    for (const char* grid :
         {"Name: n", "Name: V", "Name: T_s", "Name: sigma2_f", "mode: grid", "light_type: point"})
        EXPECT_NE(print.output.find(grid), std::string::npos) << grid << "\n" << print.output;
}

TEST(CliCommands, TablesFromScene) {
    test::TempDir dir;
    const auto r = test::runHairvox(
        "tables --scene " + quoted(test::dataDir() / "scenes" / "ratboy_mohawk.json") +
        " --cache-dir " + quoted(dir / "cache") + " -o " + quoted(dir / "t.csv"));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_EQ(readBytes(dir / "t.csv").rfind("theta,af_r,af_g,af_b,", 0), 0u);
    EXPECT_EQ(
        test::runHairvox("tables --scene x.json --eta 1.5 -o " + quoted(dir / "u.csv")).exitCode,
        2); // --scene excludes fiber options
}

} // namespace
} // namespace hairvox
