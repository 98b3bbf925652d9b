#include <hairvox/core/hash.h>

#include <cstring>

namespace hairvox {

namespace {

std::uint64_t splitMix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

} // namespace

void Hasher::mixWord(std::uint64_t word) {
    state_ = splitMix64(state_ ^ word) + 0x9e3779b97f4a7c15ull;
}

Hasher& Hasher::bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    length_ += size;
    // Fill a partial word first, then whole words, then keep the tail pending.
    while (size > 0 && pendingBytes_ != 0) {
        pending_ |= std::uint64_t(*p++) << (8 * pendingBytes_);
        --size;
        if (++pendingBytes_ == 8) {
            mixWord(pending_);
            pending_ = 0;
            pendingBytes_ = 0;
        }
    }
    for (; size >= 8; size -= 8, p += 8) {
        std::uint64_t word;
        std::memcpy(&word, p, 8);
        mixWord(word);
    }
    for (; size > 0; --size)
        pending_ |= std::uint64_t(*p++) << (8 * pendingBytes_++);
    return *this;
}

std::uint64_t Hasher::digest() const {
    return splitMix64(splitMix64(state_ ^ pending_) ^ length_);
}

std::string hexDigest(std::uint64_t digest) {
    static constexpr char digits[] = "0123456789abcdef";
    std::string s(16, '0');
    for (int i = 15; i >= 0; --i, digest >>= 4)
        s[static_cast<std::size_t>(i)] = digits[digest & 0xf];
    return s;
}

} // namespace hairvox
