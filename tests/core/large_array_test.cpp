// Storage for large arrays (core/large_array.h): vector semantics, alignment,
// and the huge-page advice the kernel records for a large block.
#include <hairvox/core/large_array.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>

namespace hairvox {
namespace {

/// The kernel's transparent-huge-page mode: "always", "madvise" or "never".
std::string thpMode() {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string line;
    std::getline(in, line);
    const std::size_t open = line.find('['), close = line.find(']');
    return open == std::string::npos || close == std::string::npos
               ? std::string("never")
               : line.substr(open + 1, close - open - 1);
}

/// The "THPeligible" flag of the mapping of /proc/self/smaps holding `p`.
int thpEligible(const void* p) {
    const auto address = reinterpret_cast<std::uintptr_t>(p);
    std::ifstream in("/proc/self/smaps");
    bool inside = false;
    for (std::string line; std::getline(in, line);) {
        std::uintptr_t begin = 0, end = 0;
        char dash = 0;
        std::istringstream header(line);
        if (header >> std::hex >> begin >> dash >> end && dash == '-') {
            inside = begin <= address && address < end;
            continue;
        }
        if (inside && line.starts_with("THPeligible:"))
            return std::stoi(line.substr(12));
    }
    return -1;
}

TEST(LargeArray, BehavesAsAVectorAcrossGrowth) {
    LargeVector<std::uint32_t> v;
    for (std::uint32_t i = 0; i < 3'000'000; ++i) // grows through kHugePageBytes
        v.push_back(i);
    std::uint64_t sum = std::accumulate(v.begin(), v.end(), std::uint64_t(0));
    EXPECT_EQ(sum, std::uint64_t(2'999'999) * 3'000'000 / 2);
    v.assign(10, 7u); // assign writes
    EXPECT_EQ(std::accumulate(v.begin(), v.end(), 0u), 70u);
    LargeVector<float> w(1000, 0.5f); // so does construction from a value
    EXPECT_EQ(std::accumulate(w.begin(), w.end(), 0.0f), 500.0f);
}

TEST(LargeArray, BufferHoldsWhatItsProducerWritesAndMovesOut) {
    struct Lanes3 {
        float v[3] = {1, 2, 3}; // default member initialisers: not run by LargeBuffer(n)
    };
    LargeBuffer<Lanes3> empty;
    EXPECT_TRUE(empty.empty());
    EXPECT_EQ(empty.begin(), empty.end());

    const std::size_t n = kHugePageBytes / sizeof(Lanes3) + 10; // a huge-page block
    LargeBuffer<Lanes3> a(n);
    ASSERT_EQ(a.size(), n);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(a.data()) % kHugePageBytes, 0u);
    std::uninitialized_fill(a.begin(), a.end(), Lanes3{{4, 5, 6}});
    EXPECT_EQ(a[n - 1].v[2], 6.0f);

    LargeBuffer<Lanes3> b = std::move(a);
    EXPECT_EQ(b.size(), n);
    EXPECT_EQ(b[0].v[0], 4.0f);
    EXPECT_TRUE(a.empty()); // NOLINT(bugprone-use-after-move): moved-from is empty
    EXPECT_EQ(a.data(), nullptr);

    const LargeBuffer<float> c(1000, 0.5f); // (n, value) writes
    EXPECT_EQ(std::accumulate(c.begin(), c.end(), 0.0f), 500.0f);
    EXPECT_EQ(c.bytes(), 1000 * sizeof(float));
}

TEST(LargeArray, LargeBlocksAreHugePageAlignedAndAdvised) {
    constexpr std::size_t bytes = 3 * kHugePageBytes + 12345;
    void* p = allocateLarge(bytes, 64);
    ASSERT_NE(p, nullptr);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p) % kHugePageBytes, 0u);
    static_cast<char*>(p)[bytes - 1] = 1; // the whole size is usable
    const std::string mode = thpMode();
    if (mode == "never") {
        deallocateLarge(p, bytes, 64);
        GTEST_SKIP() << "transparent huge pages are off on this kernel";
    }
    EXPECT_EQ(thpEligible(p), 1) << "THP mode " << mode;
    deallocateLarge(p, bytes, 64);

    // A small block keeps its own alignment, without the 2 MiB rounding.
    void* q = allocateLarge(1000, 256);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(q) % 256, 0u);
    deallocateLarge(q, 1000, 256);
}

} // namespace
} // namespace hairvox
