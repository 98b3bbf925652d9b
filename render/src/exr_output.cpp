#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/parallel.h>
#include <hairvox/render/output.h>

#include <ImfChannelList.h>
#include <ImfCompressionAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <half.h>

#include <algorithm>
#include <cmath>
#include <exception>

namespace hairvox {

namespace {

/// Largest finite half: a channel holding anything larger is stored as float.
constexpr float kHalfMax = 65504.0f;
/// Rows converted and written at a time, so that the half copies cost a band,
/// not an image.
constexpr int kBandRows = 64;

/// One EXR channel: where its floats are in the film and how it is stored.
struct ExrChannel {
    std::string name;
    const float* first; ///< pixel (0, 0)
    std::size_t stride; ///< bytes between pixels
    bool half;
};

class ExrLayout {
public:
    explicit ExrLayout(const Film& film) : width_(std::size_t(film.width)), pixels_(film.pixelCount()) {}

    void addScalar(const std::string& name, const float* data, bool alwaysFloat = false) {
        add(name, data, sizeof(float), alwaysFloat);
    }
    void addRgb(const std::string& layer, const Rgb* data) {
        static constexpr const char* channels[3] = {"R", "G", "B"};
        for (int c = 0; c < 3; ++c)
            add(layer.empty() ? channels[c] : layer + "." + channels[c],
                reinterpret_cast<const float*>(data) + c, sizeof(Rgb), false);
    }

    void declare(Imf::Header& header) const {
        for (const ExrChannel& c : channels_)
            header.channels().insert(c.name, Imf::Channel(c.half ? Imf::HALF : Imf::FLOAT));
    }

    /// Converts rows [y0, y0 + rows) into the band buffers and points `file` at them.
    void setBand(Imf::OutputFile& file, int y0, int rows) {
        Imf::FrameBuffer frameBuffer;
        const std::size_t count = width_ * std::size_t(rows);
        halves_.resize(channels_.size() * count);
        floats_.resize(channels_.size() * count);
        for (std::size_t i = 0; i < channels_.size(); ++i) {
            const ExrChannel& c = channels_[i];
            const auto* src = reinterpret_cast<const char*>(c.first) +
                              std::size_t(y0) * width_ * c.stride;
            void* band;
            if (c.half) {
                half* dst = halves_.data() + i * count;
                for (std::size_t p = 0; p < count; ++p)
                    dst[p] = half(*reinterpret_cast<const float*>(src + p * c.stride));
                band = dst;
            } else {
                float* dst = floats_.data() + i * count;
                for (std::size_t p = 0; p < count; ++p)
                    dst[p] = *reinterpret_cast<const float*>(src + p * c.stride);
                band = dst;
            }
            frameBuffer.insert(c.name, Imf::Slice::Make(c.half ? Imf::HALF : Imf::FLOAT, band,
                                                        Imath::V2i(0, y0), std::int64_t(width_),
                                                        rows));
        }
        file.setFrameBuffer(frameBuffer);
    }

private:
    void add(const std::string& name, const float* first, std::size_t stride, bool alwaysFloat) {
        bool fitsHalf = !alwaysFloat;
        const auto* bytes = reinterpret_cast<const char*>(first);
        for (std::size_t i = 0; i < pixels_ && fitsHalf; ++i)
            fitsHalf = std::abs(*reinterpret_cast<const float*>(bytes + i * stride)) <= kHalfMax;
        channels_.push_back({name, first, stride, fitsHalf});
    }

    std::size_t width_, pixels_;
    std::vector<ExrChannel> channels_;
    std::vector<half> halves_;
    std::vector<float> floats_;
};

} // namespace

void writeExr(const std::filesystem::path& path, const Film& film, const Camera& camera,
              const std::map<std::string, std::string>& attributes) {
    if (film.pixelCount() == 0 || film.width != camera.width() || film.height != camera.height())
        throw std::logic_error("writeExr: the film does not match the camera");
    const std::size_t pixels = film.pixelCount();
    std::vector<Rgb> beauty(pixels);
    for (std::size_t p = 0; p < pixels; ++p)
        beauty[p] = film.beauty(p);

    Imf::Header header(film.width, film.height);
    // ZIPS (zlib per scanline): the same size as ZIP's 16-line chunks on these
    // images, and faster to write with several threads (measured on the
    // default scene at 1024²: 17.8 vs 18.0 MB, 1.39 vs 0.98 s on 2 cores).
    header.compression() = Imf::ZIPS_COMPRESSION;
    float m[4][4];
    camera.worldToCameraMatrix(m);
    Imf::addWorldToCamera(header, Imath::M44f(m));
    header.insert("software", Imf::StringAttribute("hairvox"));
    for (const auto& [key, value] : attributes)
        header.insert(key, Imf::StringAttribute(value));

    ExrLayout layout(film);
    layout.addRgb("", beauty.data());
    layout.addScalar("A", film.alpha.data());
    layout.addRgb("direct_R", film.directR.data());
    layout.addRgb("direct_TT", film.directTT.data());
    layout.addRgb("direct_TRT", film.directTRT.data());
    layout.addRgb("back_direct", film.backDirect.data());
    layout.addRgb("scatter", film.scatter.data());
    layout.addRgb("head", film.head.data());
    layout.addRgb("background", film.background.data());
    layout.addScalar("hair.A", film.hairAlpha.data());
    layout.addScalar("Z", film.depth.data(), true);
    for (std::size_t l = 0; l < film.lightCount(); ++l) {
        const std::string& name = film.lightNames[l];
        layout.addScalar(name + ".V", film.V.data() + l * pixels);
        layout.addScalar(name + ".n", film.n.data() + l * pixels);
        layout.addRgb(name + ".T_s", film.T_s.data() + l * pixels);
        layout.addRgb(name + ".sigma_f", film.sigma_f.data() + l * pixels);
    }
    layout.declare(header);

    // OpenEXR compresses line blocks on its own global thread pool, which is
    // empty unless sized: match it to the thread limit in force.
    const int threads = activeThreadCount();
    if (Imf::globalThreadCount() != threads)
        Imf::setGlobalThreadCount(threads);
    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        try {
            Imf::OutputFile file(tmp.c_str(), header, threads);
            for (int y = 0; y < film.height; y += kBandRows) {
                throwIfInterrupted(); // a large image with many AOVs takes seconds to compress
                const int rows = std::min(kBandRows, film.height - y);
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

std::vector<std::filesystem::path> writeOutputs(const Film& film, const Scene& scene,
                                                const std::map<std::string, std::string>& extra) {
    std::vector<std::filesystem::path> written;
    if (!scene.output.exr.empty()) {
        std::map<std::string, std::string> attributes = {
            {"hairvox:scene", scene.name},
            {"hairvox:globalTermMode", toString(scene.globalTermMode)},
            {"hairvox:voxelSize", scene.voxelSize ? strCat(*scene.voxelSize) : "auto"},
            {"hairvox:shadingRate", toString(scene.shadingRate)},
        };
        for (const auto& [key, value] : extra)
            attributes[key] = value;
        writeExr(scene.output.exr, film, Camera(scene.camera), attributes);
        written.push_back(scene.output.exr);
    }
    if (!scene.output.png.empty()) {
        writePng(scene.output.png, film, scene.output.exposure, scene.output.toneMap);
        written.push_back(scene.output.png);
    }
    return written;
}

} // namespace hairvox
