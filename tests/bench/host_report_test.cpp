#include <hairvox/bench/host_report.h>
#include <hairvox/shading/simd.h>

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

namespace hairvox {
namespace {

TEST(BenchHost, ReportsTheHostTheKernelsTargetAndTheCalibration) {
    const bench::HostReport r = bench::HostReport::measure();
    EXPECT_EQ(r.simdTarget, simdTarget());
    EXPECT_TRUE(std::isfinite(r.simdFmaFlopsPerSecond));
    EXPECT_GT(r.simdFmaFlopsPerSecond, 0.0);
    const auto entries = r.entries();
    const std::map<std::string, std::string> byKey(entries.begin(), entries.end());
    ASSERT_EQ(byKey.size(), entries.size()) << "a key twice";
    for (const char* key :
         {"cpu_model", "logical_cores", "simd_target", "simd_fma_gflops", "dram_gb_per_s",
          "miss_latency_ns", "baseline_gflops", "calibration_s"}) {
        ASSERT_TRUE(byKey.count(key)) << key;
        EXPECT_FALSE(byKey.at(key).empty()) << key;
    }
    EXPECT_EQ(byKey.at("cpu_model"), r.host.cpuModel);
    EXPECT_EQ(byKey.at("simd_target"), r.simdTarget);
    EXPECT_EQ(std::stoul(byKey.at("logical_cores")), r.host.logicalCores);
    for (const char* key : {"simd_fma_gflops", "dram_gb_per_s", "miss_latency_ns"})
        EXPECT_GT(std::stod(byKey.at(key)), 0.0) << key;
    const std::string line = r.line();
    for (const std::string& part : {r.host.cpuModel, "SIMD " + r.simdTarget, std::string("DRAM ")})
        EXPECT_NE(line.find(part), std::string::npos) << part << " in " << line;
}

} // namespace
} // namespace hairvox
