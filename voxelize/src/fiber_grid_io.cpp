// hairvox voxelize: the fiber grid as a .vdb file (fiber_grid.h).
//
// One file holds the grids "density", "orientation" and optionally
// "tensorDiag" and "tensorOffDiag", and "fiberType0", "fiberType1", ... for a
// groom of several fiber types; every grid carries FiberGridInfo as grid
// metadata, so a grid copied out of the file alone keeps its provenance and
// `vdb_print -l` or pyopenvdb show it. Counts are stored as int64 (the widest
// integer pyopenvdb reads). Each grid also says what it holds: string
// metadata `units` and `description`, for vector grids `component_order`;
// density is GRID_FOG_VOLUME (a density, background 0), the others
// GRID_UNKNOWN.
#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <openvdb/io/File.h>

#include <cmath>

namespace hairvox {

namespace {

constexpr const char* kMetaVoxelSize = "voxel_size";
constexpr const char* kMetaFiberDiameter = "fiber_diameter";
constexpr const char* kMetaDensityMultiplier = "density_multiplier";
constexpr const char* kMetaSourceFile = "source_file";
constexpr const char* kMetaSourceHash = "source_hash";
constexpr const char* kMetaStrands = "strands";
constexpr const char* kMetaSegments = "segments";
constexpr const char* kMetaTotalLength = "total_length";
constexpr const char* kMetaVersion = "hairvox_version";

void addMetadata(openvdb::GridBase& grid, const FiberGridInfo& info) {
    grid.insertMeta(kMetaVoxelSize, openvdb::DoubleMetadata(info.voxelSize));
    grid.insertMeta(kMetaFiberDiameter, openvdb::FloatMetadata(info.fiberScale.diameter));
    grid.insertMeta(kMetaDensityMultiplier,
                    openvdb::FloatMetadata(info.fiberScale.densityMultiplier));
    grid.insertMeta(kMetaSourceFile, openvdb::StringMetadata(info.sourceFile));
    grid.insertMeta(kMetaSourceHash, openvdb::StringMetadata(info.sourceHash));
    grid.insertMeta(kMetaStrands, openvdb::Int64Metadata(static_cast<std::int64_t>(info.strands)));
    grid.insertMeta(kMetaSegments,
                    openvdb::Int64Metadata(static_cast<std::int64_t>(info.segments)));
    grid.insertMeta(kMetaTotalLength, openvdb::DoubleMetadata(info.totalLength));
    grid.insertMeta(kMetaVersion, openvdb::StringMetadata(info.version));

    struct Meaning {
        const char* name;
        const char* units;
        const char* description;
        const char* componentOrder; ///< null for a scalar grid
    };
    static constexpr Meaning kMeanings[] = {
        {kDensityGridName, "1/length^2 (scene units)",
         "fiber length density lambda: modeled-strand length per unit volume (a real hair "
         "count is lambda * density_multiplier); background 0",
         nullptr},
        {kOrientationGridName, "dimensionless, |o| in [0, 1]",
         "length-weighted mean unit fiber tangent E[u], root to tip; |o| is the coherence",
         "x,y,z (world axes)"},
        {kTensorDiagGridName, "dimensionless",
         "diagonal of the orientation tensor E[u u^T] (symmetric, trace 1)", "xx,yy,zz"},
        {kTensorOffDiagGridName, "dimensionless",
         "off-diagonal of the orientation tensor E[u u^T] (symmetric: yx = xy, zx = xz, zy = yz)",
         "xy,xz,yz"},
    };
    if (grid.getName().starts_with("fiberType")) {
        grid.setGridClass(openvdb::GRID_UNKNOWN);
        grid.insertMeta("units", openvdb::StringMetadata("dimensionless, [0, 1]"));
        grid.insertMeta("description",
                        openvdb::StringMetadata(
                            "fraction of the voxel's (diameter-weighted) fiber length of this "
                            "fiber type; the types' fractions sum to 1; background 0"));
    }
    for (const Meaning& m : kMeanings) {
        if (grid.getName() != m.name)
            continue;
        grid.setGridClass(m.componentOrder ? openvdb::GRID_UNKNOWN : openvdb::GRID_FOG_VOLUME);
        grid.insertMeta("units", openvdb::StringMetadata(m.units));
        grid.insertMeta("description", openvdb::StringMetadata(m.description));
        if (m.componentOrder)
            grid.insertMeta("component_order", openvdb::StringMetadata(m.componentOrder));
    }
}

/// Reads one metadata value of the grid; InputError naming the file if absent or mistyped.
template <typename T>
T metaValue(const openvdb::GridBase& grid, const char* name, const std::string& file) {
    const auto meta = grid.getMetadata<openvdb::TypedMetadata<T>>(name);
    if (!meta)
        throw InputError(strCat(file, ": grid '", grid.getName(), "' has no ",
                                openvdb::TypedMetadata<T>::staticTypeName(), " metadata '", name,
                                "'; not a hairvox fiber grid"));
    return meta->value();
}

FiberGridInfo readMetadata(const openvdb::GridBase& grid, const std::string& file) {
    FiberGridInfo info;
    info.voxelSize = metaValue<double>(grid, kMetaVoxelSize, file);
    info.fiberScale.diameter = metaValue<float>(grid, kMetaFiberDiameter, file);
    // Grids written before the density multiplier had one name call it density_scale.
    info.fiberScale.densityMultiplier = metaValue<float>(
        grid,
        grid.getMetadata<openvdb::FloatMetadata>(kMetaDensityMultiplier) ? kMetaDensityMultiplier
                                                                         : "density_scale",
        file);
    info.sourceFile = metaValue<std::string>(grid, kMetaSourceFile, file);
    info.sourceHash = metaValue<std::string>(grid, kMetaSourceHash, file);
    const std::int64_t strands = metaValue<std::int64_t>(grid, kMetaStrands, file);
    const std::int64_t segments = metaValue<std::int64_t>(grid, kMetaSegments, file);
    info.totalLength = metaValue<double>(grid, kMetaTotalLength, file);
    info.version = metaValue<std::string>(grid, kMetaVersion, file);
    const auto bad = [&](const char* name, const auto& value, const char* range) {
        return InputError(strCat(file, ": metadata ", name, " = ", value, " should be ", range));
    };
    if (!(std::isfinite(info.voxelSize) && info.voxelSize > 0))
        throw bad(kMetaVoxelSize, info.voxelSize, "> 0");
    try {
        info.fiberScale.validate();
    } catch (const InputError& e) {
        throw InputError(strCat(file, ": metadata ", kMetaFiberDiameter, "/",
                                kMetaDensityMultiplier, ": ", e.what()));
    }
    if (strands < 0)
        throw bad(kMetaStrands, strands, ">= 0");
    if (segments < 0)
        throw bad(kMetaSegments, segments, ">= 0");
    if (!(std::isfinite(info.totalLength) && info.totalLength >= 0))
        throw bad(kMetaTotalLength, info.totalLength, ">= 0");
    info.strands = static_cast<std::uint64_t>(strands);
    info.segments = static_cast<std::uint64_t>(segments);
    return info;
}

/// The named grid as GridT, null if absent; InputError if it has another type
/// or a transform other than the vertex-centred one of voxel size h.
template <typename GridT>
typename GridT::Ptr readGrid(openvdb::io::File& in, const char* name, const std::string& file) {
    if (!in.hasGrid(name))
        return nullptr;
    auto grid = openvdb::gridPtrCast<GridT>(in.readGrid(name));
    if (!grid)
        throw InputError(strCat(file, ": grid '", name, "' should be of type ", GridT::gridType()));
    return grid;
}

template <typename GridT>
void checkTransform(const GridT& grid, double h, const std::string& file) {
    if (grid.transform() != *openvdb::math::Transform::createLinearTransform(h))
        throw InputError(strCat(file, ": grid '", grid.getName(),
                                "' should have a uniform linear transform of voxel size ", h,
                                " without offset (vertex-centred voxels at ijk·h); it has ",
                                grid.transform()));
}

template <typename GridT, typename Check>
void checkValues(const GridT& grid, const std::string& file, const char* requirement,
                 const Check& valid) {
    for (auto it = grid.cbeginValueOn(); it; ++it)
        if (!valid(*it))
            throw InputError(strCat(file, ": grid '", grid.getName(), "' value ", *it, " at ",
                                    it.getCoord(), " should be ", requirement));
}

bool finiteVec(const openvdb::Vec3s& v) {
    return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

} // namespace

std::string typeFractionGridName(std::size_t type) {
    return strCat("fiberType", type);
}

void writeFiberGrid(const std::filesystem::path& path, const FiberGrid& grid) {
    if (!grid.density || !grid.orientation)
        throw std::invalid_argument(
            "writeFiberGrid: the density and orientation grids are required");
    openvdb::initialize();
    // Shallow copies (shared trees) carry the metadata, leaving the caller's grids untouched.
    openvdb::GridPtrVec grids;
    std::vector<openvdb::GridBase::Ptr> all{
        grid.density, grid.orientation, grid.tensorDiag, grid.tensorOffDiag};
    all.insert(all.end(), grid.typeFraction.begin(), grid.typeFraction.end());
    for (const openvdb::GridBase::Ptr& g : all) {
        if (!g)
            continue;
        openvdb::GridBase::Ptr copy = g->copyGrid();
        addMetadata(*copy, grid.info);
        grids.push_back(copy);
    }
    writeVdbFile(path, grids);
}

void writeVdbFile(const std::filesystem::path& path, const openvdb::GridPtrVec& grids) {
    openvdb::initialize();
    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        try {
            openvdb::io::File out(tmp.string());
            out.write(grids);
            out.close();
        } catch (const openvdb::Exception& e) {
            throw InputError(strCat(path.string(), ": cannot write: ", e.what()));
        }
    });
}

FiberGrid readFiberGrid(const std::filesystem::path& path) {
    const std::string file = path.string();
    openvdb::initialize();
    FiberGrid grid;
    try {
        openvdb::io::File in(file);
        in.open(/*delayLoad=*/false);
        grid.density = readGrid<openvdb::FloatGrid>(in, kDensityGridName, file);
        grid.orientation = readGrid<openvdb::Vec3SGrid>(in, kOrientationGridName, file);
        grid.tensorDiag = readGrid<openvdb::Vec3SGrid>(in, kTensorDiagGridName, file);
        grid.tensorOffDiag = readGrid<openvdb::Vec3SGrid>(in, kTensorOffDiagGridName, file);
        for (std::size_t t = 0; t < kMaxFiberTypes; ++t) {
            const std::string name = typeFractionGridName(t);
            auto fraction = readGrid<openvdb::FloatGrid>(in, name.c_str(), file);
            if (!fraction)
                break;
            grid.typeFraction.push_back(std::move(fraction));
        }
        in.close();
        if (!grid.density || !grid.orientation)
            throw InputError(strCat(file, ": a fiber grid needs the grids '", kDensityGridName,
                                    "' and '", kOrientationGridName, "'"));
        if ((grid.tensorDiag == nullptr) != (grid.tensorOffDiag == nullptr))
            throw InputError(strCat(file, ": the grids '", kTensorDiagGridName, "' and '",
                                    kTensorOffDiagGridName,
                                    "' come together; only one is present"));
        grid.info = readMetadata(*grid.density, file);

        const double h = grid.info.voxelSize;
        checkTransform(*grid.density, h, file);
        checkTransform(*grid.orientation, h, file);
        checkValues(*grid.density, file, "finite and >= 0",
                    [](float v) { return std::isfinite(v) && v >= 0; });
        checkValues(*grid.orientation, file, "finite", finiteVec);
        if (grid.hasTensor()) {
            checkTransform(*grid.tensorDiag, h, file);
            checkTransform(*grid.tensorOffDiag, h, file);
            checkValues(*grid.tensorDiag, file, "finite", finiteVec);
            checkValues(*grid.tensorOffDiag, file, "finite", finiteVec);
        }
        if (grid.typeFraction.size() == 1)
            throw InputError(strCat(file, ": a single fiber-type fraction grid '",
                                    typeFractionGridName(0),
                                    "'; fractions come for 2 types or more"));
        for (const auto& fraction : grid.typeFraction) {
            checkTransform(*fraction, h, file);
            checkValues(*fraction, file, "in [0, 1]",
                        [](float v) { return v >= 0 && v <= 1; });
        }
    } catch (const openvdb::Exception& e) {
        throw InputError(strCat(file, ": cannot read as a hairvox fiber grid: ", e.what()));
    }
    return grid;
}

} // namespace hairvox
