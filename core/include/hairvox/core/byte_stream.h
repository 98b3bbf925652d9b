// hairvox core: values to bytes and back, for cache entries (disk_cache.h)
// that machines of one architecture share: host byte order, trivially
// copyable values as their bytes, arrays with a 64-bit count before them.
// A reader never reads past its bytes: every get() says whether the value
// was there, and an array's count is checked against what is left before
// anything is allocated.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace hairvox {

class ByteWriter {
public:
    template <typename T>
    requires std::is_trivially_copyable_v<T> ByteWriter& put(const T& v) {
        return bytes(&v, sizeof(T));
    }
    /// A count, then the elements' bytes.
    template <typename T>
    requires std::is_trivially_copyable_v<T> ByteWriter& array(std::span<const T> values) {
        put(std::uint64_t{values.size()});
        return bytes(values.data(), values.size_bytes());
    }
    ByteWriter& string(const std::string& s) {
        return array(std::span<const char>(s.data(), s.size()));
    }
    ByteWriter& bytes(const void* data, std::size_t size) {
        const std::size_t at = out.size();
        out.resize(at + size);
        if (size > 0)
            std::memcpy(out.data() + at, data, size);
        return *this;
    }

    std::vector<std::byte> out;
};

class ByteReader {
public:
    explicit ByteReader(std::span<const std::byte> in)
        : in_(in) {}

    template <typename T>
    requires std::is_trivially_copyable_v<T>
    bool get(T& v) { return bytes(&v, sizeof(T)); }
    /// A counted array into `v` (resized); false, and `v` untouched, when
    /// the count is more than the bytes left hold.
    template <typename V>
    requires std::is_trivially_copyable_v<typename V::value_type>
    bool array(V& v) {
        using T = typename V::value_type;
        std::uint64_t count = 0;
        if (!get(count) || count > (in_.size() - at_) / sizeof(T))
            return false;
        v.resize(count);
        return bytes(v.data(), v.size() * sizeof(T));
    }
    bool string(std::string& s) { return array(s); }
    bool bytes(void* data, std::size_t size) {
        if (size > in_.size() - at_)
            return false;
        if (size > 0)
            std::memcpy(data, in_.data() + at_, size);
        at_ += size;
        return true;
    }
    bool atEnd() const { return at_ == in_.size(); }

private:
    std::span<const std::byte> in_;
    std::size_t at_ = 0;
};

} // namespace hairvox
