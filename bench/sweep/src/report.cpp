#include "report.h"

#include "text.h"

#include <hairvox/core/error.h>
#include <hairvox/core/format.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>

namespace hairvox::bench {

namespace {

std::string utcNow() {
    const std::time_t now = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buf[64];
    std::strftime(buf, sizeof(buf), "%Y-%m-%d %H:%M UTC", &tm);
    return buf;
}

std::string csvNumber(double v) {
    return format("%.6g", v);
}
std::string csvOptional(const std::optional<double>& v) {
    return v ? csvNumber(*v) : "";
}

std::string mdOptional(const std::optional<double>& v, int digits) {
    return v ? format("%.*f", digits, *v) : "–";
}

std::string imageSize(const BenchRow& r) {
    return strCat(r.width, "×", r.height);
}

const BenchRow* findRow(const std::vector<BenchRow>& rows, const std::string& scene,
                        const std::function<bool(const BenchRow&)>& pred) {
    for (const BenchRow& r : rows)
        if (r.scene == scene && pred(r))
            return &r;
    return nullptr;
}

std::vector<std::string> sceneOrder(const std::vector<BenchRow>& rows, BenchSweepKind kind) {
    std::vector<std::string> order;
    for (const BenchRow& r : rows)
        if (r.kind == kind && std::find(order.begin(), order.end(), r.scene) == order.end())
            order.push_back(r.scene);
    return order;
}

const char* stageHeader() {
    return "| total s | load | voxelize | tables | global term | raster | shade | write | peak MiB "
           "|";
}

std::string stageCells(const BenchMeasurement& m) {
    const StageTimes& t = m.times;
    return strCat(" ", seconds(m.totalSeconds), " | ", seconds(t.load), " | ", seconds(t.voxelize),
                  " | ", seconds(t.tables), " | ", seconds(t.globalTerm), " | ", seconds(t.raster),
                  " | ", seconds(t.shade), " | ", seconds(t.write), " | ", mdOptional(m.peakMiB, 0),
                  " |");
}

std::string fitText(const char* what, const std::optional<PowerLawFit>& f) {
    if (!f)
        return strCat(what, " –");
    return strCat(what, " k = ", format("%.2f", f->exponent), " (R² ", format("%.3f", f->r2), ")");
}

/// "~0.0123": the error with the reference's noise removed, marked when it is
/// within 1.5× that noise (not resolved); "–" when not measured.
std::string removedText(const std::optional<ImageError>& e) {
    if (!e)
        return "–";
    return strCat(e->resolved() ? "" : "~", format("%.4f", e->relL1NoiseRemoved));
}

/// The model sweep's table: per scene and hair colour, the path-traced
/// reference, then one row per method (dual scattering's modes, the volumetric
/// integrator at its budgets, the path tracer at fewer samples).
std::string modelMarkdown(const SweepOptions& o, const std::vector<BenchRow>& rows) {
    const std::vector<std::string> scenes = sceneOrder(rows, BenchSweepKind::PathReference);
    if (scenes.empty())
        return {};
    std::string md = "## Model error: dual scattering and volumetric against path tracing\n\n";
    md += strCat(
        "The hair's radiance (the beauty without head and background) of each global-term mode, "
        "of the volumetric integrator (docs/DESIGN.md §9) at its budgets and of the path tracer "
        "at fewer samples (seeded apart from the reference) against a path trace of the same "
        "fibers with the same f_s (docs/DESIGN.md §8), per pixel and as means over ",
        o.model.block, "×", o.model.block,
        " pixel blocks. `floor`: the relative L1 the reference's own noise gives (from its "
        "two independent halves); `noise removed`: sqrt(L1² − floor²) — an error within 1.5× "
        "its floor is not resolved (marked ~). `bias`: signed, over the blocks, the estimate "
        "brighter when positive. Target: within 0.05 over the blocks with the noise removed. "
        "frontier.png plots time against both errors.\n\n");
    md += "| scene, hair | method | s | pixels: rel L1 | floor | noise removed | blocks: rel L1 "
          "| floor | noise removed | bias | spp | Mrays/s | Mpaths/s |\n";
    md += "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const std::string& s : scenes) {
        for (const BenchRow& r : rows) {
            if (r.scene != s ||
                (r.kind != BenchSweepKind::Model && r.kind != BenchSweepKind::PathReference))
                continue;
            const bool reference = r.kind == BenchSweepKind::PathReference;
            const PathTraceStats* pt = r.m.pathTrace ? &*r.m.pathTrace : nullptr;
            const auto errors = [](const std::optional<ImageError>& e) {
                return e ? strCat(format("%.4f", e->relL1), " | ", format("%.4f", e->noiseFloorL1),
                                  " | ", removedText(e))
                         : std::string("– | – | –");
            };
            md += strCat("| ", s, " | ",
                         reference ? strCat("path ", pt ? pt->spp : 0u, " spp (reference)")
                         : r.config.integrator == Integrator::DualScattering ? r.config.method()
                                                                             : r.config.label(),
                         " | ", seconds(r.m.totalSeconds), " | ", errors(r.m.image), " | ",
                         errors(r.m.imageBlocks), " | ",
                         r.m.imageBlocks ? format("%+.4f", r.m.imageBlocks->relBias) : "–", " | ",
                         pt ? std::to_string(pt->spp) : "–", " | ",
                         pt ? format("%.2f", pt->raysPerSecond() * 1e-6) : "–", " | ",
                         pt ? format("%.3f", pt->pathsPerSecond() * 1e-6) : "–", " |\n");
        }
    }
    return md + "\n";
}

} // namespace

RunInfo RunInfo::now() {
    RunInfo info;
    info.started = utcNow();
    info.loadStart = info.loadMax = loadAverage(); // before the calibration's own load
    info.host = HostReport::measure();
    return info;
}

std::string hostJsonText(const RunInfo& info) {
    const HostReport& h = info.host;
    const MachineCalibration& c = h.calibration;
    const nlohmann::ordered_json j = {
        {"cpu_model", h.host.cpuModel},
        {"logical_cores", h.host.logicalCores},
        {"simd_target", h.simdTarget},
        {"simd_fma_flops_per_second", h.simdFmaFlopsPerSecond},
        {"dram_bytes_per_second", c.dramBytesPerSecond},
        {"miss_latency_ns", c.missLatencyNs},
        {"baseline_flops_per_second", c.baselineFlopsPerSecond},
        {"calibration_array_bytes", c.arrayBytes},
        {"calibration_seconds", c.seconds},
        {"started", info.started},
        {"load_average",
         {{"start", info.loadStart}, {"max", info.loadMax}, {"end", info.loadEnd}}}};
    return j.dump(2) + "\n";
}

double loadAverage() {
    double load[3] = {0, 0, 0};
    return getloadavg(load, 3) >= 1 ? load[0] : 0.0;
}

std::string csvText(const std::vector<BenchRow>& rows) {
    std::string out;
    for (std::size_t i = 0; i < kBenchCsvColumns.size(); ++i)
        out += std::string(i ? "," : "") + kBenchCsvColumns[i];
    out += "\n";
    for (const BenchRow& r : rows) {
        const BenchMeasurement& m = r.m;
        const StageTimes& t = m.times;
        const std::vector<std::string> cells = {
            toString(r.kind),
            r.scene,
            r.config.method(),
            csvNumber(r.config.voxelScale),
            csvNumber(m.voxelSize),
            r.config.mode == GlobalTermMode::Exact ? std::to_string(r.config.rays) : "",
            toString(r.config.shadingRate),
            std::to_string(r.width),
            std::to_string(r.height),
            std::to_string(m.segments),
            std::to_string(m.runs),
            csvNumber(t.load),
            csvNumber(t.voxelize),
            csvNumber(t.tables),
            csvNumber(t.globalTerm),
            csvNumber(t.raster),
            csvNumber(t.shade),
            csvNumber(t.write),
            csvNumber(m.totalSeconds),
            csvOptional(m.peakMiB),
            std::to_string(m.shadingPoints),
            std::to_string(m.activeVoxels),
            csvOptional(m.image ? std::optional(m.image->relL1) : std::nullopt),
            csvOptional(m.image ? std::optional(m.image->relRmse) : std::nullopt),
            csvOptional(m.probe ? std::optional(m.probe->maeV) : std::nullopt),
            csvOptional(m.probe ? std::optional(m.probe->maeT_s) : std::nullopt),
            csvOptional(r.eumelanin ? std::optional(double(*r.eumelanin)) : std::nullopt),
            csvOptional(m.image ? std::optional(m.image->relBias) : std::nullopt),
            csvOptional(m.image ? std::optional(m.image->noiseFloorL1) : std::nullopt),
            csvOptional(m.image ? std::optional(m.image->relL1NoiseRemoved) : std::nullopt),
            m.pathTrace ? std::to_string(m.pathTrace->spp) : "",
            csvOptional(m.pathTrace ? std::optional(m.pathTrace->raysPerSecond()) : std::nullopt),
            csvOptional(m.pathTrace ? std::optional(m.pathTrace->pathsPerSecond()) : std::nullopt),
            csvOptional(m.imageBlocks ? std::optional(m.imageBlocks->relL1) : std::nullopt),
            csvOptional(m.imageBlocks ? std::optional(m.imageBlocks->noiseFloorL1) : std::nullopt),
            csvOptional(m.imageBlocks ? std::optional(m.imageBlocks->relL1NoiseRemoved)
                                      : std::nullopt),
            csvNumber(m.prepareSeconds),
            r.config.integrator == Integrator::Volumetric ? csvNumber(r.config.pathsPerCell) : "",
            r.block > 0 ? std::to_string(r.block) : ""};
        for (std::size_t i = 0; i < cells.size(); ++i) {
            // Scene labels are the only free text: quote them if they need it.
            const bool quote = cells[i].find_first_of(",\"\n") != std::string::npos;
            std::string cell = cells[i];
            if (quote) {
                std::string escaped;
                for (char c : cell)
                    escaped += c == '"' ? std::string("\"\"") : std::string(1, c);
                cell = "\"" + escaped + "\"";
            }
            out += (i ? "," : "") + cell;
        }
        out += "\n";
    }
    return out;
}

/// Fixed-point with `digits` decimals, "–" when there is no value.
std::string configText(const BenchRow& r) {
    if (r.kind == BenchSweepKind::Reference)
        return strCat("exact K=", r.config.rays, " (reference)");
    if (r.kind == BenchSweepKind::PathReference)
        return strCat("path tracing", r.m.pathTrace ? strCat(" ", r.m.pathTrace->spp, " spp") : "",
                      " (reference)");
    return r.config.label();
}

std::string markdownText(const SweepOptions& o, const SweepResult& result, const RunInfo& info) {
    const std::vector<BenchRow>& rows = result.rows;
    std::string md = "# hairvox benchmark: run time against error, and how cost grows\n\n";
    md += strCat(
        "Generated by `", o.commandLine.empty() ? std::string("hairvox bench") : o.commandLine,
        "`, started ", info.started, ".\n\nHost: ", info.host.line(),
        "; in host.json.\n\nLoad average (1 min) ", format("%.1f", info.loadStart),
        " at the start, at most ", format("%.1f", info.loadMax), ", ", format("%.1f", info.loadEnd),
        " at the end (the machine may be shared: times are wall clock).\n\n");
    md += strCat("Times are seconds, end to end through `renderScene()` including writing the EXR "
                 "and PNG; each stage is the median of ",
                 o.runs, o.runs == 1 ? " run" : " runs",
                 " and `total` the median of the totals (the exact reference: one run",
                 o.singleRunAbove > 0 && o.runs > 1
                     ? strCat("; a configuration whose first run takes over ",
                              format("%g", o.singleRunAbove), " s: one run")
                     : std::string(),
                 "). "
                 "Peak MiB is the resident peak of a process that ran that configuration alone. "
                 "Errors are against an exact-mode render with K rays per shading point spread "
                 "over a disk of one default voxel h0 (the scene's grid voxel size): relative L1 "
                 "and relative RMSE of the beauty over hair pixels; MAE(V) and MAE(T_s) at ",
                 o.probePoints, " points on the fibers toward each light, against exact mode with ",
                 o.probeRays,
                 " rays over a disk of the configuration's voxel size. `grid xS`/`approx xS`: "
                 "voxel size S·h0; `exact K=n`: n rays over the h0 disk. The image reference "
                 "is itself noisy (a few rays per shading point): it is rendered as two "
                 "independent halves of K/2 rays (different seeds), and the rel L1 its noise "
                 "alone gives (`floor`) is measured from them and removed from every error "
                 "(`noise removed` = sqrt(L1² − floor²), film/image_compare.h); an error within "
                 "1.5× the floor is not resolved and is marked ~. The same errors over the means "
                 "of ",
                 kAccuracyBlock, "×", kAccuracyBlock, " pixel blocks (`", kAccuracyBlock, "×",
                 kAccuracyBlock,
                 " blocks`), where the reference's per-pixel noise averages "
                 "out and an error that is there at that scale does not, resolve what the pixels "
                 "cannot.\n\n");

    const std::vector<std::string> scenes = sceneOrder(rows, BenchSweepKind::Reference);
    if (!scenes.empty()) {
        const ShadingRate rate = o.shadingRates.front();
        const std::uint32_t fewestRays =
            o.exactRays.empty() ? 0 : *std::min_element(o.exactRays.begin(), o.exactRays.end());
        md += strCat("## Summary (", toString(rate), " shading)\n\n");
        md += strCat(
            "| scene | segments | image | h0 | exact reference s | exact K=", fewestRays,
            " s | grid x1 s | grid speed-up: global term, total | grid x1 rel L1 | "
            "noise removed | floor | ",
            kAccuracyBlock, "×", kAccuracyBlock,
            " blocks: noise removed | floor | MAE(V) | MAE(T_s) | approx within grid's time | "
            "its rel L1 | noise removed | ",
            kAccuracyBlock, "×", kAccuracyBlock, " blocks |\n");
        md += "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|"
              "---:|---:|\n";
        for (const std::string& s : scenes) {
            const BenchRow* ref = findRow(
                rows, s, [](const BenchRow& r) { return r.kind == BenchSweepKind::Reference; });
            const auto accuracy = [&](const BenchRow& r) {
                return r.kind == BenchSweepKind::Accuracy && r.config.shadingRate == rate;
            };
            const BenchRow* exact = findRow(rows, s, [&](const BenchRow& r) {
                return accuracy(r) && r.config.mode == GlobalTermMode::Exact &&
                       r.config.rays == fewestRays;
            });
            const BenchRow* grid = findRow(rows, s, [&](const BenchRow& r) {
                return accuracy(r) && r.config.mode == GlobalTermMode::Grid &&
                       r.config.voxelScale == 1.0;
            });
            std::string line = strCat("| ", s, " | ", ref ? thousands(ref->m.segments) : "–", " | ",
                                      ref ? imageSize(*ref) : "–", " | ",
                                      ref ? format("%.3g", ref->m.defaultVoxelSize) : "–", " | ",
                                      ref ? seconds(ref->m.totalSeconds) : "–", " | ",
                                      exact ? seconds(exact->m.totalSeconds) : "–", " | ",
                                      grid ? seconds(grid->m.totalSeconds) : "–", " | ");
            if (grid && exact && grid->m.times.globalTerm > 0 && grid->m.totalSeconds > 0)
                line +=
                    strCat(format("%.1f×", exact->m.times.globalTerm / grid->m.times.globalTerm),
                           ", ", format("%.1f×", exact->m.totalSeconds / grid->m.totalSeconds));
            else
                line += "–";
            const auto relL1 = [](const BenchRow* r) {
                return r && r->m.image ? std::optional(r->m.image->relL1) : std::nullopt;
            };
            const auto removed = [&](const BenchRow* r) {
                return r ? removedText(r->m.image) : std::string("–");
            };
            const auto removedBlocks = [&](const BenchRow* r) {
                return r ? removedText(r->m.imageBlocks) : std::string("–");
            };
            const auto floorOf = [](const std::optional<ImageError>& e) {
                return e ? std::optional(e->noiseFloorL1) : std::nullopt;
            };
            line += strCat(
                " | ", mdOptional(relL1(grid), 4), " | ", removed(grid), " | ",
                mdOptional(grid ? floorOf(grid->m.image) : std::nullopt, 4), " | ",
                removedBlocks(grid), " | ",
                mdOptional(grid ? floorOf(grid->m.imageBlocks) : std::nullopt, 4), " | ",
                mdOptional(
                    grid && grid->m.probe ? std::optional(grid->m.probe->maeV) : std::nullopt, 4),
                " | ",
                mdOptional(
                    grid && grid->m.probe ? std::optional(grid->m.probe->maeT_s) : std::nullopt, 4),
                " | ");
            // Approx at the grid's time budget: the most accurate approx
            // configuration no slower than grid x1 (else the fastest one).
            const BenchRow* approx = nullptr;
            bool withinBudget = false;
            for (const BenchRow& r : rows) {
                if (r.scene != s || !accuracy(r) || r.config.mode != GlobalTermMode::Approx ||
                    !r.m.image)
                    continue;
                const bool within = grid && r.m.totalSeconds <= grid->m.totalSeconds;
                if (within && (!withinBudget || r.m.image->relL1 < approx->m.image->relL1)) {
                    approx = &r;
                    withinBudget = true;
                } else if (!withinBudget &&
                           (!approx || r.m.totalSeconds < approx->m.totalSeconds)) {
                    approx = &r;
                }
            }
            line += approx ? strCat(approx->config.label(), " (", seconds(approx->m.totalSeconds),
                                    " s", withinBudget ? "" : ", none was as fast", ")")
                           : std::string("–");
            line += strCat(" | ", mdOptional(relL1(approx), 4), " | ", removed(approx), " | ",
                           removedBlocks(approx), " |\n");
            md += line;
        }
        md += "\n";
    }

    for (const std::string& s : scenes) {
        const BenchRow* ref =
            findRow(rows, s, [](const BenchRow& r) { return r.kind == BenchSweepKind::Reference; });
        md += strCat("## ", s, "\n\n");
        if (ref)
            md += strCat(thousands(ref->m.segments), " segments, ", imageSize(*ref),
                         ", h0 = ", format("%.4g", ref->m.defaultVoxelSize), "\n\n");
        md += strCat("| configuration | voxel or radius | shading ", stageHeader(),
                     " rel L1 | rel RMSE | ", kAccuracyBlock, "×", kAccuracyBlock,
                     " blocks: rel L1 | noise removed | MAE(V) | MAE(T_s) |\n");
        md += "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
              "---:|\n";
        for (const BenchRow& r : rows) {
            if (r.scene != s ||
                (r.kind != BenchSweepKind::Reference && r.kind != BenchSweepKind::Accuracy))
                continue;
            const BenchMeasurement& m = r.m;
            md += strCat(
                "| ", configText(r), " | ", format("%.3g", m.voxelSize), " | ",
                toString(r.config.shadingRate), " |", stageCells(m), " ",
                mdOptional(m.image ? std::optional(m.image->relL1) : std::nullopt, 4), " | ",
                mdOptional(m.image ? std::optional(m.image->relRmse) : std::nullopt, 4), " | ",
                mdOptional(m.imageBlocks ? std::optional(m.imageBlocks->relL1) : std::nullopt, 4),
                " | ",
                m.imageBlocks ? strCat(m.imageBlocks->resolved() ? "" : "~",
                                       format("%.4f", m.imageBlocks->relL1NoiseRemoved))
                              : std::string("–"),
                " | ", mdOptional(m.probe ? std::optional(m.probe->maeV) : std::nullopt, 4), " | ",
                mdOptional(m.probe ? std::optional(m.probe->maeT_s) : std::nullopt, 4), " |\n");
        }
        md += "\n";
    }

    md += modelMarkdown(o, rows);

    for (const ScalingFit& fit : result.fits) {
        const BenchSweepKind kind = fit.kind;
        const char* x = kind == BenchSweepKind::Segments ? "segments"
                        : kind == BenchSweepKind::Pixels ? "pixels"
                                                         : "active voxels";
        if (kind == BenchSweepKind::Voxels) {
            md += "## Scaling with active voxels (one groom, grid mode, decreasing voxel sizes, "
                  "fragment shading)\n\n";
            md += strCat("| scene | voxel size | active voxels | lights' preparation s ",
                         stageHeader(), "\n");
            md += "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
        } else {
            md += strCat("## Scaling with ",
                         kind == BenchSweepKind::Segments ? "segment count" : "image size",
                         " (grid mode, default voxel size, fragment shading)\n\n");
            md += strCat("| scene | segments | image ", stageHeader(), "\n");
            md += "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
        }
        for (const BenchRow& r : rows) {
            if (r.kind != kind)
                continue;
            if (kind == BenchSweepKind::Voxels)
                md += strCat("| ", r.scene, " | ", format("%.3g", r.m.voxelSize), " | ",
                             thousands(r.m.activeVoxels), " | ", seconds(r.m.prepareSeconds), " |",
                             stageCells(r.m), "\n");
            else
                md += strCat("| ", r.scene, " | ", thousands(r.m.segments), " | ", imageSize(r),
                             " |", stageCells(r.m), "\n");
        }
        md += strCat(
            "\nGrowth, least-squares fit of cost ∝ ", x, "^k: ", fitText("total time", fit.total),
            "; ", fitText("voxelize", fit.voxelize), "; ", fitText("global term", fit.globalTerm),
            "; ", fitText("of it the lights' preparation", fit.prepare), "; ",
            fitText("raster + shade", fit.rasterShade), "; ",
            fitText("peak memory", fit.peakMemory), ".\n\n");
    }
    return md;
}

std::vector<ScalingFit> fitScaling(const std::vector<BenchRow>& rows) {
    std::vector<ScalingFit> fits;
    for (const BenchSweepKind kind :
         {BenchSweepKind::Segments, BenchSweepKind::Pixels, BenchSweepKind::Voxels}) {
        std::vector<double> x, total, voxelize, globalTerm, prepare, rasterShade, memX, memory;
        for (const BenchRow& r : rows) {
            if (r.kind != kind)
                continue;
            const double size = kind == BenchSweepKind::Segments ? double(r.m.segments)
                                : kind == BenchSweepKind::Pixels
                                    ? double(r.width) * double(r.height)
                                    : double(r.m.activeVoxels);
            x.push_back(size);
            total.push_back(r.m.totalSeconds);
            voxelize.push_back(r.m.times.voxelize);
            globalTerm.push_back(r.m.times.globalTerm);
            prepare.push_back(r.m.prepareSeconds);
            rasterShade.push_back(r.m.times.raster + r.m.times.shade);
            if (r.m.peakMiB) {
                memX.push_back(size);
                memory.push_back(*r.m.peakMiB);
            }
        }
        if (x.empty())
            continue;
        ScalingFit fit;
        fit.kind = kind;
        fit.total = fitPowerLaw(x, total);
        fit.voxelize = fitPowerLaw(x, voxelize);
        fit.globalTerm = fitPowerLaw(x, globalTerm);
        fit.prepare = fitPowerLaw(x, prepare);
        fit.rasterShade = fitPowerLaw(x, rasterShade);
        fit.peakMemory = fitPowerLaw(memX, memory);
        fits.push_back(fit);
    }
    return fits;
}

std::string fitsCsvText(const std::vector<ScalingFit>& fits) {
    std::string out = "kind,stage,exponent,coefficient,r2\n";
    for (const ScalingFit& fit : fits) {
        const std::pair<const char*, const std::optional<PowerLawFit>*> stages[] = {
            {"total", &fit.total},
            {"voxelize", &fit.voxelize},
            {"global term", &fit.globalTerm},
            {"lights' preparation", &fit.prepare},
            {"raster+shade", &fit.rasterShade},
            {"peak memory", &fit.peakMemory}};
        for (const auto& [stage, f] : stages)
            if (*f)
                out +=
                    strCat(toString(fit.kind), ",", stage, ",", format("%.6g", (*f)->exponent), ",",
                           format("%.6g", (*f)->coefficient), ",", format("%.6g", (*f)->r2), "\n");
    }
    return out;
}

} // namespace hairvox::bench
