// AMD TressFX .tfx, version 4 (TressFXFileFormat.h; layout in data/README.md):
// a 160-byte header of a float32 version, the strand and per-strand vertex
// counts and five byte offsets (0 = absent), then the arrays:
//   positions float4[strands·verticesPerStrand] (w = inverse mass, ignored),
//   strand UVs float2[strands], vertex UVs float2[strands·verticesPerStrand],
//   strand thickness float[strands], vertex colours float4[strands·verticesPerStrand].
#include "file_bytes.h"

#include <hairvox/strands/groom_io.h>

#include <cmath>

namespace hairvox {

namespace {

#pragma pack(push, 1)
struct TfxHeader {
    float version;
    std::uint32_t numStrands;
    std::uint32_t verticesPerStrand;
    std::uint32_t offsetPositions;
    std::uint32_t offsetStrandUV;
    std::uint32_t offsetVertexUV;
    std::uint32_t offsetStrandThickness;
    std::uint32_t offsetVertexColor;
    std::uint32_t reserved[32];
};
#pragma pack(pop)
static_assert(sizeof(TfxHeader) == 160);

struct Float4 {
    float x, y, z, w;
};

} // namespace

LoadedGroom readTfxFile(const std::filesystem::path& path, const GroomReadOptions& options) {
    // Offsets are 32-bit, so a valid file is under 4 GiB plus its last array.
    const std::vector<unsigned char> bytes =
        detail::readFileBytes(path, sizeof(TfxHeader) + 40 * options.maxPoints);
    return parseTfxBytes(bytes, path.string(), options);
}

LoadedGroom parseTfxBytes(std::span<const unsigned char> bytes, const std::string& name,
                          const GroomReadOptions& options) {
    const detail::FileBytes file(bytes, name);
    if (file.size() < sizeof(TfxHeader))
        throw InputError(strCat(name, ": truncated header: ", file.size(),
                                " bytes, a TressFX header is 160"));
    const auto header = file.read<TfxHeader>(0, "header");
    if (!(header.version >= 4.0f && header.version < 5.0f))
        throw InputError(strCat(name, ": not a TressFX 4 file (version field reads ",
                                header.version, ", expected 4.x)"));
    const std::uint64_t strands = header.numStrands, perStrand = header.verticesPerStrand;
    if (strands > 0 && perStrand < 2)
        throw InputError(strCat(name, ": ", perStrand,
                                " vertices per strand; a strand needs at least 2"));
    const std::uint64_t points = strands * perStrand; // both < 2^32: no overflow
    if (points > options.maxPoints)
        throw InputError(strCat(name, ": header declares ", points,
                                " vertices, more than the limit of ", options.maxPoints));
    if (header.offsetPositions < sizeof(TfxHeader) && points > 0)
        throw InputError(strCat(name, ": position array offset ", header.offsetPositions,
                                " lies inside the header"));

    // Every declared array must lie inside the file (checked before allocating).
    file.checkRange(header.offsetPositions, points, sizeof(Float4), "vertex positions");
    if (header.offsetStrandUV)
        file.checkRange(header.offsetStrandUV, strands, 2 * sizeof(float), "strand UVs");
    if (header.offsetVertexUV)
        file.checkRange(header.offsetVertexUV, points, 2 * sizeof(float), "vertex UVs");
    if (header.offsetStrandThickness)
        file.checkRange(header.offsetStrandThickness, strands, sizeof(float), "strand thickness");
    if (header.offsetVertexColor)
        file.checkRange(header.offsetVertexColor, points, sizeof(Float4), "vertex colours");

    LoadedGroom loaded;
    loaded.format = GroomFormat::Tfx;
    Groom& groom = loaded.groom;

    std::vector<Float4> raw;
    file.readArray(header.offsetPositions, points, raw, "vertex positions");
    groom.points.resize(points);
    for (std::uint64_t i = 0; i < points; ++i)
        groom.points[i] = Vec3f(raw[i].x, raw[i].y, raw[i].z);
    if (strands > 0) {
        groom.strandStart.resize(strands + 1);
        for (std::uint64_t s = 0; s <= strands; ++s)
            groom.strandStart[s] = static_cast<std::uint32_t>(s * perStrand);
    }
    if (header.offsetStrandThickness) {
        std::vector<float> perStrandThickness;
        file.readArray(header.offsetStrandThickness, strands, perStrandThickness,
                       "strand thickness");
        groom.thickness.resize(points);
        for (std::uint64_t i = 0; i < points; ++i)
            groom.thickness[i] = perStrandThickness[i / perStrand];
    }
    if (header.offsetVertexColor) {
        file.readArray(header.offsetVertexColor, points, raw, "vertex colours");
        groom.color.resize(points);
        for (std::uint64_t i = 0; i < points; ++i)
            groom.color[i] = Rgb(raw[i].x, raw[i].y, raw[i].z);
    }

    loaded.sanitized = sanitizeGroom(groom, name);
    return loaded;
}

} // namespace hairvox
