#include <hairvox/transmittance/lit_grid.h>

#include <vector>

namespace hairvox {

LitGrid evaluateOnFiberGrid(const FiberGrid& grid, const LightGlobalTerm& term) {
    std::vector<openvdb::Coord> coords;
    std::vector<GlobalTermQuery> queries;
    const openvdb::math::Transform& xform = grid.density->transform();
    auto orientation = grid.orientation->getConstAccessor();
    for (auto it = grid.density->cbeginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        const openvdb::Vec3d p = xform.indexToWorld(c);
        const openvdb::Vec3s o = orientation.getValue(c);
        coords.push_back(c);
        queries.push_back({Vec3f(float(p.x()), float(p.y()), float(p.z())),
                           normalizeOr(Vec3f(o.x(), o.y(), o.z()), Vec3f(0.0f, 1.0f, 0.0f))});
    }
    std::vector<GlobalTerm> terms(queries.size());
    LitGrid lit;
    lit.stats = term.evaluate(queries, terms);

    lit.n = openvdb::FloatGrid::create(0.0f);
    lit.V = openvdb::FloatGrid::create(0.0f);
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
    const auto name = [&](openvdb::GridBase& g, const char* gridName) {
        g.setName(gridName);
        g.setTransform(xform.copy());
        g.setGridClass(openvdb::GRID_FOG_VOLUME);
    };
    name(*lit.n, "n");
    name(*lit.V, "V");
    name(*lit.T_s, "T_s");
    name(*lit.sigma2_f, "sigma2_f");
    return lit;
}

void writeLitGrid(const std::filesystem::path& path, const LitGrid& lit,
                  const std::map<std::string, std::string>& metadata) {
    openvdb::initialize();
    openvdb::GridPtrVec grids{lit.n, lit.V, lit.T_s, lit.sigma2_f};
    for (const auto& g : grids)
        for (const auto& [key, value] : metadata)
            g->insertMeta(key, openvdb::StringMetadata(value));
    writeVdbFile(path, grids);
}

} // namespace hairvox
