#!/usr/bin/python3
"""Plots of a `hairvox bench` sweep, drawn with matplotlib.

    plot_sweep.py OUT_DIR

reads OUT_DIR/results.csv (one row per measured configuration) and
OUT_DIR/scaling_fits.csv (the least-squares growth fits the sweep computed),
and writes

    OUT_DIR/runtime_vs_error.png   end-to-end time against image error, per scene,
                                   with each scene's Pareto front
    OUT_DIR/scaling.png            stage times against segment count, image size and
                                   active voxels, with the fitted power laws
    OUT_DIR/frontier.png           the model sweep's time against error, a panel per
                                   scene and hair colour: dual scattering, the volumetric
                                   integrator over its budgets, the path tracer over its
                                   samples, per pixel and over block means

The benchmark (bench/sweep) calls it after writing the CSV files; it can be
rerun by hand on a results directory. Only reads the CSVs: every number is the
sweep's.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.patches  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

MARKERS = {"exact": "o", "grid": "s", "approx": "^"}
# Marker fill per shading rate: fragment solid, adaptive pale, vertex hollow.
FILL = {"fragment": 1.0, "adaptive": 0.3, "vertex": 0.0}
STAGES = [("total", "total_s"), ("voxelize", "voxelize_s"), ("global term", "global_term_s"),
          ("lights' preparation", "global_term_prepare_s"), ("raster+shade", None)]
# Scaling kinds: (sweep, x axis label, title, size of a row).
SCALING = [("segments", "segments", "segment count", lambda r: number(r, "segments")),
           ("pixels", "pixels", "image size", lambda r: number(r, "width") * number(r, "height")),
           ("voxels", "active voxels", "active voxels (one groom, finer voxels)",
            lambda r: number(r, "active_voxels"))]


def number(row, key):
    value = row.get(key, "")
    return float(value) if value not in ("", None) else None


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def pareto(points):
    front = []
    for t, e in sorted(points):
        if not front or e < front[-1][1]:
            front.append((t, e))
    return front


def short_label(row):
    if row["mode"] == "exact":
        return "e" + row["rays"]
    return ("g" if row["mode"] == "grid" else "a") + "%g" % float(row["voxel_scale"])


def plot_runtime_vs_error(rows, path):
    accuracy = [r for r in rows if r["sweep"] == "accuracy" and number(r, "rel_l1")]
    if not accuracy:
        return False
    reference = next((r for r in rows if r["sweep"] == "reference"), None)
    against = " vs exact K=%s" % reference["rays"] if reference else ""
    # Per pixel, and over 4x4-pixel block means where the reference's noise
    # averages out; the dashed line per scene is the reference's own noise
    # floor: an error on or under it is not resolved.
    panels = [("rel_l1", "noise_floor_l1", "per pixel"),
              ("block_rel_l1", "block_noise_floor_l1", "over 4×4-pixel block means")]
    fig, axes = plt.subplots(1, 2, figsize=(14, 6.5), dpi=110, sharex=True)
    scenes = list(dict.fromkeys(r["scene"] for r in accuracy))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for ax, (key, floor_key, title) in zip(axes, panels):
        for i, scene in enumerate(scenes):
            colour = colours[i % len(colours)]
            points = []
            floors = []
            for r in (r for r in accuracy if r["scene"] == scene and number(r, key)):
                t, e = number(r, "total_s"), number(r, key)
                fill = FILL.get(r["shading_rate"], 0.0)
                face = matplotlib.colors.to_rgba(colour, fill) if fill > 0 else "none"
                ax.scatter([t], [e], marker=MARKERS.get(r["mode"], "o"), s=42,
                           facecolors=face, edgecolors=colour, zorder=3)
                ax.annotate(short_label(r), (t, e), textcoords="offset points", xytext=(4, 3),
                            fontsize=7, color=colour)
                points.append((t, e))
                if number(r, floor_key):
                    floors.append(number(r, floor_key))
            if not points:
                continue
            front = pareto(points)
            ax.plot([p[0] for p in front], [p[1] for p in front], color=colour, lw=1.2,
                    label=scene)
            if floors:
                ax.axhline(sorted(floors)[len(floors) // 2], color=colour, lw=0.9, ls="--")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("end-to-end time, s")
        ax.set_ylabel("relative L1 error of the beauty over hair pixels" + against)
        ax.set_title(title + " (dashed: the reference's noise floor)", fontsize=10)
        ax.grid(True, which="both", color="#e4e4e4", lw=0.6)
    fig.suptitle("hairvox: run time against image error")
    legend = [plt.Line2D([], [], ls="", marker=m, color="gray", label=f"{k}")
              for k, m in MARKERS.items()]
    first = axes[0].legend(loc="upper right", fontsize=8, title="scene (line: Pareto front)")
    axes[0].add_artist(first)
    axes[1].legend(handles=legend + [plt.Line2D([], [], ls="", marker="o", mfc="none",
                                                color="gray", label="hollow: vertex shading"),
                                 plt.Line2D([], [], ls="", marker="o",
                                            mfc=matplotlib.colors.to_rgba("gray", FILL["adaptive"]),
                                            color="gray", label="pale: adaptive shading")],
                   loc="upper right", fontsize=8, title="eK: K rays; gS/aS: voxel S·h0")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return True


def plot_scaling(rows, fits, path):
    kinds = [k for k in SCALING if any(r["sweep"] == k[0] for r in rows)]
    if not kinds:
        return False
    fig, axes = plt.subplots(1, len(kinds), figsize=(7 * len(kinds), 5.2), dpi=120, squeeze=False)
    for ax, (kind, xlabel, title, size) in zip(axes[0], kinds):
        series = [r for r in rows if r["sweep"] == kind]
        x = [size(r) for r in series]
        for name, column in STAGES:
            y = [number(r, column) if column else number(r, "raster_s") + number(r, "shade_s")
                 for r in series]
            fit = next((f for f in fits if f["kind"] == kind and f["stage"] == name), None)
            label = name + (" k=%.2f" % float(fit["exponent"]) if fit else "")
            points = ax.plot(x, y, "o", ms=5, label=label)[0]
            if fit:
                lo, hi = min(x), max(x)
                c, k = float(fit["coefficient"]), float(fit["exponent"])
                ax.plot([lo, hi], [c * lo ** k, c * hi ** k], color=points.get_color(), lw=1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("seconds")
        ax.set_title("time against " + title)
        ax.grid(True, which="both", color="#e4e4e4", lw=0.6)
        ax.legend(fontsize=8, title="lines: cost = c·size^k")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return True


def split_cell(label):
    """'wavy (default scene), blond' -> ('wavy (default scene)', 'blond')."""
    scene, _, hair = label.rpartition(", ")
    return (scene, hair) if scene else (label, "")


def plot_frontier(rows, path):
    """Time against the hair's error with the reference's noise removed, one
    panel per scene (row) and hair colour (column). Solid lines and filled
    markers: per pixel; dashed and hollow: over block means. Dotted: the
    reference's own floor (per pixel, blocks); an error below it is not
    resolved. The grey band is the 5% target."""
    model = [r for r in rows if r["sweep"] == "model" and number(r, "rel_l1_noise_removed")
             is not None]
    if not model:
        return False
    references = {r["scene"]: r for r in rows if r["sweep"] == "path_reference"}
    cells = list(dict.fromkeys(r["scene"] for r in model))
    scenes = list(dict.fromkeys(split_cell(c)[0] for c in cells))
    hairs = list(dict.fromkeys(split_cell(c)[1] for c in cells))
    fig, axes = plt.subplots(len(scenes), len(hairs), figsize=(5.2 * len(hairs), 4.4 * len(scenes)),
                             dpi=100, squeeze=False, sharex=True, sharey=True)
    colours = {"exact": "#7f7f7f", "grid": "#1f77b4", "approx": "#9467bd",
               "volumetric": "#d62728", "path": "#2ca02c"}
    lowest = 1e-3  # errors at or under it (fully within the noise) are drawn here
    block = next((r["block"] for r in model if r.get("block")), "")
    for cell in cells:
        scene, hair = split_cell(cell)
        ax = axes[scenes.index(scene)][hairs.index(hair)]
        mine = [r for r in model if r["scene"] == cell]
        for key, style, fill in (("rel_l1_noise_removed", "-", True),
                                 ("block_rel_l1_noise_removed", "--", False)):
            for method in ("exact", "grid", "approx", "volumetric", "path"):
                series = sorted((number(r, "total_s"), max(number(r, key) or 0.0, lowest), r)
                                for r in mine if r["mode"] == method and number(r, key)
                                is not None)
                if not series:
                    continue
                colour = colours[method]
                marker = MARKERS.get(method, "o" if method == "path" else "D")
                ax.plot([p[0] for p in series], [p[1] for p in series], ls=style if
                        len(series) > 1 else "", marker=marker, color=colour, ms=5,
                        mfc=colour if fill else "none", lw=1.1)
                for t, e, r in series if fill else ():
                    text = (r["spp"] if method == "path" else
                            "%g" % float(r["paths_per_cell"]) if method == "volumetric" else "")
                    if text:
                        ax.annotate(text, (t, e), textcoords="offset points", xytext=(3, 3),
                                    fontsize=7, color=colour)
        reference = references.get(cell)
        floors = [number(r, k) for r in mine[:1] for k in ("noise_floor_l1", "block_noise_floor_l1")]
        for floor in floors:
            if floor:
                ax.axhline(floor, color="#bbbbbb", lw=0.8, ls=":")
        ax.axhspan(lowest, 0.05, color="#f2f2f2", zorder=0)
        title = cell + (" — reference %s spp, %.0f s" % (reference["spp"],
                                                          number(reference, "total_s"))
                        if reference else "")
        ax.set_title(title, fontsize=9)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, which="both", color="#e4e4e4", lw=0.6)
    for ax in axes[-1]:
        ax.set_xlabel("end-to-end time, s")
    for row in axes:
        row[0].set_ylabel("rel L1 of the hair, noise removed")
    handles = [plt.Line2D([], [], color=c, marker=MARKERS.get(m, "o" if m == "path" else "D"),
                          ls="", label={"path": "path tracing (label: spp)",
                                        "volumetric": "volumetric (label: paths/cell)"}.get(
                              m, "dual scattering, " + m)) for m, c in colours.items()]
    handles += [plt.Line2D([], [], color="gray", ls="-", marker="o", label="per pixel"),
                plt.Line2D([], [], color="gray", ls="--", marker="o", mfc="none",
                           label="over %s×%s-pixel block means" % (block, block)),
                plt.Line2D([], [], color="#bbbbbb", ls=":", label="reference's noise floor"),
                matplotlib.patches.Patch(color="#f2f2f2", label="within 5%")]
    fig.legend(handles=handles, loc="lower center", ncol=5, fontsize=8)
    fig.suptitle("hairvox: time against error of each method (the path tracer's own error "
                 "is its noise)")
    fig.tight_layout(rect=(0, 0.06, 1, 0.97))
    fig.savefig(path)
    plt.close(fig)
    return True


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: plot_sweep.py OUT_DIR")
    out = sys.argv[1]
    rows = read_csv(os.path.join(out, "results.csv"))
    fits_path = os.path.join(out, "scaling_fits.csv")
    fits = read_csv(fits_path) if os.path.exists(fits_path) else []
    # Written under temporary names and renamed: a plot is never half-written.
    for name, draw in (("runtime_vs_error.png", lambda p: plot_runtime_vs_error(rows, p)),
                       ("scaling.png", lambda p: plot_scaling(rows, fits, p)),
                       ("frontier.png", lambda p: plot_frontier(rows, p))):
        final = os.path.join(out, name)
        tmp = os.path.join(out, "." + name + ".tmp.png")
        if draw(tmp):
            os.replace(tmp, final)
            print(final)


if __name__ == "__main__":
    main()
