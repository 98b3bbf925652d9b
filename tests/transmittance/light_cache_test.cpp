// The grid modes' per-light cache through the shared disk cache
// (GlobalTermSettings::diskCache): a light prepared by another process is
// read back and evaluates to the same bits; which lights are stored follows
// diskCacheStores; an entry whose bytes are intact but not a cache of this
// build (a wrong index, a NaN) is refused, computed again and replaced.
#include "slab.h"
#include "test_util.h"

#include <hairvox/core/disk_cache.h>
#include <hairvox/core/hash.h>
#include <hairvox/transmittance/grid_global_term.h>
#include <hairvox/voxelize/fiber_grid.h>

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <vector>

namespace hairvox {
namespace {

namespace fs = std::filesystem;

struct SlabScene {
    FiberGrid grid;
    std::vector<GlobalTermQuery> queries;

    SlabScene() {
        const test::Slab slab;
        SplatOptions o;
        o.voxelSize = 0.002;
        grid = splatStrands(slab.groom(), o);
        Pcg32 rng(5);
        for (int i = 0; i < 400; ++i)
            queries.push_back({Vec3f(rng.uniform(-0.04f, 0.04f), rng.uniform(0.0f, 0.01f),
                                     rng.uniform(-0.08f, 0.08f)),
                               Vec3f(1, 0, 0)});
    }

    /// The global term toward `light` of a model using `cache` under key 7.
    std::vector<GlobalTerm> evaluate(const Light& light, const DiskCache* cache,
                                     std::function<bool(const Light&)> stores = {}) const {
        GlobalTermSettings settings = test::slabSettings();
        settings.diskCache = cache;
        settings.diskCacheKey = 7;
        settings.diskCacheStores = std::move(stores);
        const auto model =
            makeGridModel(grid, {test::constantTable(0.6f, 0.02f)}, settings, GridOptions{});
        std::vector<GlobalTerm> out(queries.size());
        model->forLight(light)->evaluate(queries, out);
        return out;
    }
};

std::vector<unsigned char> bits(const std::vector<GlobalTerm>& terms) {
    std::vector<unsigned char> b(terms.size() * sizeof(GlobalTerm));
    std::memcpy(b.data(), terms.data(), b.size());
    return b;
}

/// The entries of kind "light" in the cache directory.
std::vector<fs::path> lightEntries(const fs::path& dir) {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir / "light", ec))
        files.push_back(e.path());
    return files;
}

TEST(LightDiskCache, APreparedLightIsReadBackToTheSameBits) {
    const SlabScene s;
    test::TempDir dir;
    const Light key = Light::directional(normalize(Vec3f(0.2f, 1.0f, 0.3f)));
    const Light point = Light::point(Vec3f(0.05f, 0.5f, 0.02f));
    for (const Light& light : {key, point}) {
        const auto alone = s.evaluate(light, nullptr);
        const DiskCache first(dir / "cache");
        EXPECT_TRUE(bits(s.evaluate(light, &first)) == bits(alone));
        EXPECT_EQ(first.stats().stored, 1u);
        EXPECT_EQ(first.stats().hits, 0u);
        const DiskCache second(dir / "cache"); // another process
        EXPECT_TRUE(bits(s.evaluate(light, &second)) == bits(alone))
            << "a light read from the cache evaluates differently";
        EXPECT_EQ(second.stats().hits, 1u);
        EXPECT_EQ(second.stats().stored, 0u);
    }
    EXPECT_EQ(lightEntries(dir / "cache").size(), 2u);
    // Another light is another entry; so is another model key.
    const DiskCache third(dir / "cache");
    s.evaluate(Light::directional(Vec3f(0, 1, 0)), &third);
    EXPECT_EQ(third.stats().hits, 0u);
    EXPECT_EQ(lightEntries(dir / "cache").size(), 3u);
}

TEST(LightDiskCache, OnlyTheLightsToStoreAreStored) {
    const SlabScene s;
    test::TempDir dir;
    const DiskCache cache(dir / "cache");
    Light moving = Light::directional(Vec3f(0, 1, 0));
    moving.name = "rim";
    s.evaluate(moving, &cache, [](const Light& l) { return l.name != "rim"; });
    EXPECT_EQ(cache.stats().stored, 0u);
    EXPECT_TRUE(lightEntries(dir / "cache").empty());
}

TEST(LightDiskCache, AnIntactEntryThatIsNoCacheIsComputedAgainAndReplaced) {
    const SlabScene s;
    test::TempDir dir;
    const Light light = Light::directional(normalize(Vec3f(-0.3f, 1.0f, 0.1f)));
    const auto alone = s.evaluate(light, nullptr);
    // Rewrites the one entry's payload, its checksum made right again:
    // intact for the disk cache, wrong for the light-space cache.
    const auto rewrite = [&](std::size_t at, const void* bytes, std::size_t n) {
        {
            const DiskCache cache(dir / "cache");
            s.evaluate(light, &cache);
        }
        const std::vector<fs::path> entries = lightEntries(dir / "cache");
        ASSERT_EQ(entries.size(), 1u);
        std::string file = test::readBytes(entries[0]);
        constexpr std::size_t kHeader = DiskCache::kOverheadBytes - 8;
        ASSERT_LT(kHeader + at + n, file.size() - 8);
        std::memcpy(file.data() + kHeader + at, bytes, n);
        const std::uint64_t sum = Hasher().bytes(file.data(), file.size() - 8).digest();
        std::memcpy(file.data() + file.size() - 8, &sum, 8);
        test::writeText(entries[0], file);
        const DiskCache cache(dir / "cache");
        EXPECT_TRUE(bits(s.evaluate(light, &cache)) == bits(alone));
        EXPECT_EQ(cache.stats().hits, 1u) << "the entry was read (intact)";
        EXPECT_EQ(cache.stats().corrupt, 1u) << "and refused";
        EXPECT_EQ(cache.stats().stored, 1u) << "and replaced";
        const DiskCache after(dir / "cache");
        EXPECT_TRUE(bits(s.evaluate(light, &after)) == bits(alone));
        EXPECT_EQ(after.stats().corrupt, 0u);
    };
    // The magic, and the previous format's (whose runs stored their first
    // sample: read as this format's, every lookup would be off by a step);
    // the first entry of the line index (a lookup would read past the runs);
    // the lattice spacing.
    rewrite(0, "XXXXXXXX", 8);
    rewrite(0, "HVXLSC01", 8);
    const std::uint32_t farRun = 1u << 30;
    rewrite(8 + 1 + 4 * 12 + 3 * 4 + 4 * 4 + 8 + 8, &farRun, 4);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    rewrite(8 + 1 + 4 * 12, &nan, 4);
}

} // namespace
} // namespace hairvox
