// Cem Yuksel's .hair format (cemyuksel.com/research/hairmodels), layout in
// data/README.md: a 128-byte header, then the arrays whose bits are set.
#include "file_bytes.h"

#include <hairvox/core/atomic_file.h>
#include <hairvox/strands/groom_io.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>
#include <limits>

namespace hairvox {

namespace {

enum HairArrayBits : std::uint32_t {
    kSegments = 1,
    kPoints = 2,
    kThickness = 4,
    kTransparency = 8,
    kColors = 16,
};
constexpr std::uint32_t kKnownBits = kSegments | kPoints | kThickness | kTransparency | kColors;

#pragma pack(push, 1)
struct HairHeader {
    char magic[4];
    std::uint32_t hairCount;
    std::uint32_t pointCount;
    std::uint32_t arrays;
    std::uint32_t defaultSegments;
    float defaultThickness;
    float defaultTransparency;
    float defaultColor[3];
    char info[88];
};
#pragma pack(pop)
static_assert(sizeof(HairHeader) == 128);

/// The .hair writer's default thickness when the groom has none: 0.1 mm, a
/// human hair in metres (the unit of the procedural grooms).
constexpr float kDefaultThicknessMetres = 1e-4f;

} // namespace

LoadedGroom readHairFile(const std::filesystem::path& path, const GroomReadOptions& options) {
    // At most 34 bytes per point: 8 floats of arrays and a segment count.
    const std::vector<unsigned char> bytes =
        detail::readFileBytes(path, sizeof(HairHeader) + 34 * options.maxPoints);
    return parseHairBytes(bytes, path.string(), options);
}

LoadedGroom parseHairBytes(std::span<const unsigned char> bytes, const std::string& name,
                           const GroomReadOptions& options) {
    const detail::FileBytes file(bytes, name);
    if (file.size() < sizeof(HairHeader))
        throw InputError(strCat(name, ": truncated header: ", file.size(),
                                " bytes, a .hair header is 128"));
    const auto header = file.read<HairHeader>(0, "header");
    if (std::memcmp(header.magic, "HAIR", 4) != 0)
        throw InputError(strCat(name, ": not a .hair file (wrong magic; expected 'HAIR')"));
    if ((header.arrays & ~kKnownBits) != 0)
        throw InputError(strCat(name, ": unknown array bits 0x", std::hex,
                                header.arrays & ~kKnownBits, " in the header"));
    if (!(header.arrays & kPoints))
        throw InputError(strCat(name, ": the header declares no points array"));

    const std::uint64_t strands = header.hairCount, points = header.pointCount;
    if (points > options.maxPoints)
        throw InputError(strCat(name, ": header declares ", points,
                                " points, more than the limit of ", options.maxPoints));
    if (strands > points)
        throw InputError(strCat(name, ": header declares ", strands, " strands but only ", points,
                                " points; every strand needs points"));

    // The arrays' total size must equal the file size: check before allocating.
    std::uint64_t expected = sizeof(HairHeader);
    if (header.arrays & kSegments)
        expected += strands * sizeof(std::uint16_t);
    const std::uint64_t perPoint =
        3 * sizeof(float) + ((header.arrays & kThickness) ? sizeof(float) : 0) +
        ((header.arrays & kTransparency) ? sizeof(float) : 0) +
        ((header.arrays & kColors) ? 3 * sizeof(float) : 0);
    expected += points * perPoint;
    if (expected != file.size())
        throw InputError(strCat(name, ": header declares ", strands, " strands and ", points,
                                " points, which need ", expected, " bytes, but the file has ",
                                file.size(), expected > file.size() ? " (truncated)" : ""));

    LoadedGroom loaded;
    loaded.format = GroomFormat::Hair;
    Groom& groom = loaded.groom;
    std::uint64_t offset = sizeof(HairHeader);

    // Strand offsets from the segments array or the default segment count.
    if (strands > 0) {
        groom.strandStart.reserve(strands + 1);
        groom.strandStart.push_back(0);
        std::uint64_t total = 0;
        std::vector<std::uint16_t> segments;
        if (header.arrays & kSegments) {
            file.readArray(offset, strands, segments, "segments array");
            offset += strands * sizeof(std::uint16_t);
        }
        for (std::uint64_t s = 0; s < strands; ++s) {
            total += 1u + ((header.arrays & kSegments) ? segments[s] : header.defaultSegments);
            if (total > points)
                throw InputError(strCat(name, ": strand segment counts need more than the ",
                                        points, " points the header declares"));
            groom.strandStart.push_back(static_cast<std::uint32_t>(total));
        }
        if (total != points)
            throw InputError(strCat(name, ": strand segment counts need ", total,
                                    " points but the header declares ", points));
    } else if (points > 0) {
        throw InputError(strCat(name, ": header declares ", points, " points but no strands"));
    }

    std::vector<float> raw;
    file.readArray(offset, 3 * points, raw, "points array");
    offset += 3 * points * sizeof(float);
    groom.points.resize(points);
    for (std::uint64_t i = 0; i < points; ++i)
        groom.points[i] = Vec3f(raw[3 * i], raw[3 * i + 1], raw[3 * i + 2]);
    if (header.arrays & kThickness) {
        file.readArray(offset, points, groom.thickness, "thickness array");
        offset += points * sizeof(float);
    }
    if (header.arrays & kTransparency) {
        file.readArray(offset, points, groom.transparency, "transparency array");
        offset += points * sizeof(float);
    }
    if (header.arrays & kColors) {
        file.readArray(offset, 3 * points, raw, "colors array");
        groom.color.resize(points);
        for (std::uint64_t i = 0; i < points; ++i)
            groom.color[i] = Rgb(raw[3 * i], raw[3 * i + 1], raw[3 * i + 2]);
    }

    loaded.sanitized = sanitizeGroom(groom, name);
    return loaded;
}

void writeHairFile(const std::filesystem::path& path, const Groom& groom, const std::string& info) {
    HairHeader header{};
    std::memcpy(header.magic, "HAIR", 4);
    if (groom.pointCount() > std::numeric_limits<std::uint32_t>::max() ||
        groom.strandCount() > std::numeric_limits<std::uint32_t>::max())
        throw InputError(strCat(path.string(), ": groom too large for the .hair format"));
    header.hairCount = static_cast<std::uint32_t>(groom.strandCount());
    header.pointCount = static_cast<std::uint32_t>(groom.pointCount());

    std::vector<std::uint16_t> segments(groom.strandCount());
    for (std::size_t s = 0; s < groom.strandCount(); ++s) {
        const std::size_t count = groom.strand(s).size() - 1;
        if (count > std::numeric_limits<std::uint16_t>::max())
            throw InputError(strCat(path.string(), ": strand ", s, " has ", count,
                                    " segments; the .hair format allows at most 65535"));
        segments[s] = static_cast<std::uint16_t>(count);
    }
    const bool uniform =
        std::adjacent_find(segments.begin(), segments.end(), std::not_equal_to<>()) ==
        segments.end();

    header.arrays = kPoints | (uniform ? 0u : kSegments) |
                    (groom.thickness.empty() ? 0u : kThickness) |
                    (groom.transparency.empty() ? 0u : kTransparency) |
                    (groom.color.empty() ? 0u : kColors);
    header.defaultSegments = uniform && !segments.empty() ? segments.front() : 0;
    header.defaultThickness = kDefaultThicknessMetres;
    header.defaultTransparency = 0.0f;
    header.defaultColor[0] = header.defaultColor[1] = header.defaultColor[2] = 1.0f;
    std::strncpy(header.info, info.c_str(), sizeof(header.info) - 1);

    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out)
            throw InputError(strCat(path.string(), ": cannot open for writing"));
        const auto put = [&out](const void* data, std::size_t bytes) {
            out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
        };
        put(&header, sizeof(header));
        if (!uniform)
            put(segments.data(), segments.size() * sizeof(std::uint16_t));
        static_assert(sizeof(Vec3f) == 3 * sizeof(float) && sizeof(Rgb) == 3 * sizeof(float));
        put(groom.points.data(), groom.points.size() * sizeof(Vec3f));
        put(groom.thickness.data(), groom.thickness.size() * sizeof(float));
        put(groom.transparency.data(), groom.transparency.size() * sizeof(float));
        put(groom.color.data(), groom.color.size() * sizeof(Rgb));
        out.flush();
        if (!out)
            throw InputError(strCat(path.string(), ": write failed (disk full?)"));
    });
}

} // namespace hairvox
