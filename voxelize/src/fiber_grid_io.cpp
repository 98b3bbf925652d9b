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
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

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

using FloatLeaf = openvdb::FloatTree::LeafNodeType;
using Vec3SLeaf = openvdb::Vec3STree::LeafNodeType;

/// Bytes of one OpenVDB leaf: the node and its separately allocated values.
template <typename Leaf>
std::uint64_t leafBytes() {
    return sizeof(Leaf) + Leaf::SIZE * sizeof(typename Leaf::ValueType);
}

/// One quantity of the fiber grid as an OpenVDB grid: a leaf per block.
template <typename GridT, typename V>
typename GridT::Ptr vdbGrid(const FiberGrid& grid, const char* name, const std::vector<V>& values) {
    using Leaf = typename GridT::TreeType::LeafNodeType;
    using Value = typename GridT::ValueType;
    std::vector<std::unique_ptr<Leaf>> leaves(grid.blocks.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size(), 64), [&](const auto& r) {
        for (std::size_t b = r.begin(); b != r.end(); ++b) {
            const FiberBlock& block = grid.blocks[b];
            leaves[b] = std::make_unique<Leaf>(block.origin, openvdb::zeroVal<Value>(), false);
            std::size_t i = block.first;
            for (auto it = block.active.beginOn(); it; ++it)
                leaves[b]->setValueOn(it.pos(), Value(values[i++]));
        }
    });
    auto out = GridT::create(openvdb::zeroVal<Value>());
    out->setName(name);
    out->setTransform(openvdb::math::Transform::createLinearTransform(grid.info.voxelSize));
    for (auto& leaf : leaves)
        out->tree().addLeaf(leaf.release());
    addMetadata(*out, grid.info);
    return out;
}

/// The fiber grid of OpenVDB grids checked by readFiberGrid: the density's
/// leaves become the blocks, and every grid is read at their active voxels.
FiberGrid packFiberGrid(const FiberVdbGrids& vdb, FiberGridInfo info, const std::string& file) {
    std::vector<const FloatLeaf*> leaves;
    vdb.density->tree().getNodes(leaves);
    std::erase_if(leaves, [](const FloatLeaf* leaf) { return leaf->isEmpty(); });
    std::sort(leaves.begin(), leaves.end(),
              [](const FloatLeaf* a, const FloatLeaf* b) { return a->origin() < b->origin(); });
    FiberGrid grid;
    grid.info = std::move(info);
    std::uint64_t voxels = 0;
    grid.blocks.reserve(leaves.size());
    for (const FloatLeaf* leaf : leaves) {
        if (voxels + leaf->onVoxelCount() > std::numeric_limits<std::uint32_t>::max())
            throw InputError(strCat(file, ": grid '", kDensityGridName,
                                    "' has over 2^32 - 1 active voxels, the most a "
                                    "hairvox fiber grid holds"));
        grid.blocks.push_back({leaf->origin(), std::uint32_t(voxels), leaf->getValueMask()});
        voxels += leaf->onVoxelCount();
    }
    grid.density.resize(voxels);
    grid.orientation.resize(voxels);
    grid.tensorStored = vdb.tensorDiag != nullptr;
    if (grid.tensorStored) {
        grid.tensorDiag.resize(voxels);
        grid.tensorOffDiag.resize(voxels);
    }
    grid.typeFraction.assign(vdb.typeFraction.size(), std::vector<float>(voxels));
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size(), 64), [&](const auto& r) {
        auto orientation = vdb.orientation->getConstAccessor();
        std::optional<openvdb::Vec3SGrid::ConstAccessor> diag, offDiag;
        if (grid.tensorStored) {
            diag.emplace(vdb.tensorDiag->getConstAccessor());
            offDiag.emplace(vdb.tensorOffDiag->getConstAccessor());
        }
        std::vector<openvdb::FloatGrid::ConstAccessor> fractions;
        for (const auto& fraction : vdb.typeFraction)
            fractions.push_back(fraction->getConstAccessor());
        for (std::size_t b = r.begin(); b != r.end(); ++b)
            FiberGrid::forEachVoxelOf(grid.blocks[b], [&](std::size_t i, const openvdb::Coord& c) {
                grid.density[i] = leaves[b]->getValue(c);
                grid.orientation[i] = orientation.getValue(c);
                if (grid.tensorStored) {
                    grid.tensorDiag[i] = diag->getValue(c);
                    grid.tensorOffDiag[i] = offDiag->getValue(c);
                }
                for (std::size_t t = 0; t < fractions.size(); ++t)
                    grid.typeFraction[t][i] = fractions[t].getValue(c);
            });
    });
    return grid;
}

} // namespace

std::string typeFractionGridName(std::size_t type) {
    return strCat("fiberType", type);
}

openvdb::GridPtrVec FiberVdbGrids::all() const {
    openvdb::GridPtrVec grids{density, orientation};
    if (tensorDiag)
        grids.insert(grids.end(), {tensorDiag, tensorOffDiag});
    grids.insert(grids.end(), typeFraction.begin(), typeFraction.end());
    return grids;
}

FiberVdbGrids toVdbGrids(const FiberGrid& grid) {
    openvdb::initialize();
    FiberVdbGrids vdb;
    vdb.density = vdbGrid<openvdb::FloatGrid>(grid, kDensityGridName, grid.density);
    vdb.orientation = vdbGrid<openvdb::Vec3SGrid>(grid, kOrientationGridName, grid.orientation);
    if (grid.hasTensor()) {
        vdb.tensorDiag = vdbGrid<openvdb::Vec3SGrid>(grid, kTensorDiagGridName, grid.tensorDiag);
        vdb.tensorOffDiag =
            vdbGrid<openvdb::Vec3SGrid>(grid, kTensorOffDiagGridName, grid.tensorOffDiag);
    }
    for (std::size_t t = 0; t < grid.typeFraction.size(); ++t)
        vdb.typeFraction.push_back(vdbGrid<openvdb::FloatGrid>(
            grid, typeFractionGridName(t).c_str(), grid.typeFraction[t]));
    return vdb;
}

std::uint64_t vdbBlockBytes(bool tensor, std::size_t typeFractions) {
    return (1 + typeFractions) * leafBytes<FloatLeaf>() + (tensor ? 3 : 1) * leafBytes<Vec3SLeaf>();
}

std::uint64_t vdbMemoryBytes(const FiberGrid& grid) {
    return grid.blocks.size() * vdbBlockBytes(grid.hasTensor(), grid.typeFraction.size());
}

void writeFiberGrid(const std::filesystem::path& path, const FiberGrid& grid) {
    writeVdbFile(path, toVdbGrids(grid).all());
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
    FiberVdbGrids vdb;
    FiberGridInfo info;
    try {
        openvdb::io::File in(file);
        in.open(/*delayLoad=*/false);
        vdb.density = readGrid<openvdb::FloatGrid>(in, kDensityGridName, file);
        vdb.orientation = readGrid<openvdb::Vec3SGrid>(in, kOrientationGridName, file);
        vdb.tensorDiag = readGrid<openvdb::Vec3SGrid>(in, kTensorDiagGridName, file);
        vdb.tensorOffDiag = readGrid<openvdb::Vec3SGrid>(in, kTensorOffDiagGridName, file);
        for (std::size_t t = 0; t < kMaxFiberTypes; ++t) {
            const std::string name = typeFractionGridName(t);
            auto fraction = readGrid<openvdb::FloatGrid>(in, name.c_str(), file);
            if (!fraction)
                break;
            vdb.typeFraction.push_back(std::move(fraction));
        }
        in.close();
        if (!vdb.density || !vdb.orientation)
            throw InputError(strCat(file, ": a fiber grid needs the grids '", kDensityGridName,
                                    "' and '", kOrientationGridName, "'"));
        if ((vdb.tensorDiag == nullptr) != (vdb.tensorOffDiag == nullptr))
            throw InputError(strCat(file, ": the grids '", kTensorDiagGridName, "' and '",
                                    kTensorOffDiagGridName,
                                    "' come together; only one is present"));
        info = readMetadata(*vdb.density, file);

        const double h = info.voxelSize;
        checkTransform(*vdb.density, h, file);
        checkTransform(*vdb.orientation, h, file);
        checkValues(*vdb.density, file, "finite and >= 0",
                    [](float v) { return std::isfinite(v) && v >= 0; });
        checkValues(*vdb.orientation, file, "finite", finiteVec);
        if (vdb.density->tree().activeTileCount() > 0)
            throw InputError(strCat(file, ": grid '", kDensityGridName, "' has ",
                                    vdb.density->tree().activeTileCount(),
                                    " active tiles; a fiber grid's active values are leaf "
                                    "voxels (voxelize the tiles first)"));
        if (vdb.tensorDiag) {
            checkTransform(*vdb.tensorDiag, h, file);
            checkTransform(*vdb.tensorOffDiag, h, file);
            checkValues(*vdb.tensorDiag, file, "finite", finiteVec);
            checkValues(*vdb.tensorOffDiag, file, "finite", finiteVec);
        }
        if (vdb.typeFraction.size() == 1)
            throw InputError(strCat(file, ": a single fiber-type fraction grid '",
                                    typeFractionGridName(0),
                                    "'; fractions come for 2 types or more"));
        for (const auto& fraction : vdb.typeFraction) {
            checkTransform(*fraction, h, file);
            checkValues(*fraction, file, "in [0, 1]",
                        [](float v) { return v >= 0 && v <= 1; });
        }
    } catch (const openvdb::Exception& e) {
        throw InputError(strCat(file, ": cannot read as a hairvox fiber grid: ", e.what()));
    }
    return packFiberGrid(vdb, std::move(info), file);
}

} // namespace hairvox
