#include <hairvox/core/error.h>
#include <hairvox/core/version.h>
#include <hairvox/geometry/builtin_environment.h>
#include <hairvox/shots/frame_hash.h>

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <span>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

namespace hairvox::shots {

std::uint64_t FileDigests::of(const std::filesystem::path& file) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        throw InputError(strCat(file.string(), ": cannot read: ", std::strerror(errno)));
    struct Closer {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
        throw InputError(strCat(file.string(), ": not a regular file"));
    const std::string id = strCat(file.string(), "|", st.st_size, "|", st.st_mtim.tv_sec, ".",
                                  st.st_mtim.tv_nsec, "|", st.st_dev, ":", st.st_ino);
    if (const auto it = digests_.find(id); it != digests_.end())
        return it->second;
    Hasher h;
    std::vector<char> buffer(1 << 20);
    for (;;) {
        const ssize_t n = ::read(fd, buffer.data(), buffer.size());
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            throw InputError(strCat(file.string(), ": read error: ", std::strerror(errno)));
        if (n == 0)
            break;
        h.bytes(buffer.data(), static_cast<std::size_t>(n));
    }
    return digests_[id] = h.digest();
}

void hashSceneInto(Hasher& h, const Scene& s) {
    // The groom: a file by its path here (its contents in frameHash()).
    h.value(s.groom.isProcedural());
    if (s.groom.isProcedural()) {
        const ProceduralGroomParams& p = s.groom.procedural;
        h.value(p.style).value(p.strands).value(p.pointsPerStrand).value(p.seed);
        h.value(p.headCenter).value(p.headRadius).value(p.length).value(p.lengthVariation);
        h.value(p.waveAmplitude).value(p.waveLength).value(p.curlRadius).value(p.curlPitch);
        h.value(p.clumpStrength);
        h.value(p.colors.size());
        for (const Rgb& c : p.colors)
            h.value(c);
    }
    h.value(s.groom.inMemory != nullptr); // (the Python module's) by its contents
    if (s.groom.inMemory)
        h.value(contentHash(*s.groom.inMemory));
    h.value(s.groom.thickness).value(s.groom.color);
    s.fiberScale.hashInto(h);
    s.fiber.hashInto(h);
    s.dualScattering.hashInto(h);
    h.value(s.lights.size());
    for (const Light& l : s.lights) {
        l.hashInto(h);
        h.string(l.name); // names the light's EXR layers
    }
    const CameraParams& c = s.camera;
    h.value(c.position).value(c.lookAt).value(c.up).value(c.fovY).value(c.width).value(c.height);
    h.value(s.head.has_value());
    if (s.head)
        h.value(s.head->sphere.center).value(s.head->sphere.radius).value(s.head->albedo);
    h.value(s.meshes.size());
    for (const MeshSource& m : s.meshes) {
        h.value(m.isMannequin());
        if (m.isMannequin())
            h.value(m.mannequin.center).value(m.mannequin.radius).value(m.mannequinRings);
        h.value(m.transform.scale).value(m.transform.rotateDegrees).value(m.transform.translate);
        h.value(m.albedo);
    }
    h.value(s.environment.has_value()).value(s.environmentLights);
    if (s.environment) { // its map's contents in frameHash()
        const EnvironmentLight& e = *s.environment;
        h.string(e.name).value(e.file.empty()).string(e.builtin).value(e.color).value(e.intensity);
        h.value(e.rotation).value(e.visible);
    }
    h.value(s.voxelSize.has_value()).value(s.voxelSize.value_or(0.0f));
    h.value(s.fiberSampleSpacing.has_value()).value(s.fiberSampleSpacing.value_or(0.0f));
    h.value(s.integrator);
    const PathTraceSettings& pt = s.pathTrace;
    h.value(pt.spp).value(pt.timeLimit).value(pt.maxDepth).value(pt.rouletteDepth).value(pt.seed);
    s.volumetric.hashInto(h);
    h.value(s.globalTermMode);
    h.value(s.exact.rays).value(s.exact.radius).value(s.exact.seed);
    h.value(s.shadingRate).value(s.shadingTolerance).value(s.tailTransmittance);
    h.value(s.background);
    const OutputSettings& o = s.output;
    h.value(o.exr.empty()).value(o.png.empty()); // which outputs, not where
    h.value(o.exposure).value(o.toneMap).value(o.exrZipLevel).value(o.exrCompression);
    h.value(o.layers.has_value());
    if (o.layers) {
        h.value(o.layers->size());
        for (const std::string& layer : *o.layers)
            h.string(layer);
    }
}

std::string frameHash(const Scene& scene, int frame, FileDigests& files) {
    Hasher h;
    h.string("hairvox frame 1");
    h.string(version());
    h.value(frame);
    hashSceneInto(h, scene);
    if (!scene.groom.file.empty())
        h.value(files.of(scene.groom.file));
    if (scene.environment && !scene.environment->file.empty())
        h.value(files.of(scene.environment->file));
    if (scene.environment && !scene.environment->builtin.empty()) {
        const std::span<const unsigned char> exr =
            builtinEnvironment(scene.environment->builtin).exr;
        h.bytes(exr.data(), exr.size());
    }
    for (const MeshSource& m : scene.meshes)
        if (!m.isMannequin())
            h.value(files.of(m.file));
    return hexDigest(h.digest());
}

} // namespace hairvox::shots
