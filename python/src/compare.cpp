// hairvox.compare: how far one render is from another (film/image_compare.h)
// over the reference's hair pixels, as `hairvox compare` measures it.
#include "bindings.h"
#include "long_call.h"

#include <hairvox/core/error.h>
#include <hairvox/film/image_file.h>
#include <hairvox/pipeline/compare.h>

namespace hairvox::python {

namespace {

/// A Render's film (shared: the Render is alive for the call), or an EXR read.
struct FilmArg {
    const Film* film = nullptr;
    std::filesystem::path file;
    std::string name;

    static FilmArg from(py::handle value, const std::string& argument) {
        if (const Film* film = filmOf(value))
            return {film, {}, argument};
        if (isPathLike(value)) {
            const std::filesystem::path p = pathArg(value, argument);
            return {nullptr, p, p.string()};
        }
        throw InputError(
            strCat(argument, ": expected a hairvox.Render or an EXR path, got ", typeName(value)));
    }
};

} // namespace

void bindCompare(py::module_& m) {
    m.def(
        "compare",
        [](py::handle a, py::handle b, py::handle block, py::handle what, py::handle layers,
           py::handle mask) {
            const FilmArg estimate = FilmArg::from(a, "a"), reference = FilmArg::from(b, "b");
            CompareSelection selection;
            if (!what.is_none())
                selection.what = enumArg(what, "what", kComparedValueNames);
            if (!layers.is_none()) {
                if (py::isinstance<py::str>(layers))
                    throw InputError("layers: expected a list of RGB layer names, got a str");
                for (const py::handle l : layers)
                    selection.layers.push_back(strArg(l, "layers"));
            }
            if (!mask.is_none())
                selection.mask = strArg(mask, "mask");
            const int blockSize = block.is_none() ? 1 : int(intArg(block, "block", 1, 4096));
            const auto [error, noisy] = longCall(Progress{}, [&] {
                const auto load = [&](const FilmArg& f) {
                    const Film film = f.film ? Film() : filmFromExr(readExr(f.file));
                    return comparedImage(f.film ? *f.film : film, selection, f.name)
                        .boxFiltered(blockSize);
                };
                const ComparedImage e = load(estimate), r = load(reference);
                const std::optional<ImageError> result = compareImages(e, r);
                if (!result)
                    throw InputError(strCat(reference.name, ": no pixel with ", selection.mask,
                                            " > 0, or all of them black: nothing to compare"));
                return std::pair{*result, !r.halfA.empty()};
            });
            py::dict out;
            out["rel_l1"] = error.relL1;
            out["rel_rmse"] = error.relRmse;
            out["rel_bias"] = error.relBias;
            out["pixels"] = error.pixels;
            out["block"] = blockSize;
            out["noisy_reference"] = noisy;
            if (noisy) {
                out["noise_floor_l1"] = error.noiseFloorL1;
                out["rel_l1_noise_removed"] = error.relL1NoiseRemoved;
                out["rel_rmse_noise_removed"] = error.relRmseNoiseRemoved;
                out["resolved"] = error.resolved();
            }
            return out;
        },
        py::arg("a"), py::arg("b"), py::kw_only(), py::arg("block") = py::none(),
        py::arg("what") = py::none(), py::arg("layers") = py::none(), py::arg("mask") = py::none(),
        R"doc(How far render `a` is from reference `b` (each a hairvox.Render or an EXR
path), as `hairvox compare` measures it, over b's pixels where `mask`
(default "hair.A") > 0: relative L1, RMSE and bias of the hair's radiance
(what="hair", the default) or of the beauty (what="beauty"), or of the sum of
`layers`; over means of block × block pixels (block, [1, 4096]). Against a
path-traced reference, its noise floor and the errors with it removed
("resolved": above 1.5 × the floor).)doc");
}

} // namespace hairvox::python
