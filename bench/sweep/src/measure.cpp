#include "measure.h"

#include "text.h"

#include <hairvox/core/error.h>
#include <hairvox/core/host.h>
#include <hairvox/core/parallel.h>
#include <hairvox/voxelize/fiber_grid.h>

namespace hairvox::bench {

namespace {

/// Peak resident memory of this process so far: the job's own in a worker
/// (core/host.h: not its parent's, which ru_maxrss would carry across exec).
double peakResidentMiB() {
    return peakResidentBytes() / double(1 << 20);
}

/// The lights a render evaluates (the renderer skips dark ones).
std::vector<const Light*> litLights(const Scene& scene) {
    std::vector<const Light*> lights;
    for (const Light& l : scene.lights)
        if (!l.isDark())
            lights.push_back(&l);
    return lights;
}

/// The global term of the scene's mode toward every lit light at `points`,
/// without the head and meshes (see the header comment).
std::vector<std::vector<GlobalTerm>> probeTerms(Scene scene, const PipelineOptions& options,
                                                const std::vector<GlobalTermQuery>& points) {
    scene.head.reset();
    scene.meshes.clear();
    const std::unique_ptr<SceneAssets> assets = loadSceneAssets(scene, options);
    std::vector<std::vector<GlobalTerm>> terms;
    for (const Light* light : litLights(scene))
        terms.push_back(evaluateGlobalTerm(*assets->globalTerm, *light, points));
    return terms;
}

std::vector<GlobalTermQuery> probePointsOf(const Scene& scene, const BenchJob& job, double* h0) {
    const Groom groom = loadGroom(scene).groom;
    if (h0)
        *h0 = scene.voxelSize ? double(*scene.voxelSize) : defaultVoxelSize(groom);
    return sampleFiberPoints(groom, job.probePoints, job.probeSeed);
}

ProbeError meanProbeError(const std::vector<std::vector<GlobalTerm>>& estimate,
                          const std::vector<std::vector<GlobalTerm>>& reference,
                          const std::filesystem::path& referenceFile) {
    if (estimate.size() != reference.size())
        throw InputError(strCat(referenceFile.string(), ": ", reference.size(),
                                " light(s), the scene has ", estimate.size()));
    ProbeError mean;
    for (std::size_t l = 0; l < estimate.size(); ++l) {
        if (estimate[l].size() != reference[l].size())
            throw InputError(strCat(referenceFile.string(), ": ", reference[l].size(),
                                    " probe points, expected ", estimate[l].size()));
        const ProbeError e = compareGlobalTerms(estimate[l], reference[l]);
        const double w = 1.0 / double(estimate.size());
        mean.maeV += w * e.maeV;
        mean.maeT_s += w * e.maeT_s;
        mean.biasN += w * e.biasN;
        mean.meanNRef += w * e.meanNRef;
    }
    return mean;
}

/// Renders the job's configuration `runs` times end to end (once if the first
/// run is longer than singleRunAbove) and takes medians.
BenchMeasurement timeRenders(const Scene& scene, const BenchJob& job,
                             const PipelineOptions& options, Film* lastFilm) {
    std::vector<double> load, voxelize, tables, globalTerm, multiple, prepare, raster, shade, trace,
        write, total;
    BenchMeasurement m;
    int runs = job.runs;
    for (int r = 0; r < runs; ++r) {
        SceneRender render = renderScene(scene, options, true);
        const StageTimes& t = render.times;
        load.push_back(t.load);
        voxelize.push_back(t.voxelize);
        tables.push_back(t.tables);
        globalTerm.push_back(t.globalTerm);
        multiple.push_back(t.multiple);
        prepare.push_back(render.globalTermPrepareSeconds);
        raster.push_back(t.raster);
        shade.push_back(t.shade);
        trace.push_back(t.trace);
        write.push_back(t.write);
        total.push_back(t.total());
        m.segments = render.raster ? render.raster->segments : 0;
        m.shadingPoints = render.raster ? render.raster->shadingPoints : 0;
        m.activeVoxels = render.activeVoxels;
        m.pathTrace = render.pathTrace;
        m.voxelSize = scene.globalTermMode == GlobalTermMode::Exact ? double(scene.exact.radius)
                                                                    : render.voxelSize;
        if (r == 0 && job.singleRunAbove > 0 && t.total() > job.singleRunAbove)
            runs = 1;
        // Only the last film is kept: holding one across renders would raise the peak.
        if (r + 1 == runs && lastFilm)
            *lastFilm = std::move(render.film);
    }
    m.times.load = median(load);
    m.times.voxelize = median(voxelize);
    m.times.tables = median(tables);
    m.times.globalTerm = median(globalTerm);
    m.times.multiple = median(multiple);
    m.times.raster = median(raster);
    m.times.shade = median(shade);
    m.times.trace = median(trace);
    m.times.write = median(write);
    m.totalSeconds = median(total);
    m.prepareSeconds = median(prepare);
    m.runs = runs;
    if (job.isolated)
        m.peakMiB = peakResidentMiB();
    return m;
}

} // namespace

BenchMeasurement runJob(const BenchJob& job) {
    const ThreadLimit threadLimit(job.threads);
    Scene scene = job.scene.build();
    scene.output.exr = job.scratch / "render.exr";
    scene.output.png = job.scratch / "render.png";
    scene.globalTermMode = job.config.mode;
    scene.integrator = job.config.integrator;
    scene.shadingRate = job.config.shadingRate;
    PipelineOptions options;
    options.threads = job.threads;

    if (job.reference) {
        // h0 first: it is the reference's footprint. The render comes before
        // the probe references so that its peak memory is its own.
        double h0 = 0;
        const std::vector<GlobalTermQuery> points = probePointsOf(scene, job, &h0);
        // Two independent halves of K/2 rays each (seeds 1 and 2): their mean
        // is the reference, half A's difference from it its noise, removed
        // from every error against it (film/image_compare.h).
        scene.exact.radius = static_cast<float>(h0);
        scene.exact.rays = std::max<std::uint32_t>(1, job.config.rays / 2);
        Film film;
        BenchMeasurement m = timeRenders(scene, job, options, &film);
        ComparedImage reference = ComparedImage::beautyOf(film, kHairAlphaLayer);
        scene.exact.seed = 2;
        const BenchMeasurement b = timeRenders(scene, job, options, &film);
        const ComparedImage halfB = ComparedImage::beautyOf(film, kHairAlphaLayer);
        film = Film();
        reference.halfA = reference.value;
        for (std::size_t p = 0; p < reference.value.size(); ++p)
            reference.value[p] = 0.5f * (reference.halfA[p] + halfB.value[p]);
        m.times += b.times;
        m.totalSeconds += b.totalSeconds;
        m.peakMiB = b.peakMiB;
        m.defaultVoxelSize = h0;
        writeComparedImage(job.referenceImage, reference);
        for (std::size_t i = 0; i < job.probeScales.size() && job.probePoints > 0; ++i) {
            Scene probe = scene;
            probe.exact.rays = job.probeRays;
            probe.exact.radius = static_cast<float>(job.probeScales[i] * h0);
            writeProbeTerms(job.probeFiles.at(i), probeTerms(probe, options, points));
        }
        return m;
    }

    if (job.pathReference) {
        scene.integrator = Integrator::Path;
        scene.pathTrace.spp = job.spp;
        scene.pathTrace.timeLimit = job.timeLimit;
        scene.validate();
        Film film;
        BenchMeasurement m = timeRenders(scene, job, options, &film);
        writeComparedImage(job.referenceImage, hairRadianceOf(film));
        return m;
    }

    if (job.config.integrator == Integrator::Path) {
        // The frontier: the path tracer against its own reference, seeded
        // apart from it, so that the error left is this run's noise.
        scene.pathTrace.spp = job.config.spp;
        scene.pathTrace.timeLimit = 0;
        scene.pathTrace.seed += 1;
    } else if (job.config.integrator == Integrator::Volumetric && job.config.pathsPerCell > 0) {
        scene.volumetric.paths = 0;
        scene.volumetric.pathsPerCell = job.config.pathsPerCell;
    }
    if (job.config.mode == GlobalTermMode::Exact) {
        scene.exact.rays = job.config.rays;
        scene.exact.radius = static_cast<float>(job.voxelSize);
    } else if (job.voxelSize > 0) {
        scene.voxelSize = static_cast<float>(job.voxelSize);
    }
    scene.validate();
    Film film;
    BenchMeasurement m = timeRenders(scene, job, options, &film);
    m.defaultVoxelSize = m.voxelSize / job.config.voxelScale;
    if (job.block > 0) {
        const ComparedImage estimate = hairRadianceOf(film);
        const ComparedImage reference = readComparedImage(job.referenceImage);
        m.image = compareImages(estimate, reference);
        m.imageBlocks =
            compareImages(estimate.boxFiltered(job.block), reference.boxFiltered(job.block));
    } else if (!job.referenceImage.empty()) {
        const ComparedImage beauty = ComparedImage::beautyOf(film, kHairAlphaLayer);
        const ComparedImage reference = readComparedImage(job.referenceImage);
        m.image = compareImages(beauty, reference);
        m.imageBlocks = compareImages(beauty.boxFiltered(kAccuracyBlock),
                                      reference.boxFiltered(kAccuracyBlock));
    }
    film = Film();
    if (job.probePoints > 0 && !job.probeFiles.empty()) {
        const std::vector<GlobalTermQuery> points = probePointsOf(scene, job, nullptr);
        m.probe = meanProbeError(probeTerms(scene, options, points),
                                 readProbeTerms(job.probeFiles.front()), job.probeFiles.front());
    }
    return m;
}

} // namespace hairvox::bench
