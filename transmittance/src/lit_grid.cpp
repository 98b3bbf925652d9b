#include <hairvox/core/error.h>
#include <hairvox/core/math.h>
#include <hairvox/transmittance/lit_grid.h>

#include <stdexcept>
#include <vector>

namespace hairvox {

VoxelGlobalTerms evaluateAtActiveVoxels(const FiberGrid& grid, const LightGlobalTerm& term) {
    std::vector<GlobalTermQuery> queries;
    const auto xform = openvdb::math::Transform::createLinearTransform(grid.info.voxelSize);
    queries.reserve(grid.activeVoxelCount());
    grid.forEachVoxel([&](std::size_t i, const openvdb::Coord& c) {
        const openvdb::Vec3d p = xform->indexToWorld(c);
        const openvdb::Vec3s& o = grid.orientation[i];
        queries.push_back({Vec3f(float(p.x()), float(p.y()), float(p.z())),
                           normalizeOr(Vec3f(o.x(), o.y(), o.z()), Vec3f(0.0f, 1.0f, 0.0f))});
    });
    VoxelGlobalTerms values;
    values.terms.resize(queries.size());
    values.stats = term.evaluate(queries, values.terms);
    return values;
}

LitGrid evaluateOnFiberGrid(const FiberGrid& grid, const LightGlobalTerm& term) {
    return toLitGrid(grid, evaluateAtActiveVoxels(grid, term));
}

LitGrid toLitGrid(const FiberGrid& grid, const VoxelGlobalTerms& values) {
    std::vector<openvdb::Coord> coords;
    coords.reserve(grid.activeVoxelCount());
    grid.forEachVoxel([&](std::size_t, const openvdb::Coord& c) { coords.push_back(c); });
    const std::vector<GlobalTerm>& terms = values.terms;
    if (terms.size() != coords.size())
        throw std::invalid_argument(
            strCat("toLitGrid: ", terms.size(), " values for ", coords.size(), " active voxels"));
    const auto xform = openvdb::math::Transform::createLinearTransform(grid.info.voxelSize);
    LitGrid lit;
    lit.stats = values.stats;

    lit.n = openvdb::FloatGrid::create(0.0f);
    lit.V = openvdb::FloatGrid::create(1.0f); // outside the hair nothing blocks the light
    lit.T_s = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    lit.sigma2_f = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    auto n = lit.n->getAccessor();
    auto V = lit.V->getAccessor();
    auto T_s = lit.T_s->getAccessor();
    auto sigma2 = lit.sigma2_f->getAccessor();
    for (std::size_t i = 0; i < coords.size(); ++i) {
        const GlobalTerm& g = terms[i];
        n.setValue(coords[i], g.n);
        V.setValue(coords[i], g.V);
        T_s.setValue(coords[i], openvdb::Vec3s(g.T_s.r, g.T_s.g, g.T_s.b));
        sigma2.setValue(coords[i], openvdb::Vec3s(g.sigma2_f.r, g.sigma2_f.g, g.sigma2_f.b));
    }
    const auto name = [&](openvdb::GridBase& g, const char* gridName, const char* units,
                          const char* description) {
        g.setName(gridName);
        g.setTransform(xform->copy());
        g.setGridClass(openvdb::GRID_UNKNOWN);
        g.insertMeta("units", openvdb::StringMetadata(units));
        g.insertMeta("description", openvdb::StringMetadata(description));
    };
    name(*lit.n, "n", "fibers (dimensionless count)",
         "expected number of fibers crossed toward the light; background 0");
    name(*lit.V, "V", "dimensionless, [0, 1]",
         "direct visibility e^-n toward the light; background 1 (unoccluded)");
    name(*lit.T_s, "T_s", "dimensionless, [0, 1] per channel",
         "forward-scattering transmittance d_f*(P - V) per colour channel; background 0");
    name(*lit.sigma2_f, "sigma2_f", "rad^2",
         "accumulated forward-scattering longitudinal variance per colour channel; background 0");
    for (openvdb::GridBase* g : {static_cast<openvdb::GridBase*>(lit.T_s.get()),
                                 static_cast<openvdb::GridBase*>(lit.sigma2_f.get())}) {
        g->setVectorType(openvdb::VEC_INVARIANT);
        g->insertMeta("component_order", openvdb::StringMetadata("R,G,B"));
    }
    return lit;
}

openvdb::MetaMap litGridMetadata(const Light& light, GlobalTermMode mode, const FiberGridInfo& grid,
                                 const FiberParams& fiber,
                                 const DualScatteringParams& dualScattering) {
    const auto vec = [](const Vec3f& v) {
        return openvdb::Vec3SMetadata(openvdb::Vec3s(v.x, v.y, v.z));
    };
    const auto rgb = [](const Rgb& c) {
        return openvdb::Vec3SMetadata(openvdb::Vec3s(c.r, c.g, c.b));
    };
    openvdb::MetaMap m;
    m.insertMeta("light_type", openvdb::StringMetadata(kLightKindNames.name(light.kind)));
    if (light.kind == Light::Kind::Directional)
        m.insertMeta("light_direction", vec(light.direction));
    else
        m.insertMeta("light_position", vec(light.position));
    m.insertMeta("light_color", rgb(light.color));
    m.insertMeta("light_intensity", openvdb::FloatMetadata(light.intensity));
    m.insertMeta("mode", openvdb::StringMetadata(toString(mode)));
    m.insertMeta("voxel_size", openvdb::DoubleMetadata(grid.voxelSize));
    m.insertMeta("fiber_diameter", openvdb::FloatMetadata(grid.fiberScale.diameter));
    m.insertMeta("density_multiplier", openvdb::FloatMetadata(grid.fiberScale.densityMultiplier));
    m.insertMeta("eta", openvdb::FloatMetadata(fiber.eta));
    m.insertMeta("sigma_a", rgb(fiber.sigma_a));
    m.insertMeta("eccentricity", openvdb::FloatMetadata(fiber.eccentricity));
    m.insertMeta("alpha_R_deg", openvdb::FloatMetadata(degrees(fiber.alpha_R)));
    m.insertMeta("beta_R_deg", openvdb::FloatMetadata(degrees(fiber.beta_R)));
    m.insertMeta("caustic_width_deg", openvdb::FloatMetadata(degrees(fiber.causticWidth)));
    m.insertMeta("caustic_gain", openvdb::FloatMetadata(fiber.causticGain));
    m.insertMeta("d_f", openvdb::FloatMetadata(dualScattering.d_f));
    m.insertMeta("d_b", openvdb::FloatMetadata(dualScattering.d_b));
    m.insertMeta("source_file", openvdb::StringMetadata(grid.sourceFile));
    m.insertMeta("source_hash", openvdb::StringMetadata(grid.sourceHash));
    m.insertMeta("hairvox_version", openvdb::StringMetadata(grid.version));
    return m;
}

void writeLitGrid(const std::filesystem::path& path, const LitGrid& lit,
                  const openvdb::MetaMap& metadata) {
    openvdb::initialize();
    openvdb::GridPtrVec grids;
    for (const openvdb::GridBase::Ptr& g :
         {openvdb::GridBase::Ptr(lit.n), openvdb::GridBase::Ptr(lit.V),
          openvdb::GridBase::Ptr(lit.T_s), openvdb::GridBase::Ptr(lit.sigma2_f)}) {
        // Shallow copies (shared trees) carry the metadata; the caller's grids stay as they are.
        openvdb::GridBase::Ptr copy = g->copyGrid();
        for (auto it = metadata.beginMeta(); it != metadata.endMeta(); ++it)
            copy->insertMeta(it->first, *it->second);
        grids.push_back(copy);
    }
    writeVdbFile(path, grids);
}

} // namespace hairvox
