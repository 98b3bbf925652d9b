// hairvox strands: reading and writing groom files.
//
// Formats (layouts in data/README.md):
//  - Cem Yuksel .hair (binary, every optional array), read and written;
//  - AMD TressFX .tfx version 4 (binary), read;
//  - OBJ polylines (`v` and `l` records), read.
// Every reader validates sizes against the file before allocating, so that a
// corrupt or malicious file gives an InputError naming the file — never a
// crash, a hang or a huge allocation — and then runs sanitizeGroom().
#pragma once

#include <hairvox/core/enum_names.h>
#include <hairvox/strands/groom.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace hairvox {

enum class GroomFormat { Hair, Tfx, Obj };

inline constexpr EnumNames<GroomFormat, 3> kGroomFormatNames{{{
    {GroomFormat::Hair, "hair"},
    {GroomFormat::Tfx, "tfx"},
    {GroomFormat::Obj, "obj"},
}}};
inline const char* toString(GroomFormat format) {
    return kGroomFormatNames.name(format);
}

struct GroomReadOptions {
    /// Refuse files that would hold more points than this (memory guard for
    /// formats whose size is not bounded by the file size, and a sanity limit).
    std::uint64_t maxPoints = std::uint64_t(1) << 30;
};

struct LoadedGroom {
    Groom groom;
    GroomFormat format = GroomFormat::Hair;
    SanitizeReport sanitized;
    /// Human-readable notes the user should see (ignored OBJ records, ...).
    std::vector<std::string> warnings;
};

/// Reads a groom, choosing the format by magic number (.hair, .tfx) or by the
/// `.obj` extension.
LoadedGroom readGroom(const std::filesystem::path& path, const GroomReadOptions& options = {});

LoadedGroom readHairFile(const std::filesystem::path& path, const GroomReadOptions& options = {});
LoadedGroom readTfxFile(const std::filesystem::path& path, const GroomReadOptions& options = {});
LoadedGroom readObjFile(const std::filesystem::path& path, const GroomReadOptions& options = {});

/// The same readers on a file's bytes already in memory (the read*File
/// functions read the file and call these); `name` prefixes error messages.
LoadedGroom parseHairBytes(std::span<const unsigned char> bytes, const std::string& name,
                           const GroomReadOptions& options = {});
LoadedGroom parseTfxBytes(std::span<const unsigned char> bytes, const std::string& name,
                          const GroomReadOptions& options = {});
LoadedGroom parseObjBytes(std::span<const unsigned char> bytes, const std::string& name,
                          const GroomReadOptions& options = {});

/// Writes a .hair file atomically, with the optional arrays the groom has.
/// Throws InputError if a strand has more than 65,535 segments (the format's limit).
void writeHairFile(const std::filesystem::path& path, const Groom& groom,
                   const std::string& info = "hairvox");

} // namespace hairvox
