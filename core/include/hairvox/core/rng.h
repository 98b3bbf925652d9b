// hairvox core: a small deterministic random number generator.
//
// PCG32 (O'Neill 2014, pcg-random.org, the generator pbrt-v4 uses): the same
// seed gives the same sequence on every platform and standard library, which
// the procedural grooms and the tests rely on (std:: distributions do not
// guarantee that).
#pragma once

#include <cstdint>

namespace hairvox {

class Pcg32 {
public:
    explicit Pcg32(std::uint64_t seed, std::uint64_t stream = 0xda3e39cb94b95bdbull) {
        inc_ = (stream << 1u) | 1u;
        nextU32();
        state_ += seed;
        nextU32();
    }

    std::uint32_t nextU32() {
        const std::uint64_t old = state_;
        state_ = old * 0x5851f42d4c957f2dull + inc_;
        const auto xorShifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
        const auto rot = static_cast<std::uint32_t>(old >> 59u);
        return (xorShifted >> rot) | (xorShifted << ((~rot + 1u) & 31u));
    }

    /// Uniform in [0, 1).
    float uniformFloat() { return static_cast<float>(nextU32() >> 8) * 0x1p-24f; }
    double uniformDouble() {
        const std::uint64_t hi = nextU32() >> 5, lo = nextU32() >> 6;
        return static_cast<double>((hi << 26) | lo) * 0x1p-53;
    }
    /// Uniform in [a, b).
    float uniform(float a, float b) { return a + (b - a) * uniformFloat(); }

private:
    std::uint64_t state_ = 0x853c49e6748fea9bull;
    std::uint64_t inc_ = 0;
};

} // namespace hairvox
