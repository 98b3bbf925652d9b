#include <hairvox/bench/host_report.h>
#include <hairvox/shading/simd.h>

#include <cstdio>
#include <ostream>
#include <sstream>

namespace hairvox::bench {

namespace {

std::string fixed(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
    return buf;
}

} // namespace

HostReport HostReport::measure() {
    HostReport r;
    r.host = HostInfo::current();
    r.simdTarget = hairvox::simdTarget();
    r.simdFmaFlopsPerSecond = simdFmaPeak().flopsPerSecond;
    r.calibration = calibrateMachine();
    return r;
}

std::vector<std::pair<std::string, std::string>> HostReport::entries() const {
    const MachineCalibration& c = calibration;
    return {{"cpu_model", host.cpuModel},
            {"logical_cores", std::to_string(host.logicalCores)},
            {"simd_target", simdTarget},
            {"simd_fma_gflops", fixed(simdFmaFlopsPerSecond * 1e-9, 1)},
            {"dram_gb_per_s", fixed(c.dramBytesPerSecond * 1e-9, 2)},
            {"miss_latency_ns", fixed(c.missLatencyNs, 1)},
            {"baseline_gflops", fixed(c.baselineFlopsPerSecond * 1e-9, 2)},
            {"calibration_s", fixed(c.seconds, 3)}};
}

std::string HostReport::line() const {
    std::ostringstream os;
    os << *this;
    return os.str();
}

std::ostream& operator<<(std::ostream& os, const HostReport& r) {
    return os << r.host << ", SIMD " << r.simdTarget << " (FMA "
              << fixed(r.simdFmaFlopsPerSecond * 1e-9, 1) << " GFLOP/s, 1 thread); "
              << r.calibration;
}

} // namespace hairvox::bench
