#include <hairvox/core/atomic_file.h>
#include <hairvox/core/error.h>
#include <hairvox/core/interrupt.h>
#include <hairvox/core/parallel.h>
#include <hairvox/film/exr_codec.h>
#include <hairvox/film/image_file.h>

#include "half_convert.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfStringAttribute.h>
#include <openexr.h>
#include <zlib.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <exception>
#include <new>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace hairvox {

namespace {

/// Largest finite half: a channel holding anything larger is stored as float.
constexpr float kHalfMax = 65504.0f;
/// Longest name of a channel or attribute without the file's long-names flag.
constexpr std::size_t kShortNameLength = 31;

/// One EXR channel: the film layer and channel its values are in, and how it
/// is stored.
struct ExrChannel {
    std::string name;
    const FilmLayer* layer;
    std::size_t channel; ///< within a pixel of the layer (0, or 0–2 for RGB)
    bool half;           ///< stored as half (else float)
    std::size_t offset;  ///< bytes from a packed scanline's start to this channel's values
};

/// The film's channels as an EXR scanline holds them: sorted by name (as
/// OpenEXR's channel list is, by strcmp), each a row of little-endian halves
/// or floats.
class ExrLayout {
public:
    explicit ExrLayout(const Film& film)
        : width_(film.width()) {
        static constexpr const char* rgb[3] = {"R", "G", "B"};
        for (const FilmLayer& l : film.layers()) {
            if (l.channels == 1) {
                channels_.push_back({l.name, &l, 0, !l.fullPrecision, 0});
                continue;
            }
            for (std::size_t c = 0; c < 3; ++c)
                channels_.push_back(
                    {l.name.empty() ? rgb[c] : l.name + "." + rgb[c], &l, c, !l.fullPrecision, 0});
        }
        std::sort(channels_.begin(), channels_.end(), [](const ExrChannel& a, const ExrChannel& b) {
            return std::strcmp(a.name.c_str(), b.name.c_str()) < 0;
        });
        // Half unless the layer asks for float or a value does not fit (the
        // tiles not held read as the fill; a held tile's pixels outside the
        // image too).
        tbb::parallel_for(std::size_t(0), channels_.size(), [&](std::size_t i) {
            ExrChannel& c = channels_[i];
            const FilmLayer& l = *c.layer;
            const float fill = l.fill(int(c.channel));
            c.half = c.half && detail::maxAbs(&fill, 1, 1) <= kHalfMax;
            for (int ty = 0; c.half && ty < l.tilesY(); ++ty)
                for (int tx = 0; c.half && tx < l.tilesX(); ++tx)
                    if (const float* t = l.tileOrNull(tx, ty))
                        c.half = detail::maxAbs(t + c.channel, std::size_t(l.channels),
                                                FilmLayer::kTilePixels) <= kHalfMax;
        });
        for (ExrChannel& c : channels_) {
            c.offset = lineBytes_;
            lineBytes_ += std::size_t(width_) * (c.half ? sizeof(std::uint16_t) : sizeof(float));
        }
        for (const FilmLayer& l : film.layers()) {
            std::vector<std::size_t> of;
            for (std::size_t i = 0; i < channels_.size(); ++i)
                if (channels_[i].layer == &l)
                    of.push_back(i);
            layers_.push_back({&l, std::move(of)});
        }
    }

    const std::vector<ExrChannel>& channels() const { return channels_; }
    std::size_t lineBytes() const { return lineBytes_; }

    /// Scanline y as the file stores it, before compression; `row` is the
    /// caller's scratch for one layer's row.
    void pack(int y, std::uint8_t* out, std::vector<float>& row) const {
        static_assert(std::endian::native == std::endian::little, "EXR files are little-endian");
        const auto width = std::size_t(width_);
        for (const auto& [layer, channels] : layers_) {
            const auto stride = std::size_t(layer->channels);
            row.resize(width * stride);
            const bool held = layer->copyRow(y, row.data());
            for (const std::size_t i : channels) {
                const ExrChannel& c = channels_[i];
                std::uint8_t* dst = out + c.offset;
                const float* src = row.data() + c.channel;
                if (!held)
                    writeFill(layer->fill(int(c.channel)), c.half, width, dst);
                else if (c.half)
                    detail::toHalf(src, stride, width, reinterpret_cast<std::uint16_t*>(dst));
                else
                    for (std::size_t x = 0; x < width; ++x)
                        std::memcpy(dst + x * sizeof(float), src + x * stride, sizeof(float));
            }
        }
    }

private:
    /// `width` copies of `fill` as the file stores it (half or float).
    static void writeFill(float fill, bool half, std::size_t width, std::uint8_t* dst) {
        const std::size_t size = half ? sizeof(std::uint16_t) : sizeof(float);
        if (isPositiveZero(fill) || width == 0) { // +0 as half and as float: zero bytes
            std::memset(dst, 0, width * size);
            return;
        }
        if (half) {
            std::uint16_t bits;
            detail::toHalf(&fill, 1, 1, &bits);
            std::memcpy(dst, &bits, size);
        } else {
            std::memcpy(dst, &fill, size);
        }
        // The first value, then what is written copied after itself.
        for (std::size_t done = 1; done < width;) {
            const std::size_t n = std::min(done, width - done);
            std::memcpy(dst + done * size, dst, n * size);
            done += n;
        }
    }

    /// A film layer and its channels' places in channels_.
    struct LayerChannels {
        const FilmLayer* layer;
        std::vector<std::size_t> channels;
    };

    int width_;
    std::size_t lineBytes_ = 0;
    std::vector<ExrChannel> channels_;
    std::vector<LayerChannels> layers_; ///< in the film's order
};

/// Scanlines per chunk: OpenEXR's, per compression.
int linesPerChunk(ExrCompression c) {
    return c == ExrCompression::Zip ? 16 : 1;
}

/// One chunk's bytes, packed and compressed as the file stores them; owned
/// by one chunk of the pipeline at a time.
class ChunkEncoder {
public:
    /// Encodes scanlines [y, y + rows); the result is valid until the next call.
    std::span<const std::uint8_t> encode(const ExrLayout& layout, int y, int rows,
                                         ExrCompression compression, int zipLevel) {
        const std::size_t bytes = layout.lineBytes() * std::size_t(rows);
        packed_.resize(bytes);
        for (int r = 0; r < rows; ++r)
            layout.pack(y + r, packed_.data() + std::size_t(r) * layout.lineBytes(), row_);
        if (compression == ExrCompression::None)
            return {packed_.data(), bytes};
        // OpenEXR's predictor, then run lengths or zlib.
        predicted_.resize(bytes);
        detail::reorderAndPredict(packed_.data(), bytes, predicted_.data());
        std::size_t size = 0;
        if (compression == ExrCompression::Rle) {
            scratch_.resize(detail::rleScratchWords(bytes));
            code_.resize(detail::rleCapacity(bytes));
            size = detail::rleCompress(predicted_.data(), bytes, scratch_.data(), code_.data());
        } else { // zip, zips: zlib at the scene's level
            uLongf capacity = compressBound(uLong(bytes));
            code_.resize(capacity);
            // With compressBound's room and a valid level, zlib fails only
            // for memory.
            if (compress2(code_.data(), &capacity, predicted_.data(), uLong(bytes), zipLevel) !=
                Z_OK)
                throw std::bad_alloc();
            size = capacity;
        }
        // Not shorter than the bytes: stored raw (what a reader expects of
        // a chunk whose size is the uncompressed size).
        if (size >= bytes)
            return {packed_.data(), bytes};
        return {code_.data(), size};
    }

private:
    std::vector<std::uint8_t> packed_, predicted_, code_;
    std::vector<std::uint64_t> scratch_;
    std::vector<float> row_; ///< one film layer's row (ExrLayout::pack)
};

exr_compression_t coreCompression(ExrCompression c) {
    switch (c) {
    case ExrCompression::Zips: return EXR_COMPRESSION_ZIPS;
    case ExrCompression::Zip: return EXR_COMPRESSION_ZIP;
    case ExrCompression::Rle: return EXR_COMPRESSION_RLE;
    case ExrCompression::None: return EXR_COMPRESSION_NONE;
    }
    throw std::logic_error("coreCompression");
}

/// An OpenEXR Core write context whose errors are thrown as InputError
/// naming the file, and which is always finished.
class ExrWriter {
public:
    ExrWriter(const std::filesystem::path& path, const std::filesystem::path& tmp)
        : path_(path) {
        exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
        init.user_data = &message_;
        init.error_handler_fn = [](exr_const_context_t ctx, exr_result_t, const char* msg) {
            void* user = nullptr;
            if (exr_get_user_data(ctx, &user) == EXR_ERR_SUCCESS && user && msg)
                *static_cast<std::string*>(user) = msg;
        };
        check(exr_start_write(&ctx_, tmp.c_str(), EXR_WRITE_FILE_DIRECTLY, &init));
    }
    ExrWriter(const ExrWriter&) = delete;
    ExrWriter& operator=(const ExrWriter&) = delete;
    ~ExrWriter() {
        if (ctx_)
            exr_finish(&ctx_);
    }

    exr_context_t get() const { return ctx_; }

    void check(exr_result_t result) const {
        if (result != EXR_ERR_SUCCESS)
            throw InputError(strCat(path_.string(), ": cannot write OpenEXR file: ",
                                    message_.empty() ? exr_get_default_error_message(result)
                                                     : message_));
    }

    /// Writes the chunk offsets and closes the file.
    void finish() { check(exr_finish(&ctx_)); }

private:
    std::filesystem::path path_;
    std::string message_;
    exr_context_t ctx_ = nullptr;
};

/// A chunk on its way to the file: its first scanline and its bytes (in its
/// encoder's buffers).
struct EncodedChunk {
    int y = 0;
    std::span<const std::uint8_t> bytes;
};

/// Hands a file's pages to the disk as they fill — writeback started every
/// few megabytes, not waited for — so that the fsync before the rename
/// (core/atomic_file.h) waits for the last of them, not the whole file: at
/// 2048² (100 MB) the write stage 0.31 → 0.28 s, the head's fsync 31–38 →
/// 20 ms. Advice only: where the file cannot be opened or the call fails,
/// the fsync does it all.
class EarlyWriteback {
public:
    explicit EarlyWriteback(const std::filesystem::path& file)
        : fd_(::open(file.c_str(), O_RDONLY | O_CLOEXEC)) {}
    EarlyWriteback(const EarlyWriteback&) = delete;
    EarlyWriteback& operator=(const EarlyWriteback&) = delete;
    ~EarlyWriteback() {
        if (fd_ >= 0)
            ::close(fd_);
    }

    void written(std::size_t bytes) {
        pending_ += bytes;
        if (fd_ < 0 || pending_ < kBytes)
            return;
        ::sync_file_range(fd_, 0, 0, SYNC_FILE_RANGE_WRITE); // the whole file's dirty pages
        pending_ = 0;
    }

private:
    static constexpr std::size_t kBytes = std::size_t(4) << 20;
    int fd_;
    std::size_t pending_ = 0;
};

} // namespace

void writeExr(const std::filesystem::path& path, const Film& film, const ExrHeader& info) {
    if (film.pixelCount() == 0)
        throw std::logic_error("writeExr: an empty film");
    if (info.zipLevel < 1 || info.zipLevel > 9)
        throw InputError(strCat(path.string(), ": EXR zip level ", info.zipLevel,
                                " should be in the range [1, 9]"));
    const ExrLayout layout(film);
    const int lines = linesPerChunk(info.compression);
    const auto chunks = std::size_t((film.height() + lines - 1) / lines);

    writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
        ExrWriter file(path, tmp);
        exr_context_t ctx = file.get();
        int part = 0;
        file.check(exr_add_part(ctx, nullptr, EXR_STORAGE_SCANLINE, &part));
        file.check(exr_initialize_required_attr_simple(ctx, part, film.width(), film.height(),
                                                       coreCompression(info.compression)));
        const auto isLong = [](const std::string& n) { return n.size() > kShortNameLength; };
        const bool longNames =
            std::any_of(info.attributes.begin(), info.attributes.end(),
                        [&](const auto& attribute) { return isLong(attribute.first); }) ||
            std::any_of(layout.channels().begin(), layout.channels().end(),
                        [&](const ExrChannel& c) { return isLong(c.name); });
        if (longNames) // only then: readers older than OpenEXR 2 take 31 characters
            file.check(exr_set_longname_support(ctx, 1));
        for (const ExrChannel& c : layout.channels())
            file.check(exr_add_channel(ctx, part, c.name.c_str(),
                                       c.half ? EXR_PIXEL_HALF : EXR_PIXEL_FLOAT,
                                       EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1));
        if (info.worldToCamera) {
            exr_attr_m44f_t m;
            for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c)
                    m.m[4 * r + c] = (*info.worldToCamera)[std::size_t(r)][std::size_t(c)];
            file.check(exr_attr_set_m44f(ctx, part, "worldToCamera", &m));
        }
        file.check(exr_attr_set_string(ctx, part, "software", "hairvox"));
        for (const auto& [key, value] : info.attributes)
            file.check(exr_attr_set_string(ctx, part, key.c_str(), value.c_str()));
        file.check(exr_write_header(ctx));

        // Chunks packed and compressed in parallel, written in order (the
        // bytes do not depend on the thread count). A chunk's encoder is
        // slot chunk % tokens: at most `tokens` chunks are in flight and
        // the last stage finishes them in order, so chunk c's slot is free
        // when chunk c + tokens starts.
        EarlyWriteback writeback(tmp);
        const std::size_t tokens = 2 * std::size_t(activeThreadCount());
        std::vector<ChunkEncoder> encoders(tokens);
        std::size_t next = 0;
        tbb::parallel_pipeline(
            tokens,
            tbb::make_filter<void, std::size_t>(
                tbb::filter_mode::serial_in_order,
                [&](tbb::flow_control& control) -> std::size_t {
                    if (next == chunks) {
                        control.stop();
                        return 0;
                    }
                    throwIfInterrupted(); // a large image with many AOVs takes a while
                    return next++;
                }) &
                tbb::make_filter<std::size_t, EncodedChunk>(
                    tbb::filter_mode::parallel,
                    [&](std::size_t chunk) {
                        const int y = int(chunk) * lines;
                        return EncodedChunk{y, encoders[chunk % tokens].encode(
                                                   layout, y, std::min(lines, film.height() - y),
                                                   info.compression, info.zipLevel)};
                    }) &
                tbb::make_filter<EncodedChunk, void>(
                    tbb::filter_mode::serial_in_order, [&](const EncodedChunk& c) {
                        file.check(exr_write_scanline_chunk(ctx, part, c.y, c.bytes.data(),
                                                            c.bytes.size()));
                        writeback.written(c.bytes.size());
                    }));
        file.finish();
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

namespace {

/// Whether every chunk of a scanline file lies within the file: OpenEXR's
/// isComplete() trusts the offset table, which a file cut short keeps.
bool chunksInFile(const std::filesystem::path& path) {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec)
        return false;
    exr_context_t ctx = nullptr;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = [](exr_const_context_t, exr_result_t, const char*) {
    };
    if (exr_start_read(&ctx, path.c_str(), &init) != EXR_ERR_SUCCESS)
        return false;
    bool inside = true;
    int32_t lines = 0;
    exr_attr_box2i_t window{};
    if (exr_get_scanlines_per_chunk(ctx, 0, &lines) != EXR_ERR_SUCCESS || lines < 1 ||
        exr_get_data_window(ctx, 0, &window) != EXR_ERR_SUCCESS)
        inside = false;
    for (int y = window.min.y; inside && y <= window.max.y; y += lines) {
        exr_chunk_info_t chunk{};
        inside = exr_read_scanline_chunk_info(ctx, 0, y, &chunk) == EXR_ERR_SUCCESS &&
                 chunk.data_offset + chunk.packed_size <= size;
    }
    exr_finish(&ctx);
    return inside;
}

/// An EXR file's bytes in memory as OpenEXR's input stream (ImfIO.h): reads
/// past the end throw, as a file's would.
class MemoryStream final : public Imf::IStream {
public:
    explicit MemoryStream(const ExrSource& source)
        : Imf::IStream(source.name.c_str())
        , bytes_(source.bytes) {}

    bool isMemoryMapped() const override { return true; }
    bool read(char c[], int n) override {
        std::memcpy(c, take(n), std::size_t(n));
        return position_ < bytes_.size();
    }
    char* readMemoryMapped(int n) override {
        // OpenEXR's interface is not const; it only reads what it is given.
        return const_cast<char*>(reinterpret_cast<const char*>(take(n)));
    }
    std::uint64_t tellg() override { return position_; }
    void seekg(std::uint64_t position) override { position_ = position; }

private:
    const unsigned char* take(int n) {
        if (n < 0 || position_ > bytes_.size() || std::uint64_t(n) > bytes_.size() - position_)
            throw std::runtime_error("unexpected end of the EXR data");
        const unsigned char* p = bytes_.data() + position_;
        position_ += std::uint64_t(n);
        return p;
    }

    std::span<const unsigned char> bytes_;
    std::uint64_t position_ = 0;
};

/// f(Imf::InputFile&) on the source's file, read with `threads` threads.
template <class F>
auto withInputFile(const ExrSource& source, int threads, F&& f) {
    if (source.bytes.empty()) {
        Imf::InputFile file(source.path.c_str(), threads);
        return f(file);
    }
    MemoryStream stream(source);
    Imf::InputFile file(stream, threads);
    return f(file);
}

} // namespace

ExrInfo readExrInfo(const std::filesystem::path& path) {
    return readExrInfo(ExrSource::file(path));
}

ExrInfo readExrInfo(const ExrSource& source) {
    try {
        return withInputFile(source, 1, [&](Imf::InputFile& file) {
            const Imf::Header& header = file.header();
            const Imath::Box2i window = header.dataWindow();
            ExrInfo info;
            info.width = std::int64_t(window.max.x) - window.min.x + 1;
            info.height = std::int64_t(window.max.y) - window.min.y + 1;
            for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
                info.channels.emplace_back(it.name());
            for (auto it = header.begin(); it != header.end(); ++it)
                if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
                    info.attributes[it.name()] = s->value();
            info.complete =
                file.isComplete() && (!source.bytes.empty() || chunksInFile(source.path));
            return info;
        });
    } catch (const std::exception& e) {
        throw InputError(strCat(source.name, ": cannot read OpenEXR file: ", e.what()));
    }
}

ExrRgbImage readExrRgb(const ExrSource& source, std::uint64_t maxPixels) {
    try {
        return withInputFile(source, activeThreadCount(), [&](Imf::InputFile& file) {
            ExrRgbImage image;
            std::string channels;
            const Imf::Header& header = file.header();
            const Imath::Box2i window = header.dataWindow();
            const std::int64_t width = std::int64_t(window.max.x) - window.min.x + 1;
            const std::int64_t height = std::int64_t(window.max.y) - window.min.y + 1;
            for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
                channels += (channels.empty() ? "" : ", ") + std::string(it.name());
            for (const char* name : {"R", "G", "B"})
                if (!header.channels().findChannel(name))
                    throw InputError(strCat(source.name, ": no channel ", name,
                                            " (an RGB or RGBA image is needed; the file has ",
                                            channels.empty() ? std::string("none") : channels,
                                            ")"));
            if (width < 1 || height < 1 || std::uint64_t(width) * std::uint64_t(height) > maxPixels)
                throw InputError(strCat(source.name, ": ", width, " x ", height,
                                        " pixels: expected at most ", maxPixels, " pixels"));
            image.width = int(width);
            image.height = int(height);
            image.rgb.assign(std::size_t(width) * std::size_t(height) * 3, 0.0f);
            Imf::FrameBuffer frameBuffer;
            const char* names[3] = {"R", "G", "B"};
            for (std::size_t c = 0; c < 3; ++c)
                frameBuffer.insert(names[c],
                                   Imf::Slice::Make(Imf::FLOAT, image.rgb.data() + c, window.min,
                                                    width, height, 3 * sizeof(float),
                                                    std::size_t(3 * width) * sizeof(float)));
            file.setFrameBuffer(frameBuffer);
            file.readPixels(window.min.y, window.max.y);
            return image;
        });
    } catch (const InputError&) {
        throw;
    } catch (const std::exception& e) {
        throw InputError(strCat(source.name, ": cannot read OpenEXR file: ", e.what()));
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
            std::vector<float> rgbValues(3 * film.pixelCount());
            for (std::size_t p = 0; p < film.pixelCount(); ++p) {
                rgbValues[3 * p] = r[p];
                rgbValues[3 * p + 1] = g[p];
                rgbValues[3 * p + 2] = b[p];
            }
            l.assign(rgbValues);
            continue;
        }
        film.layer(film.addLayer(name, 1, true)).assign(values);
    }
    return film;
}

} // namespace hairvox
