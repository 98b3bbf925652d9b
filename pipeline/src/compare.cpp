#include <hairvox/core/error.h>
#include <hairvox/pipeline/compare.h>
#include <hairvox/pipeline/pipeline.h>

#include <stdexcept>

namespace hairvox {

ComparedImage comparedImage(const Film& film, const CompareSelection& selection,
                            const std::string& source) {
    try {
        if (!selection.layers.empty())
            return ComparedImage::fromFilm(film, selection.layers, selection.mask);
        if (selection.what == ComparedValue::Hair) {
            ComparedImage image = hairRadianceOf(film);
            image.mask = film.layer(selection.mask).dense();
            return image;
        }
        return ComparedImage::beautyOf(film, selection.mask);
    } catch (const std::out_of_range& e) {
        throw InputError(strCat(source, ": ", e.what(),
                                " (a render with output.layers keeps only some layers: "
                                "compare what both have with --what beauty --mask A, or "
                                "--layers)"));
    }
}

} // namespace hairvox
