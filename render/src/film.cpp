#include <hairvox/render/film.h>

namespace hairvox {

Film::Film(int width_, int height_, std::vector<std::string> lightNames_)
    : width(width_), height(height_), lightNames(std::move(lightNames_)) {
    const std::size_t pixels = pixelCount(), perLight = pixels * lightNames.size();
    for (std::vector<Rgb>* layer :
         {&directR, &directTT, &directTRT, &backDirect, &scatter, &head, &background})
        layer->assign(pixels, Rgb(0.0f));
    alpha.assign(pixels, 0.0f);
    hairAlpha.assign(pixels, 0.0f);
    depth.assign(pixels, 0.0f);
    V.assign(perLight, 0.0f);
    n.assign(perLight, 0.0f);
    T_s.assign(perLight, Rgb(0.0f));
    sigma_f.assign(perLight, Rgb(0.0f));
}

Rgb Film::beauty(std::size_t p) const {
    return directR[p] + directTT[p] + directTRT[p] + backDirect[p] + scatter[p] + head[p] +
           background[p];
}

} // namespace hairvox
