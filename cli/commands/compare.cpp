// hairvox compare ESTIMATE.exr REFERENCE.exr [--what hair|beauty] [--mask LAYER]
// [--block N] [--figure OUT.png]:
// how far one render is from another (film/image_compare.h) over the
// reference's masked pixels (by default the hair) — relative L1, RMSE and
// bias, and, against a path-traced reference, its noise floor and the errors
// with its noise removed. --figure draws estimate | reference | difference.
#include "../commands.h"

#include <hairvox/core/error.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/film/image_file.h>
#include <hairvox/pipeline/compare.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace hairvox::cli {

namespace {

struct CompareOptions {
    std::string estimate, reference;
    std::string what = "hair";
    std::vector<std::string> layers;
    std::string mask = "hair.A";
    int block = 1;
    std::string figure;
    float exposure = 0;
};

/// Blue (estimate darker) – white – red (brighter), saturating at |d| = 1.
std::array<std::uint8_t, 3> diverging(double d) {
    const double t = std::clamp(std::abs(d), 0.0, 1.0);
    const auto c = [](double v) {
        return static_cast<std::uint8_t>(std::lround(255.0 * v));
    };
    const std::uint8_t fade = c(1.0 - t);
    return d >= 0 ? std::array<std::uint8_t, 3>{255, fade, fade}
                  : std::array<std::uint8_t, 3>{fade, fade, 255};
}

/// The figure: the two beauties tone-mapped alike, then the signed difference
/// of the compared values (per block when --block > 1), full colour at ±50% of
/// the reference's mean over its masked pixels; 4 white pixels between panels.
void writeFigure(const CompareOptions& opt, const Film& estimateFilm, const Film& referenceFilm,
                 const ComparedImage& estimate, const ComparedImage& reference) {
    const int w = referenceFilm.width(), h = referenceFilm.height(), gap = 4;
    const int fw = 3 * w + 2 * gap;
    std::vector<std::uint8_t> rgb(std::size_t(fw) * std::size_t(h) * 3, 255);
    const auto put = [&](int panel, const std::vector<std::uint8_t>& pixels) {
        for (int y = 0; y < h; ++y)
            std::copy_n(pixels.begin() + std::ptrdiff_t(y) * w * 3, w * 3,
                        rgb.begin() + (std::ptrdiff_t(y) * fw + panel * (w + gap)) * 3);
    };
    put(0, previewPixels(estimateFilm, opt.exposure, ToneMap::Filmic));
    put(1, previewPixels(referenceFilm, opt.exposure, ToneMap::Filmic));
    double sum = 0, weight = 0;
    for (std::size_t p = 0; p < reference.value.size(); ++p)
        if (reference.mask[p] > 0) {
            sum += double(reference.value[p].average());
            weight += 1;
        }
    const double scale = weight > 0 && sum > 0 ? 0.5 * sum / weight : 1.0;
    std::vector<std::uint8_t> diff(std::size_t(w) * std::size_t(h) * 3, 255);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t b = std::size_t(y / opt.block) * std::size_t(reference.width) +
                                  std::size_t(x / opt.block);
            if (!(reference.mask[b] > 0))
                continue;
            const auto c =
                diverging(double((estimate.value[b] - reference.value[b]).average()) / scale);
            std::copy(c.begin(), c.end(), diff.begin() + (std::ptrdiff_t(y) * w + x) * 3);
        }
    put(2, diff);
    writePng(opt.figure, fw, h, rgb);
}

void runCompare(const CompareOptions& opt) {
    const Film estimateFilm = filmFromExr(readExr(opt.estimate)),
               referenceFilm = filmFromExr(readExr(opt.reference));
    const CompareSelection selection{*kComparedValueNames.parse(opt.what), opt.layers, opt.mask};
    const ComparedImage
        estimate = comparedImage(estimateFilm, selection, opt.estimate).boxFiltered(opt.block),
        reference = comparedImage(referenceFilm, selection, opt.reference).boxFiltered(opt.block);
    const std::optional<ImageError> e = compareImages(estimate, reference);
    if (!e)
        throw InputError(strCat(opt.reference, ": no pixel with ", opt.mask,
                                " > 0, or all of them black: nothing to compare"));
    std::string what = opt.what == "hair" ? "hair's radiance" : "beauty";
    if (!opt.layers.empty()) {
        what = "sum of the layers";
        for (const std::string& l : opt.layers)
            what += " '" + l + "'";
    }
    if (opt.block > 1)
        std::printf("compared:        the %s over %zu blocks of %dx%d pixels (%s > 0 in the "
                    "reference)\n",
                    what.c_str(), e->pixels, opt.block, opt.block, opt.mask.c_str());
    else
        std::printf("compared:        the %s over %zu pixels (%s > 0 in the reference)\n",
                    what.c_str(), e->pixels, opt.mask.c_str());
    std::printf("relative L1:     %.4f\n", e->relL1);
    std::printf("relative RMSE:   %.4f\n", e->relRmse);
    std::printf("relative bias:   %+.4f\n", e->relBias);
    if (!reference.halfA.empty()) {
        std::printf("reference noise: relative L1 floor %.4f\n", e->noiseFloorL1);
        std::printf("noise removed:   relative L1 %.4f, relative RMSE %.4f%s\n",
                    e->relL1NoiseRemoved, e->relRmseNoiseRemoved,
                    e->resolved() ? ""
                                  : " (not resolved: within 1.5x the reference's noise floor)");
    }
    if (!opt.figure.empty()) {
        writeFigure(opt, estimateFilm, referenceFilm, estimate, reference);
        std::printf("wrote %s\n", opt.figure.c_str());
    }
}

} // namespace

void addCompareCommand(CLI::App& app) {
    auto opt = std::make_shared<CompareOptions>();
    CLI::App* cmd = app.add_subcommand(
        "compare", "How far one EXR render is from another, with a path-traced reference's noise "
                   "removed");
    cmd->add_option("estimate", opt->estimate, "The render to judge (.exr)")->required();
    cmd->add_option("reference", opt->reference, "The reference render (.exr)")->required();
    cmd->add_option("--what", opt->what,
                    "hair: the hair's radiance (direct + multiple scattering); beauty: the image")
        ->capture_default_str()
        ->check(CLI::IsMember(kComparedValueNames.names()));
    cmd->add_option(
           "--layers", opt->layers,
           "Compare the sum of these RGB layers instead (e.g. direct_R,direct_TT,direct_TRT; "
           "no noise estimate)")
        ->delimiter(',');
    cmd->add_option("--mask", opt->mask, "Scalar channel selecting the compared pixels (> 0)")
        ->capture_default_str();
    cmd->add_option("--block", opt->block,
                    "Compare means over blocks of N x N pixels: aliasing and noise average out, "
                    "a bias does not")
        ->capture_default_str()
        ->check(CLI::Range(1, 4096));
    cmd->add_option("--figure", opt->figure,
                    "Write a PNG: estimate | reference (filmic) | signed difference of the "
                    "compared values (red: estimate brighter, blue: darker, full colour at ±50% "
                    "of the reference's mean)");
    cmd->add_option("--exposure", opt->exposure, "Stops applied to the figure's two renders")
        ->capture_default_str()
        ->check(CLI::Range(-20.0f, 20.0f));
    cmd->callback([opt] { runCompare(*opt); });
}

} // namespace hairvox::cli
