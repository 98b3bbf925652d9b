// Grid accuracy against exact ray casting on real grooms (issue 5): the
// convergence table, grid against approx on curly hair, the orientation
// representation and the self-shadow start offset, with the real light-blond
// dual-scattering tables. These are the measurements the grid mode's defaults
// were chosen by; each prints its table.
#include "test_util.h"

#include <hairvox/shading/dual_scattering_tables.h>
#include <hairvox/strands/groom_io.h>
#include <hairvox/strands/procedural.h>
#include <hairvox/transmittance/exact_global_term.h>
#include <hairvox/transmittance/grid_global_term.h>
#include <hairvox/transmittance/probe.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <map>

namespace hairvox {
namespace {

/// A groom, points on its fibers, lights, and exact references per light.
class Probe {
public:
    Probe(std::string name, Groom groom, double referenceVoxel)
        : name_(std::move(name))
        , groom_(std::move(groom)) {
        test::TempDir cache;
        crossings_ = CrossingTable::fromDualScattering(
            DualScatteringTables::loadOrBuild(FiberParams{}, cache.path()));
        settings_.fiberScale.diameter = 7e-5f;
        points_ = sampleFiberPoints(groom_, 300, 7);
        ExactOptions exact;
        exact.rays = 256;
        exact.radius = static_cast<float>(referenceVoxel); // the footprint the grid resolves
        const auto model = makeExactModel(groom_, {crossings_}, settings_, exact);
        for (const Vec3f& l : lights_)
            reference_.push_back(evaluateGlobalTerm(*model, Light::directional(l), points_));
    }

    struct Result {
        ProbeError error;
        double seconds = 0;
    };

    Result measure(const FiberGrid& grid, GlobalTermMode mode, const GridOptions& options) const {
        const auto model = mode == GlobalTermMode::Approx
                               ? makeApproxModel(grid, {crossings_}, settings_, options)
                               : makeGridModel(grid, {crossings_}, settings_, options);
        Result r;
        const auto start = std::chrono::steady_clock::now();
        for (std::size_t l = 0; l < lights_.size(); ++l) {
            const ProbeError e = compareGlobalTerms(
                evaluateGlobalTerm(*model, Light::directional(lights_[l]), points_), reference_[l]);
            r.error.maeV += e.maeV / double(lights_.size());
            r.error.maeT_s += e.maeT_s / double(lights_.size());
            r.error.biasN += e.biasN / double(lights_.size());
            r.error.meanNRef += e.meanNRef / double(lights_.size());
        }
        r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return r;
    }

    FiberGrid splat(double voxelSize, bool tensor = false) const {
        SplatOptions options;
        options.voxelSize = voxelSize;
        options.storeOrientationTensor = tensor;
        return splatStrands(groom_, options);
    }

    void print(const char* label, const Result& r) const {
        std::printf("  %-12s %-34s MAE(V) %.4f  MAE(T_s) %.4f  bias(n) %+.3f of %.2f  %.2f s\n",
                    name_.c_str(), label, r.error.maeV, r.error.maeT_s, r.error.biasN,
                    r.error.meanNRef, r.seconds);
    }

    const Groom& groom() const { return groom_; }

private:
    std::string name_;
    Groom groom_;
    CrossingTable crossings_ =
        CrossingTable::build([](float) { return Rgb(1.0f); }, [](float) { return Rgb(0.0f); });
    GlobalTermSettings settings_;
    std::vector<GlobalTermQuery> points_;
    std::vector<Vec3f> lights_{glm::normalize(Vec3f(0.3f, 1, 0.4f)),
                               glm::normalize(Vec3f(1, 0.2f, -0.3f)),
                               glm::normalize(Vec3f(-0.2f, 0.3f, -1))};
    std::vector<std::vector<GlobalTerm>> reference_;
};

Groom procedural(GroomStyle style, std::uint32_t strands) {
    ProceduralGroomParams p;
    p.style = style;
    p.strands = strands;
    return generateGroom(p);
}

TEST(GlobalTermAccuracySlow, ConvergesAsVoxelsShrink) {
    std::printf(
        "grid (default options) against exact, K = 256 rays of radius h0 = default voxel:\n");
    for (const auto& [name, groom] :
         {std::pair{std::string("wavy"), procedural(GroomStyle::Wavy, 6000)},
          std::pair{std::string("curly"), procedural(GroomStyle::Curly, 6000)},
          std::pair{std::string("ratboy"),
                    readGroom(test::dataDir() / "Ratboy_mohawk.tfx").groom}}) {
        const double h0 = defaultVoxelSize(groom);
        const Probe probe(name, groom, h0);
        std::vector<double> maeV, maeT_s;
        for (const double scale : {4.0, 2.0, 1.0}) {
            const Probe::Result r =
                probe.measure(probe.splat(h0 * scale), GlobalTermMode::Grid, {});
            char label[64];
            std::snprintf(label, sizeof(label), "h = %.2f mm (%.0f x default)", h0 * scale * 1e3,
                          scale);
            probe.print(label, r);
            maeV.push_back(r.error.maeV);
            maeT_s.push_back(r.error.maeT_s);
        }
        EXPECT_LT(maeV.back(), maeV.front()) << name;
        EXPECT_LT(maeT_s.back(), maeT_s.front()) << name;
        // At the default voxel size. These grooms are sparser than the
        // 50,000-strand head of the targets (0.03 and 0.02, met there:
        // bench/transmittance_bench ProbeAccuracy), and sparse hair is where
        // the exact mode's ray disk and the grid's trilinear footprint differ
        // most: measured 0.015–0.029 and 0.005–0.009.
        EXPECT_LT(maeV.back(), 0.04) << name;
        EXPECT_LT(maeT_s.back(), 0.02) << name;
    }
}

TEST(GlobalTermAccuracySlow, GridBeatsApproxOnCurlyHair) {
    const Groom groom = procedural(GroomStyle::Curly, 6000);
    const double h = defaultVoxelSize(groom);
    const Probe probe("curly", groom, h);
    const FiberGrid grid = probe.splat(h);
    const Probe::Result gridResult = probe.measure(grid, GlobalTermMode::Grid, {});
    const Probe::Result approxResult = probe.measure(grid, GlobalTermMode::Approx, {});
    probe.print("grid", gridResult);
    probe.print("approx", approxResult);
    EXPECT_LT(gridResult.error.maeT_s, approxResult.error.maeT_s);
}

TEST(GlobalTermAccuracySlow, OrientationRepresentationOnCurlyHair) {
    const Groom groom = procedural(GroomStyle::Curly, 6000);
    const double h = defaultVoxelSize(groom);
    const Probe probe("curly", groom, h);
    const FiberGrid grid = probe.splat(h, true);
    std::map<OrientationModel, Probe::Result> results;
    for (const OrientationModel model :
         {OrientationModel::MeanTangent, OrientationModel::CoherenceBlend,
          OrientationModel::Tensor}) {
        GridOptions options;
        options.orientation = model;
        results[model] = probe.measure(grid, GlobalTermMode::Grid, options);
        probe.print(toString(model), results[model]);
    }
    // The mean tangent alone is the worst: what voxelize stores beyond it pays.
    const double mean = results[OrientationModel::MeanTangent].error.maeV;
    EXPECT_LT(results[OrientationModel::CoherenceBlend].error.maeV, mean);
    EXPECT_LT(results[OrientationModel::Tensor].error.maeV, mean);
}

TEST(GlobalTermAccuracySlow, StartOffsetMeasuredAgainstExact) {
    const Groom groom = procedural(GroomStyle::Wavy, 6000);
    const double h = defaultVoxelSize(groom);
    const Probe probe("wavy", groom, h);
    const FiberGrid grid = probe.splat(h);
    std::map<float, Probe::Result> results;
    for (const float offset : {0.0f, 0.5f, 1.0f, 2.0f}) {
        GridOptions options;
        options.startOffset = offset;
        results[offset] = probe.measure(grid, GlobalTermMode::Grid, options);
        char label[64];
        std::snprintf(label, sizeof(label), "start offset %.1f voxels", double(offset));
        probe.print(label, results[offset]);
    }
    // Over random points inside the groom, 0 has the smallest bias: the own
    // fiber's optical depth is taken out (grid_global_term.h), and an offset
    // leaves out the fibers in front too. (The visible top of a dense layer
    // prefers 0.4, the default: pipeline/integrators_test.)
    const double bias0 = std::abs(results[0.0f].error.biasN);
    for (const float offset : {0.5f, 1.0f, 2.0f})
        EXPECT_LT(bias0, std::abs(results[offset].error.biasN)) << offset;
}

} // namespace
} // namespace hairvox
