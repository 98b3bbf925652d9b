// hairvox core: 64-bit content hashing for cache keys and provenance metadata.
//
// Not cryptographic: it identifies inputs (groom contents, fiber parameters) so
// that an unchanged input is not processed twice (DESIGN.md §7). Words are
// mixed with the SplitMix64 finaliser; the length is folded in at the end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>

namespace hairvox {

class Hasher {
public:
    Hasher& bytes(const void* data, std::size_t size);

    template <typename T>
        requires std::is_trivially_copyable_v<T>
    Hasher& value(const T& v) {
        return bytes(&v, sizeof(T));
    }

    template <typename T>
        requires std::is_trivially_copyable_v<T>
    Hasher& values(std::span<const T> vs) {
        value(vs.size());
        return bytes(vs.data(), vs.size_bytes());
    }

    /// Length-prefixed, so that ("ab", "c") and ("a", "bc") differ.
    Hasher& string(std::string_view s) {
        value(s.size());
        return bytes(s.data(), s.size());
    }

    std::uint64_t digest() const;

private:
    void mixWord(std::uint64_t word);

    std::uint64_t state_ = 0x9e3779b97f4a7c15ull;
    std::uint64_t length_ = 0;
    std::uint64_t pending_ = 0; ///< bytes not yet forming a full word
    unsigned pendingBytes_ = 0;
};

/// 16 lowercase hex digits.
std::string hexDigest(std::uint64_t digest);

} // namespace hairvox
