// Image comparison (film/image_compare.h): relative errors over the masked
// (hair) pixels.
#include <hairvox/core/error.h>
#include <hairvox/film/image_compare.h>

#include <gtest/gtest.h>

namespace hairvox {
namespace {

ComparedImage constantImage(int width, int height, Rgb value, float mask) {
    ComparedImage image;
    image.width = width;
    image.height = height;
    image.value.assign(std::size_t(width * height), value);
    image.mask.assign(std::size_t(width * height), mask);
    return image;
}

TEST(ImageCompare, ZeroForIdenticalImages) {
    ComparedImage a = constantImage(7, 5, Rgb(0.2f, 0.5f, 0.9f), 1.0f);
    a.value[3] = Rgb(3.0f, 0.0f, 1.0f);
    a.mask[4] = 0.0f;
    const std::optional<ImageError> e = compareImages(a, a);
    ASSERT_TRUE(e);
    EXPECT_EQ(e->relL1, 0.0);
    EXPECT_EQ(e->relRmse, 0.0);
    EXPECT_EQ(e->pixels, 34u);
}

TEST(ImageCompare, RelativeErrorsOfAUniformScale) {
    const ComparedImage reference = constantImage(6, 4, Rgb(0.5f), 0.3f);
    const ComparedImage brighter = constantImage(6, 4, Rgb(0.55f), 0.3f);
    const std::optional<ImageError> e = compareImages(brighter, reference);
    ASSERT_TRUE(e);
    EXPECT_NEAR(e->relL1, 0.1, 1e-6);
    EXPECT_NEAR(e->relRmse, 0.1, 1e-6); // constant image: RMSE / mean = the relative step
}

TEST(ImageCompare, OnlyHairPixelsCount) {
    ComparedImage reference = constantImage(4, 4, Rgb(1.0f), 1.0f);
    ComparedImage estimate = reference;
    for (std::size_t p = 0; p < 8; ++p) {
        reference.mask[p] = 0.0f;
        estimate.value[p] = Rgb(100.0f); // background or head: not compared
    }
    const std::optional<ImageError> e = compareImages(estimate, reference);
    ASSERT_TRUE(e);
    EXPECT_EQ(e->relL1, 0.0);
    EXPECT_EQ(e->pixels, 8u);

    const ComparedImage noHair = constantImage(4, 4, Rgb(1.0f), 0.0f);
    EXPECT_FALSE(compareImages(estimate, noHair));
    EXPECT_THROW(compareImages(constantImage(4, 3, Rgb(1.0f), 1.0f), reference), InputError);
}

} // namespace
} // namespace hairvox
