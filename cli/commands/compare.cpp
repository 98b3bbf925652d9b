// hairvox compare ESTIMATE.exr REFERENCE.exr [--mask LAYER]: how far one
// render is from another (film/image_compare.h) — relative L1 and RMSE of the
// beauty over the reference's masked pixels (by default the hair).
#include "../commands.h"

#include <hairvox/core/error.h>
#include <hairvox/film/image_compare.h>
#include <hairvox/film/image_file.h>

#include <cstdio>
#include <memory>
#include <string>

namespace hairvox::cli {

namespace {

struct CompareOptions {
    std::string estimate, reference;
    std::string mask = "hair.A";
};

void runCompare(const CompareOptions& opt) {
    const auto load = [&](const std::string& path) {
        try {
            return BeautyImage::fromExr(readExr(path), opt.mask);
        } catch (const InputError& e) {
            throw InputError(strCat(path, ": ", e.what()));
        }
    };
    const BeautyImage estimate = load(opt.estimate), reference = load(opt.reference);
    const std::optional<ImageError> e = compareImages(estimate, reference);
    if (!e)
        throw InputError(strCat(opt.reference, ": no pixel with ", opt.mask,
                                " > 0, or all of them black: nothing to compare"));
    std::printf("pixels compared: %zu (%s > 0 in the reference)\n", e->pixels, opt.mask.c_str());
    std::printf("relative L1:     %.6f\n", e->relL1);
    std::printf("relative RMSE:   %.6f\n", e->relRmse);
}

} // namespace

void addCompareCommand(CLI::App& app) {
    auto opt = std::make_shared<CompareOptions>();
    CLI::App* cmd = app.add_subcommand(
        "compare", "Relative L1 and RMSE of one EXR render's beauty against another's");
    cmd->add_option("estimate", opt->estimate, "The render to judge (.exr)")->required();
    cmd->add_option("reference", opt->reference, "The reference render (.exr)")->required();
    cmd->add_option("--mask", opt->mask, "Scalar channel selecting the compared pixels (> 0)")
        ->capture_default_str();
    cmd->callback([opt] { runCompare(*opt); });
}

} // namespace hairvox::cli
