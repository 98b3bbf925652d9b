// Internal to hairvox strands: a groom file's bytes in memory with
// bounds-checked, overflow-safe little-endian reads. Every read names the file
// and the field on failure, so readers never index past the end of what was read.
#pragma once

#include <hairvox/core/error.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace hairvox::detail {

static_assert(std::endian::native == std::endian::little,
              "the binary groom readers assume a little-endian host");

/// Reads the whole file; refuses files over `maxBytes`.
std::vector<unsigned char> readFileBytes(const std::filesystem::path& path,
                                         std::uint64_t maxBytes);

/// A view of a file's bytes (which must outlive it) named for error messages.
class FileBytes {
public:
    FileBytes(std::span<const unsigned char> bytes, std::string name)
        : name_(std::move(name)), bytes_(bytes) {}

    const std::string& name() const { return name_; }
    std::uint64_t size() const { return bytes_.size(); }
    std::span<const unsigned char> bytes() const { return bytes_; }

    template <typename T>
        requires std::is_trivially_copyable_v<T>
    T read(std::uint64_t offset, const char* field) const {
        T value;
        checkRange(offset, 1, sizeof(T), field);
        std::memcpy(&value, bytes_.data() + offset, sizeof(T));
        return value;
    }

    /// Copies `count` values of T starting at byte `offset` into `out`.
    template <typename T>
        requires std::is_trivially_copyable_v<T>
    void readArray(std::uint64_t offset, std::uint64_t count, std::vector<T>& out,
                   const char* field) const {
        checkRange(offset, count, sizeof(T), field);
        out.resize(count);
        if (count > 0)
            std::memcpy(out.data(), bytes_.data() + offset, count * sizeof(T));
    }

    /// Throws InputError unless [offset, offset + count·elementSize) lies in the file.
    void checkRange(std::uint64_t offset, std::uint64_t count, std::uint64_t elementSize,
                    const char* field) const;

private:
    std::string name_;
    std::span<const unsigned char> bytes_;
};

} // namespace hairvox::detail
