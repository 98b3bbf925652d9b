// Renders through the shared disk cache (PipelineOptions::diskCache): a
// render that takes the fiber grid and the lights' preparation from entries
// another process stored is the same bytes as one that computes them; what
// is stored follows diskCacheStoresGrid and diskCacheSkipsLights; a damaged
// grid entry is splatted again and replaced.
#include "film/film_bytes.h"
#include "scene_test_util.h"
#include "test_util.h"

#include <hairvox/pipeline/pipeline.h>

#include <gtest/gtest.h>

#include <fstream>

namespace hairvox {
namespace {

namespace fs = std::filesystem;

Scene smallScene() {
    Scene scene = test::keyBackScene();
    scene.name = "cached";
    scene.groom.procedural.strands = 600;
    scene.camera.width = scene.camera.height = 64;
    scene.output.exr.clear();
    scene.output.png.clear();
    return scene;
}

PipelineOptions withCache(const test::TempDir& dir, std::shared_ptr<const DiskCache> cache) {
    PipelineOptions o;
    o.tableCacheDir = dir / "tables";
    o.diskCache = std::move(cache);
    return o;
}

std::size_t entries(const fs::path& dir) {
    std::error_code ec;
    std::size_t n = 0;
    for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); ++it)
        ++n;
    return n;
}

TEST(DiskCacheRender, CachedAssetsRenderTheSameBytes) {
    test::TempDir dir;
    const Scene scene = smallScene();
    ASSERT_EQ(scene.lights.size(), 2u);
    const auto alone = test::filmBytes(renderScene(scene, withCache(dir, nullptr), false).film);

    auto first = std::make_shared<const DiskCache>(dir / "cache");
    const SceneRender stored = renderScene(scene, withCache(dir, first), false);
    EXPECT_TRUE(test::filmBytes(stored.film) == alone);
    EXPECT_EQ(first->stats().stored, 3u) << "the grid and two lights";
    EXPECT_EQ(entries(dir / "cache" / "grid"), 1u);
    EXPECT_EQ(entries(dir / "cache" / "light"), 2u);

    auto second = std::make_shared<const DiskCache>(dir / "cache");
    const SceneRender loaded = renderScene(scene, withCache(dir, second), false);
    EXPECT_TRUE(test::filmBytes(loaded.film) == alone)
        << "a render from cached assets differs from one that computed them";
    EXPECT_EQ(second->stats().hits, 3u);
    EXPECT_EQ(second->stats().stored, 0u);
    EXPECT_EQ(loaded.activeVoxels, stored.activeVoxels);

    // A camera that moves keeps every entry; a light that moves misses its own.
    Scene moved = scene;
    moved.camera.position.x += 0.1f;
    moved.lights[1].direction = normalize(Vec3f(0.2f, 0.9f, -0.4f));
    auto third = std::make_shared<const DiskCache>(dir / "cache");
    const SceneRender relit = renderScene(moved, withCache(dir, third), false);
    EXPECT_TRUE(test::filmBytes(relit.film) ==
                test::filmBytes(renderScene(moved, withCache(dir, nullptr), false).film));
    EXPECT_EQ(third->stats().hits, 2u) << "the grid and the still light";
    EXPECT_EQ(third->stats().stored, 1u) << "the moved light";
}

TEST(DiskCacheRender, WhatIsStoredIsWhatFramesShare) {
    test::TempDir dir;
    const Scene scene = smallScene();
    auto cache = std::make_shared<const DiskCache>(dir / "cache");
    PipelineOptions o = withCache(dir, cache);
    o.diskCacheStoresGrid = false;
    o.diskCacheSkipsLights = {scene.lights[0].name};
    renderScene(scene, o, false);
    EXPECT_EQ(cache->stats().stored, 1u);
    EXPECT_EQ(entries(dir / "cache" / "grid"), 0u);
    EXPECT_EQ(entries(dir / "cache" / "light"), 1u);
}

TEST(DiskCacheRender, ADamagedGridEntryIsSplattedAgainAndReplaced) {
    test::TempDir dir;
    const Scene scene = smallScene();
    const auto alone = test::filmBytes(renderScene(scene, withCache(dir, nullptr), false).film);
    renderScene(scene, withCache(dir, std::make_shared<const DiskCache>(dir / "cache")), false);
    const fs::path entry = fs::directory_iterator(dir / "cache" / "grid")->path();
    std::string bytes = test::readBytes(entry);
    bytes[bytes.size() / 2] ^= 0x40;
    test::writeText(entry, bytes);

    auto cache = std::make_shared<const DiskCache>(dir / "cache");
    EXPECT_TRUE(test::filmBytes(renderScene(scene, withCache(dir, cache), false).film) == alone);
    EXPECT_EQ(cache->stats().corrupt, 1u);
    EXPECT_EQ(cache->stats().hits, 2u) << "the lights were intact";
    EXPECT_EQ(cache->stats().stored, 1u) << "the grid replaced";
    auto after = std::make_shared<const DiskCache>(dir / "cache");
    renderScene(scene, withCache(dir, after), false);
    EXPECT_EQ(after->stats().hits, 3u);
    EXPECT_EQ(after->stats().corrupt, 0u);
}

} // namespace
} // namespace hairvox
