#include <hairvox/core/host.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <fcntl.h>
#include <fstream>
#include <iomanip>
#include <limits>
#include <numeric>
#include <new>
#include <sched.h>
#include <sys/mman.h>
#include <thread>
#include <unistd.h>

namespace hairvox {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string readCpuModel() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) {
            const std::size_t colon = line.find(':');
            const std::size_t first =
                colon == std::string::npos ? colon : line.find_first_not_of(" \t", colon + 1);
            if (first != std::string::npos)
                return line.substr(first);
        }
    return "unknown CPU";
}

unsigned countLogicalCores() {
    cpu_set_t set;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof(set), &set) == 0 && CPU_COUNT(&set) > 0)
        return static_cast<unsigned>(CPU_COUNT(&set));
    return std::max(1u, std::thread::hardware_concurrency());
}

/// An array in pages of its own, given back to the kernel when it goes (an
/// allocator would keep them, resident, for later allocations): the
/// calibration leaves no memory behind.
template <class T>
class MappedArray {
public:
    explicit MappedArray(std::size_t n) : n_(n) {
        void* p = mmap(nullptr, bytes(), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (p == MAP_FAILED)
            throw std::bad_alloc();
        data_ = static_cast<T*>(p);
    }
    MappedArray(const MappedArray&) = delete;
    MappedArray& operator=(const MappedArray&) = delete;
    ~MappedArray() { munmap(data_, bytes()); }

    T* data() { return data_; }
    T& operator[](std::size_t i) { return data_[i]; }

private:
    std::size_t bytes() const { return std::max<std::size_t>(1, n_ * sizeof(T)); }
    T* data_ = nullptr;
    std::size_t n_ = 0;
};

/// A field of /proc/self/status in bytes ("VmRSS", "VmHWM": given in kB), 0 if unreadable.
double statusBytes(const std::string& field) {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind(field + ":", 0) == 0)
            return 1024.0 * std::strtod(line.c_str() + field.size() + 1, nullptr);
    return 0;
}

/// The triad's arrays together: 3× the L3 cache, within [96, 384] MiB.
std::size_t triadBytes() {
    constexpr std::size_t kMiB = std::size_t(1) << 20;
    const long l3 = sysconf(_SC_LEVEL3_CACHE_SIZE);
    const std::size_t wanted = l3 > 0 ? 3 * static_cast<std::size_t>(l3) : 96 * kMiB;
    return std::clamp(wanted, 96 * kMiB, 384 * kMiB);
}

/// The best of a few passes of a[i] = b[i] + s·c[i]: bytes of a, b and c per second.
double triadBandwidth(std::size_t n) {
    MappedArray<float> a(n), b(n), c(n);
    for (std::size_t i = 0; i < n; ++i) { // written: first touch here, untimed
        a[i] = 0.0f;
        b[i] = 1.0f;
        c[i] = 2.0f;
    }
    const float s = 0.5f;
    double best = std::numeric_limits<double>::infinity();
    double spent = 0;
    for (int pass = 0; pass < 3 || (pass < 8 && spent < 0.06); ++pass) {
        const Clock::time_point start = Clock::now();
        float* __restrict pa = a.data();
        const float* __restrict pb = b.data();
        const float* __restrict pc = c.data();
        for (std::size_t i = 0; i < n; ++i)
            pa[i] = pb[i] + s * pc[i];
        const double t = secondsSince(start);
        // Read a lane so that the loop is not removed.
        if (a[std::size_t(pass) % n] != 2.0f)
            return 0;
        best = std::min(best, t);
        spent += t;
    }
    return 3.0 * double(n) * sizeof(float) / best;
}

/// A dependent-load chase through the cache lines of a `bytes` array (a
/// power of two of them) in the order of a full-period linear congruential
/// sequence (Knuth's MMIX multiplier): every line once, at addresses no stride
/// prefetcher follows, each load waiting for the one before. Nanoseconds per
/// load.
double missLatency(std::size_t bytes) {
    constexpr std::size_t kLineSlots = 64 / sizeof(std::uint32_t);
    const std::size_t lines = std::bit_floor(bytes / 64);
    const std::uint64_t mask = lines - 1;
    // Slot 0 of line k holds the first slot of the line after it.
    MappedArray<std::uint32_t> next(lines * kLineSlots);
    for (std::uint64_t k = 0; k < lines; ++k)
        next[k * kLineSlots] = static_cast<std::uint32_t>(
            ((k * 6364136223846793005ull + 1442695040888963407ull) & mask) * kLineSlots);
    // Four rounds along the cycle, the fastest kept: a round the scheduler
    // interrupts (a shared machine) says nothing of the memory.
    const std::size_t steps = std::min<std::size_t>(lines / 4, std::size_t(1) << 15);
    std::uint32_t at = 0;
    double best = std::numeric_limits<double>::infinity();
    for (int round = 0; round < 4; ++round) {
        const Clock::time_point start = Clock::now();
        for (std::size_t step = 0; step < steps; ++step)
            at = next[at];
        best = std::min(best, secondsSince(start));
    }
    return at == std::numeric_limits<std::uint32_t>::max() ? 0 : 1e9 * best / double(steps);
}

/// Independent double multiply-add chains as the x86-64 baseline compiles
/// them (no FMA): FLOP/s, the best of three.
double baselineFlops() {
    constexpr int kChains = 16, kSteps = 1 << 20;
    volatile double seed = 1.0; // not a constant the compiler could fold
    double best = std::numeric_limits<double>::infinity();
    double sink = 0;
    for (int pass = 0; pass < 3; ++pass) {
        double acc[kChains];
        for (int k = 0; k < kChains; ++k)
            acc[k] = seed + k;
        const double m = 0.999999, add = 1e-7;
        const Clock::time_point start = Clock::now();
        for (int step = 0; step < kSteps; ++step)
            for (int k = 0; k < kChains; ++k)
                acc[k] = acc[k] * m + add;
        best = std::min(best, secondsSince(start));
        sink += std::accumulate(acc, acc + kChains, 0.0);
    }
    return sink > 0 ? 2.0 * kChains * double(kSteps) / best : 0;
}

} // namespace

HostInfo HostInfo::current() {
    return {readCpuModel(), countLogicalCores()};
}

MachineCalibration calibrateMachine() {
    const Clock::time_point start = Clock::now();
    MachineCalibration c;
    c.arrayBytes = triadBytes();
    c.dramBytesPerSecond = triadBandwidth(c.arrayBytes / (3 * sizeof(float)));
    c.missLatencyNs = missLatency(c.arrayBytes);
    c.baselineFlopsPerSecond = baselineFlops();
    c.seconds = secondsSince(start);
    resetPeakResidentMemory(); // the arrays are unmapped: not part of a later peak
    return c;
}

double residentBytes() {
    return statusBytes("VmRSS");
}

double peakResidentBytes() {
    return statusBytes("VmHWM");
}

void resetPeakResidentMemory() {
    // A control of the kernel's, not an output: written as a system call.
    const int fd = ::open("/proc/self/clear_refs", O_WRONLY | O_CLOEXEC);
    if (fd < 0)
        return;
    // Refused by a kernel before 4.0: the peak then stays what it was.
    [[maybe_unused]] const ssize_t written = ::write(fd, "5", 1);
    ::close(fd);
}

std::ostream& operator<<(std::ostream& os, const HostInfo& h) {
    return os << h.cpuModel << ", " << h.logicalCores << " logical cores";
}

std::ostream& operator<<(std::ostream& os, const MachineCalibration& c) {
    const std::ios::fmtflags flags = os.flags();
    const std::streamsize precision = os.precision();
    os << std::fixed << std::setprecision(1) << "DRAM " << c.dramBytesPerSecond * 1e-9
       << " GB/s (triad, 1 thread), miss " << std::setprecision(0) << c.missLatencyNs
       << " ns, baseline double " << std::setprecision(2) << c.baselineFlopsPerSecond * 1e-9
       << " GFLOP/s (calibrated in " << c.seconds << " s)";
    os.flags(flags);
    os.precision(precision);
    return os;
}

} // namespace hairvox
