#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/large_array.h>
#include <hairvox/core/parallel.h>
#include <hairvox/film/image_file.h>

#include "half_convert.h"

#include <tbb/parallel_for.h>

#include <ImfChannelList.h>
#include <ImfCompressionAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <memory>

namespace hairvox {

namespace {

/// Largest finite half: a channel holding anything larger is stored as float.
constexpr float kHalfMax = 65504.0f;
/// Rows converted and written at a time, so that the half copies cost a band,
/// not an image (and Ctrl-C is seen between bands); enough line blocks for
/// OpenEXR's pool to compress in parallel. 64 rather than 256: a 43-channel
/// 1080p band is then 21 MB, not 84, and fresh pages are what writing costs
/// most on a VM (docs/DESIGN.md §7, "Pages": the write stage of a 1080p
/// render of 10k segments 0.61–0.68 → 0.51–0.55 s, the same bytes).
constexpr int kBandRows = 64;

/// One EXR channel: where its floats are in the film and how it is stored.
struct ExrChannel {
    std::string name;
    const float* first; ///< pixel (0, 0)
    std::size_t stride; ///< floats between pixels (1 or 3)
    bool half;          ///< stored as half (else float)
};

class ExrLayout {
public:
    explicit ExrLayout(const Film& film)
        : width_(std::size_t(film.width()))
        , pixels_(film.pixelCount()) {
        static constexpr const char* rgb[3] = {"R", "G", "B"};
        for (const FilmLayer& l : film.layers()) {
            if (l.channels == 1) {
                channels_.push_back({l.name, l.data.data(), 1, !l.fullPrecision});
                continue;
            }
            for (int c = 0; c < 3; ++c)
                channels_.push_back({l.name.empty() ? rgb[c] : l.name + "." + rgb[c],
                                     l.data.data() + c, 3, !l.fullPrecision});
        }
        // Half unless the layer asks for float or a value does not fit.
        tbb::parallel_for(std::size_t(0), channels_.size(), [&](std::size_t i) {
            ExrChannel& c = channels_[i];
            c.half = c.half && detail::maxAbs(c.first, c.stride, pixels_) <= kHalfMax;
        });
    }

    void declare(Imf::Header& header) const {
        for (const ExrChannel& c : channels_)
            header.channels().insert(c.name, Imf::Channel(c.half ? Imf::HALF : Imf::FLOAT));
    }

    /// Converts rows [y0, y0 + rows) into the band buffers and points `file` at them.
    void setBand(Imf::OutputFile& file, int y0, int rows) {
        const std::size_t capacity = width_ * std::size_t(kBandRows);
        if (band_.empty()) // written before read: left unwritten by resize
            band_.resize(channels_.size() * capacity);
        const std::size_t count = width_ * std::size_t(rows);
        // Channels × blocks of rows, converted on the calling threads while
        // OpenEXR's pool waits for the band.
        constexpr std::size_t kRowsPerTask = 64;
        const std::size_t blocks = (std::size_t(rows) + kRowsPerTask - 1) / kRowsPerTask;
        tbb::parallel_for(std::size_t(0), channels_.size() * blocks, [&](std::size_t task) {
            const ExrChannel& c = channels_[task / blocks];
            const std::size_t begin = (task % blocks) * kRowsPerTask * width_;
            const std::size_t n = std::min(count, begin + kRowsPerTask * width_) - begin;
            const float* src = c.first + (std::size_t(y0) * width_ + begin) * c.stride;
            std::uint32_t* dst = band_.data() + (task / blocks) * capacity;
            if (c.half)
                detail::toHalf(src, c.stride, n, reinterpret_cast<std::uint16_t*>(dst) + begin);
            else
                for (std::size_t p = 0; p < n; ++p)
                    std::memcpy(dst + begin + p, src + p * c.stride, sizeof(float));
        });
        Imf::FrameBuffer frameBuffer;
        for (std::size_t i = 0; i < channels_.size(); ++i) {
            const ExrChannel& c = channels_[i];
            char* band = reinterpret_cast<char*>(band_.data() + i * capacity);
            // The band's first value is pixel (0, y0).
            frameBuffer.insert(c.name,
                               Imf::Slice::Make(c.half ? Imf::HALF : Imf::FLOAT, band,
                                                Imath::V2i(0, y0), std::int64_t(width_), rows));
        }
        file.setFrameBuffer(frameBuffer);
    }

private:
    std::size_t width_, pixels_;
    std::vector<ExrChannel> channels_;
    /// One band: per channel kBandRows rows of halves or floats (4 bytes reserved per value).
    LargeVector<std::uint32_t> band_;
};

} // namespace

void writeExr(const std::filesystem::path& path, const Film& film, const ExrHeader& info) {
    if (film.pixelCount() == 0)
        throw std::logic_error("writeExr: an empty film");
    if (info.zipLevel < 1 || info.zipLevel > 9)
        throw InputError(strCat(path.string(), ": EXR zip level ", info.zipLevel,
                                " should be in the range [1, 9]"));
    Imf::Header header(film.width(), film.height());
    switch (info.compression) { // the trade-offs: ExrCompression
    case ExrCompression::Zips: header.compression() = Imf::ZIPS_COMPRESSION; break;
    case ExrCompression::Zip: header.compression() = Imf::ZIP_COMPRESSION; break;
    case ExrCompression::Rle: header.compression() = Imf::RLE_COMPRESSION; break;
    case ExrCompression::None: header.compression() = Imf::NO_COMPRESSION; break;
    }
    header.zipCompressionLevel() = info.zipLevel;
    if (info.worldToCamera) {
        const Matrix44& m = *info.worldToCamera;
        Imf::addWorldToCamera(header,
                              Imath::M44f(m[0][0], m[0][1], m[0][2], m[0][3], m[1][0], m[1][1],
                                          m[1][2], m[1][3], m[2][0], m[2][1], m[2][2], m[2][3],
                                          m[3][0], m[3][1], m[3][2], m[3][3]));
    }
    header.insert("software", Imf::StringAttribute("hairvox"));
    for (const auto& [key, value] : info.attributes)
        header.insert(key, Imf::StringAttribute(value));

    ExrLayout layout(film);
    layout.declare(header);

    // OpenEXR compresses line blocks on its own global thread pool, which is
    // empty unless sized: match it to the thread limit in force.
    const int threads = activeThreadCount();
    if (Imf::globalThreadCount() != threads)
        Imf::setGlobalThreadCount(threads);
    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        try {
            Imf::OutputFile file(tmp.c_str(), header, threads);
            for (int y = 0; y < film.height(); y += kBandRows) {
                throwIfInterrupted(); // a large image with many AOVs takes seconds to compress
                const int rows = std::min(kBandRows, film.height() - y);
                layout.setBand(file, y, rows);
                file.writePixels(rows);
            }
        } catch (const Interrupted&) {
            throw;
        } catch (const std::exception& e) {
            throw InputError(strCat(path.string(), ": cannot write OpenEXR file: ", e.what()));
        }
    });
}

ExrImage readExr(const std::filesystem::path& path) {
    try {
        Imf::InputFile file(path.c_str(), activeThreadCount());
        const Imf::Header& header = file.header();
        const Imath::Box2i window = header.dataWindow();
        ExrImage image;
        image.width = window.max.x - window.min.x + 1;
        image.height = window.max.y - window.min.y + 1;
        const auto width = static_cast<std::size_t>(image.width);
        const std::size_t pixels = width * static_cast<std::size_t>(image.height);
        Imf::FrameBuffer frameBuffer;
        for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
            std::vector<float>& data = image.channels[it.name()];
            data.assign(pixels, 0.0f);
            frameBuffer.insert(it.name(),
                               Imf::Slice::Make(Imf::FLOAT, data.data(), window.min,
                                                std::int64_t(image.width), image.height));
        }
        for (auto it = header.begin(); it != header.end(); ++it)
            if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
                image.attributes[it.name()] = s->value();
        file.setFrameBuffer(frameBuffer);
        file.readPixels(window.min.y, window.max.y);
        return image;
    } catch (const std::exception& e) {
        throw InputError(strCat(path.string(), ": cannot read OpenEXR file: ", e.what()));
    }
}

Film filmFromExr(const ExrImage& image) {
    Film film(image.width, image.height);
    const auto has = [&](const std::string& name) {
        return image.channels.count(name) > 0;
    };
    // The layers whose R, G and B channels are all present; a channel of none is a scalar.
    std::map<std::string, bool> rgbLayer;
    for (const auto& [name, values] : image.channels) {
        const std::size_t dot = name.rfind('.');
        const std::string layer = dot == std::string::npos ? "" : name.substr(0, dot);
        const std::string prefix = layer.empty() ? "" : layer + ".";
        if (name == prefix + "R" || name == prefix + "G" || name == prefix + "B")
            rgbLayer[layer] = has(prefix + "R") && has(prefix + "G") && has(prefix + "B");
    }
    for (const auto& [name, values] : image.channels) {
        const std::size_t dot = name.rfind('.');
        const std::string layer = dot == std::string::npos ? "" : name.substr(0, dot);
        const std::string channel = dot == std::string::npos ? name : name.substr(dot + 1);
        const auto rgb = rgbLayer.find(layer);
        if (rgb != rgbLayer.end() && rgb->second &&
            (channel == "R" || channel == "G" || channel == "B")) {
            if (film.find(layer))
                continue;
            const std::string prefix = layer.empty() ? "" : layer + ".";
            FilmLayer& l = film.layer(film.addLayer(layer, 3, true));
            const std::vector<float>&r = image.channels.at(prefix + "R"),
                  &g = image.channels.at(prefix + "G"), &b = image.channels.at(prefix + "B");
            for (std::size_t p = 0; p < film.pixelCount(); ++p) {
                l.data[3 * p] = r[p];
                l.data[3 * p + 1] = g[p];
                l.data[3 * p + 2] = b[p];
            }
            continue;
        }
        film.layer(film.addLayer(name, 1, true)).data.assign(values.begin(), values.end());
    }
    return film;
}

} // namespace hairvox
