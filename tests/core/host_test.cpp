#include <hairvox/core/host.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

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

TEST(Host, TheCalibrationLeavesNoPeakAndAPeakIsSeen) {
    // The calibration touches ≥ 96 MiB and gives it back: the peak after it
    // is the resident set's, not the calibration's (a benchmark's peak
    // memory would otherwise be at least its arrays).
    const MachineCalibration c = calibrateMachine();
    const double afterwards = peakResidentBytes();
    ASSERT_GT(residentBytes(), 0.0) << "/proc/self/status unreadable";
    EXPECT_GE(afterwards, residentBytes() - double(1 << 20)); // what was touched since
    EXPECT_LT(afterwards, residentBytes() + 0.5 * double(c.arrayBytes));
    // 64 MiB touched now is seen in the peak, and stays there once freed.
    {
        std::vector<char> block(std::size_t(64) << 20);
        for (std::size_t i = 0; i < block.size(); i += 4096)
            block[i] = char(i);
        EXPECT_EQ(block[4096], char(4096 % 256));
    }
    EXPECT_GE(peakResidentBytes(), afterwards + 60.0 * double(1 << 20));
    resetPeakResidentMemory();
    EXPECT_LT(peakResidentBytes(), residentBytes() + 32.0 * double(1 << 20));
}

} // namespace
} // namespace hairvox
