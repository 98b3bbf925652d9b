// hairvox render: the film — the image and its AOV layers, as composited.
//
// Layers mirror Figure 4 of the RenderMan dual-scattering report (Sadeghi &
// Tamstorf): the hair's radiance split into direct single scattering per lobe
// (R, TT, TRT), f_back^direct (local multiple scattering) and F_scatter
// (global multiple scattering), plus the head and the background. Every
// radiance layer is premultiplied by coverage, so that
//     beauty = directR + directTT + directTRT + backDirect + scatter + head + background
// exactly (beauty() adds them; the EXR stores the sum). The per-light layers
// are the global term toward each light (V, n, T_s, σ_f = √σ_f²), averaged over
// the visible hair in the pixel with the same weights as the radiance (not
// premultiplied; 0 where there is no hair).
//
// Planar storage, row-major, row 0 at the top (camera.h). Memory: 96 bytes per
// pixel plus 32 per light.
#pragma once

#include <hairvox/core/rgb.h>

#include <cstddef>
#include <string>
#include <vector>

namespace hairvox {

struct Film {
    Film() = default;
    Film(int width, int height, std::vector<std::string> lightNames);

    int width = 0, height = 0;
    std::vector<std::string> lightNames; ///< per-light layer prefixes, in scene order

    std::vector<Rgb> directR, directTT, directTRT; ///< single scattering per lobe
    std::vector<Rgb> backDirect;                  ///< V·d_b·f_back^direct (local multiple scattering)
    std::vector<Rgb> scatter;                     ///< F_scatter (global multiple scattering)
    std::vector<Rgb> head;                        ///< the opaque head sphere (Lambertian)
    std::vector<Rgb> background;                  ///< background · transmittance of everything in front
    std::vector<float> alpha;     ///< coverage of hair and head, [0, 1]
    std::vector<float> hairAlpha; ///< the hair's share of alpha
    std::vector<float> depth;     ///< camera depth, averaged with the compositing weights; 0 where empty

    /// Per light l at [l·pixelCount() + pixel].
    std::vector<float> V, n;
    std::vector<Rgb> T_s, sigma_f;

    std::size_t pixelCount() const { return std::size_t(width) * std::size_t(height); }
    std::size_t lightCount() const { return lightNames.size(); }
    std::size_t index(int x, int y) const { return std::size_t(y) * std::size_t(width) + std::size_t(x); }
    Rgb beauty(std::size_t pixel) const;
};

} // namespace hairvox
