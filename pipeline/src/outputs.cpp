// hairvox pipeline: a render's outputs — the EXR with its attributes and the
// PNG preview, both written atomically (writeOutputs(), pipeline.h).
#include <hairvox/core/error.h>
#include <hairvox/core/format.h>
#include <hairvox/film/image_file.h>
#include <hairvox/geometry/camera.h>
#include <hairvox/pipeline/pipeline.h>

#include <tbb/task_group.h>

#include <exception>
#include <map>

namespace hairvox {

namespace {

void writeExrOutput(const Film& film, const Scene& scene,
                    const std::map<std::string, std::string>& extra) {
    if (!scene.output.exr.empty()) {
        ExrHeader header;
        header.zipLevel = scene.output.exrZipLevel;
        header.compression = scene.output.exrCompression;
        header.worldToCamera = Camera(scene.camera).worldToCameraMatrix();
        header.attributes = {{"hairvox:scene", scene.name},
                             {"hairvox:integrator", toString(scene.integrator)}};
        if (isRasterized(scene.integrator)) {
            header.attributes["hairvox:globalTermMode"] = toString(scene.globalTermMode);
            header.attributes["hairvox:voxelSize"] =
                scene.voxelSize ? strCat(*scene.voxelSize) : "auto";
            header.attributes["hairvox:shadingRate"] = toString(scene.shadingRate);
        }
        for (const auto& [key, value] : extra)
            header.attributes[key] = value;
        writeExr(scene.output.exr, film, header);
    }
}

} // namespace

std::vector<std::filesystem::path> writeOutputs(const Film& film, const Scene& scene,
                                                const std::map<std::string, std::string>& extra) {
    std::vector<std::filesystem::path> written;
    // The PNG is encoded while the EXR is written, and written (atomically)
    // only once the EXR is: an interrupted or failed EXR leaves both outputs
    // as they were.
    tbb::task_group encoding;
    std::vector<std::uint8_t> png;
    std::exception_ptr pngError;
    if (!scene.output.png.empty())
        encoding.run([&] {
            try {
                png = encodePng(film.width(), film.height(),
                                previewPixels(film, scene.output.exposure, scene.output.toneMap));
            } catch (...) {
                pngError = std::current_exception();
            }
        });
    try {
        writeExrOutput(film, scene, extra);
    } catch (...) {
        encoding.wait();
        throw;
    }
    encoding.wait();
    if (pngError)
        std::rethrow_exception(pngError);
    if (!scene.output.png.empty())
        writeEncodedPng(scene.output.png, png);
    if (!scene.output.exr.empty())
        written.push_back(scene.output.exr);
    if (!scene.output.png.empty())
        written.push_back(scene.output.png);
    return written;
}

} // namespace hairvox
