// AMD TressFX .tfx (layouts in data/README.md), versions 3 and 4:
//  - version 4 (TressFXFileFormat.h of TressFX 4): a 160-byte header of a
//    float32 version, the strand and per-strand vertex counts and five byte
//    offsets (0 = absent), then the arrays: positions float4[strands·vertices]
//    (w = inverse mass, ignored), strand UVs float2[strands], vertex UVs
//    float2[strands·vertices], strand thickness float[strands], vertex colours
//    float4[strands·vertices];
//  - version 3 (TressFXFileFormat.h of TressFX 3): a 296-byte header of the
//    version, strand and per-strand vertex counts, follow-hair ratio, a flag,
//    31 reserved words, six byte offsets (vertices, strand thickness, strand
//    UVs, vertex colours, guide-strand flags, vertex UVs) and 32 reserved
//    words; positions float3[strands·vertices]. AMD's viewer samples (the
//    bear, the ponytail) carry zero offsets with the positions right after the
//    header: a zero vertex offset means that.
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
struct Tfx3Header {
    float version;
    std::uint32_t numStrands; ///< numGuideHairStrands: every strand in the file
    std::uint32_t verticesPerStrand;
    std::uint32_t numFollowHairsPerGuideHair;
    std::uint32_t bothEndsImmovable;
    std::uint32_t reserved1[31];
    std::uint32_t offsetPositions;
    std::uint32_t offsetStrandThickness;
    std::uint32_t offsetStrandUV;
    std::uint32_t offsetVertexColor;
    std::uint32_t offsetGuideStrand;
    std::uint32_t offsetVertexUV;
    std::uint32_t reserved2[32];
};
#pragma pack(pop)
static_assert(sizeof(TfxHeader) == 160);
static_assert(sizeof(Tfx3Header) == 296);

struct Float3 {
    float x, y, z;
};
struct Float4 {
    float x, y, z, w;
};

/// What both versions declare: counts and where the arrays the renderer reads are.
struct TfxArrays {
    std::uint64_t strands, perStrand, headerSize;
    std::uint32_t offsetPositions, offsetStrandThickness, offsetVertexColor;
    bool float4Positions;
};

TfxArrays readHeader(const detail::FileBytes& file, const std::string& name) {
    const auto version = file.read<float>(0, "version");
    if (version >= 4.0f && version < 5.0f) {
        if (file.size() < sizeof(TfxHeader))
            throw InputError(strCat(name, ": truncated header: ", file.size(),
                                    " bytes, a TressFX 4 header is 160"));
        const auto h = file.read<TfxHeader>(0, "header");
        // Every declared array must lie inside the file (checked before allocating).
        const std::uint64_t points = std::uint64_t(h.numStrands) * h.verticesPerStrand;
        if (h.offsetStrandUV)
            file.checkRange(h.offsetStrandUV, h.numStrands, 2 * sizeof(float), "strand UVs");
        if (h.offsetVertexUV)
            file.checkRange(h.offsetVertexUV, points, 2 * sizeof(float), "vertex UVs");
        return {h.numStrands,          h.verticesPerStrand,       sizeof(TfxHeader),
                h.offsetPositions,     h.offsetStrandThickness,   h.offsetVertexColor, true};
    }
    if (version >= 3.0f && version < 4.0f) {
        if (file.size() < sizeof(Tfx3Header))
            throw InputError(strCat(name, ": truncated header: ", file.size(),
                                    " bytes, a TressFX 3 header is 296"));
        const auto h = file.read<Tfx3Header>(0, "header");
        return {h.numStrands,
                h.verticesPerStrand,
                sizeof(Tfx3Header),
                h.offsetPositions ? h.offsetPositions : std::uint32_t(sizeof(Tfx3Header)),
                h.offsetStrandThickness,
                h.offsetVertexColor,
                false};
    }
    throw InputError(strCat(name, ": not a TressFX 3 or 4 file (version field reads ", version,
                            ", expected 3.x or 4.x)"));
}

} // namespace

LoadedGroom readTfxFile(const std::filesystem::path& path, const GroomReadOptions& options) {
    // Offsets are 32-bit, so a valid file is under 4 GiB plus its last array.
    const std::vector<unsigned char> bytes =
        detail::readFileBytes(path, sizeof(Tfx3Header) + 40 * options.maxPoints);
    return parseTfxBytes(bytes, path.string(), options);
}

LoadedGroom parseTfxBytes(std::span<const unsigned char> bytes, const std::string& name,
                          const GroomReadOptions& options) {
    const detail::FileBytes file(bytes, name);
    if (file.size() < sizeof(float))
        throw InputError(strCat(name, ": truncated header: ", file.size(),
                                " bytes, a TressFX header is 160 (version 4) or 296 (version 3)"));
    const TfxArrays header = readHeader(file, name);
    const std::uint64_t strands = header.strands, perStrand = header.perStrand;
    if (strands > 0 && perStrand < 2)
        throw InputError(strCat(name, ": ", perStrand,
                                " vertices per strand; a strand needs at least 2"));
    const std::uint64_t points = strands * perStrand; // both < 2^32: no overflow
    if (points > options.maxPoints)
        throw InputError(strCat(name, ": header declares ", points,
                                " vertices, more than the limit of ", options.maxPoints));
    if (header.offsetPositions < header.headerSize && points > 0)
        throw InputError(strCat(name, ": position array offset ", header.offsetPositions,
                                " lies inside the header"));

    // Every declared array must lie inside the file (checked before allocating).
    file.checkRange(header.offsetPositions, points,
                    header.float4Positions ? sizeof(Float4) : sizeof(Float3), "vertex positions");
    if (header.offsetStrandThickness)
        file.checkRange(header.offsetStrandThickness, strands, sizeof(float), "strand thickness");
    if (header.offsetVertexColor)
        file.checkRange(header.offsetVertexColor, points, sizeof(Float4), "vertex colours");

    LoadedGroom loaded;
    loaded.format = GroomFormat::Tfx;
    Groom& groom = loaded.groom;

    std::vector<Float4> raw;
    groom.points.resize(points);
    if (header.float4Positions) {
        file.readArray(header.offsetPositions, points, raw, "vertex positions");
        for (std::uint64_t i = 0; i < points; ++i)
            groom.points[i] = Vec3f(raw[i].x, raw[i].y, raw[i].z);
    } else {
        std::vector<Float3> raw3;
        file.readArray(header.offsetPositions, points, raw3, "vertex positions");
        for (std::uint64_t i = 0; i < points; ++i)
            groom.points[i] = Vec3f(raw3[i].x, raw3[i].y, raw3[i].z);
    }
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
