// hairvox compare ESTIMATE.exr REFERENCE.exr [--what hair|beauty] [--mask LAYER]
// [--block N]:
// how far one render is from another (film/image_compare.h) over the
// reference's masked pixels (by default the hair) — relative L1, RMSE and
// bias, and, against a path-traced reference, its noise floor and the errors
// with its noise removed.
#include "../commands.h"

#include <hairvox/core/error.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/film/image_file.h>
#include <hairvox/pipeline/pipeline.h>

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
};

void runCompare(const CompareOptions& opt) {
    const auto load = [&](const std::string& path) {
        const Film film = filmFromExr(readExr(path));
        try {
            if (!opt.layers.empty())
                return ComparedImage::fromFilm(film, opt.layers, opt.mask);
            if (opt.what == "hair") {
                ComparedImage image = hairRadianceOf(film);
                image.mask = film.layer(opt.mask).data;
                return image;
            }
            return ComparedImage::beautyOf(film, opt.mask);
        } catch (const std::out_of_range& e) {
            throw InputError(strCat(path, ": ", e.what()));
        }
    };
    const ComparedImage estimate = load(opt.estimate).boxFiltered(opt.block),
                        reference = load(opt.reference).boxFiltered(opt.block);
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
        std::printf("noise removed:   relative L1 %.4f, relative RMSE %.4f%s\n", e->relL1NoiseRemoved,
                    e->relRmseNoiseRemoved,
                    e->resolved() ? "" : " (not resolved: within 1.5x the reference's noise floor)");
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
        ->check(CLI::IsMember({"hair", "beauty"}));
    cmd->add_option("--layers", opt->layers,
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
    cmd->callback([opt] { runCompare(*opt); });
}

} // namespace hairvox::cli
