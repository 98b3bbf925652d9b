#include <hairvox/core/host.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace hairvox {
namespace {

TEST(Host, NamesTheCpuAndCountsItsCores) {
    const HostInfo h = HostInfo::current();
    // This Linux host's /proc/cpuinfo names its model: the name is read, not defaulted.
    std::ifstream cpuinfo("/proc/cpuinfo");
    ASSERT_TRUE(cpuinfo) << "/proc/cpuinfo: not readable on this host";
    const std::string text((std::istreambuf_iterator<char>(cpuinfo)), {});
    ASSERT_NE(text.find("model name"), std::string::npos) << "/proc/cpuinfo has no model name";
    EXPECT_FALSE(h.cpuModel.empty());
    EXPECT_NE(h.cpuModel, "unknown CPU");
    EXPECT_NE(text.find(h.cpuModel), std::string::npos) << h.cpuModel;
    EXPECT_NE(h.cpuModel.front(), ' ');
    EXPECT_GE(h.logicalCores, 1u);
    if (std::thread::hardware_concurrency() > 0) {
        EXPECT_LE(h.logicalCores, std::thread::hardware_concurrency());
    }
    std::ostringstream os;
    os << h;
    EXPECT_NE(os.str().find(h.cpuModel), std::string::npos) << os.str();
}

TEST(Host, CalibrationFiguresAreFiniteAndPositive) {
    const MachineCalibration c = calibrateMachine();
    for (const auto& [name, value] :
         {std::pair{"DRAM bytes/s", c.dramBytesPerSecond}, std::pair{"miss ns", c.missLatencyNs},
          std::pair{"baseline FLOP/s", c.baselineFlopsPerSecond},
          std::pair{"seconds", c.seconds}}) {
        EXPECT_TRUE(std::isfinite(value)) << name;
        EXPECT_GT(value, 0.0) << name;
    }
    // Plausible for any machine this runs on, loaded or not: a triad above
    // 100 MB/s, a miss under 100 µs, more than 10 MFLOP/s.
    EXPECT_GT(c.dramBytesPerSecond, 1e8);
    EXPECT_LT(c.missLatencyNs, 1e5);
    EXPECT_GT(c.baselineFlopsPerSecond, 1e7);
    EXPECT_GE(c.arrayBytes, std::size_t(96) << 20);
    EXPECT_LE(c.arrayBytes, std::size_t(384) << 20);
    std::ostringstream os;
    os << c;
    EXPECT_NE(os.str().find("GB/s"), std::string::npos) << os.str();
}

} // namespace
} // namespace hairvox
