#!/usr/bin/python3
"""One groom rendered at five melanin concentrations, as a contact sheet.

The default scene's groom (20,000 wavy strands on the mannequin), rendered
with the fiber's eumelanin from platinum blond to black (pbrt's reference
values: 0.3 blond, 1.3 brown, 8 black) at the same exposure, above the
forward attenuation a_f(theta) of each fiber (hairvox.tables): the share of
light a fiber passes on forward, the quantity whose product along a shadow
path the voxel grid's global term estimates.

    /usr/bin/python3 examples/melanin_sweep.py [--out out/melanin_sweep.png] [--size 320]
"""

import argparse
import copy
import pathlib
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import hairvox  # noqa: E402

EUMELANIN = [0.1, 0.3, 1.3, 3.0, 8.0]
PHEOMELANIN = 0.2


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/melanin_sweep.png", help="the contact sheet (PNG)")
    parser.add_argument("--size", type=int, default=320, help="pixels a side of each render")
    args = parser.parse_args()

    base = hairvox.default_scene()
    # One groom for every render: generated once, given to each scene in
    # memory; its fiber grid is splatted once and shared (FrameReuse: a new
    # colour keeps the grid, the lights are prepared for the new fibers).
    groom = hairvox.generate(**base["groom"]["procedural"])
    reuse = hairvox.FrameReuse()
    renders, tables = [], []
    for eumelanin in EUMELANIN:
        scene = copy.deepcopy(base)
        scene["groom"] = groom
        scene["fiber"]["melanin"] = {"eumelanin": eumelanin, "pheomelanin": PHEOMELANIN}
        start = time.monotonic()
        r = hairvox.render(scene, width=args.size, height=args.size, reuse=reuse)
        print(f"eumelanin {eumelanin:>4}: {time.monotonic() - start:.2f} s")
        renders.append(r.preview())
        tables.append(hairvox.tables(scene["fiber"]))

    fig = plt.figure(figsize=(2.2 * len(EUMELANIN), 3.9), dpi=110)
    grid = fig.add_gridspec(2, len(EUMELANIN), height_ratios=[2.2, 1.0], hspace=0.25)
    colors = plt.cm.copper(np.linspace(0.95, 0.0, len(EUMELANIN)))
    for i, (image, eumelanin) in enumerate(zip(renders, EUMELANIN)):
        ax = fig.add_subplot(grid[0, i])
        ax.imshow(image)
        ax.set_title(f"eumelanin {eumelanin}", fontsize=9, color=colors[i] * 0.8)
        ax.axis("off")
    ax = fig.add_subplot(grid[1, :])
    for t, eumelanin, color in zip(tables, EUMELANIN, colors):
        # The mean of R, G and B: one curve per fiber.
        ax.plot(np.degrees(t["theta"]), t["a_f"].mean(axis=1), color=color, label=str(eumelanin))
    ax.set_xlabel("incident inclination θ (degrees)", fontsize=8)
    ax.set_ylabel("ā_f (mean of RGB)", fontsize=8)
    ax.set_xlim(-90, 90)
    ax.tick_params(labelsize=7)
    ax.legend(title="eumelanin", fontsize=7, title_fontsize=7, loc="center left",
              bbox_to_anchor=(1.005, 0.5), frameon=False)
    fig.suptitle(f"hairvox {hairvox.__version__}: one groom, five melanin concentrations "
                 f"(pheomelanin {PHEOMELANIN}), dual scattering, grid global term", fontsize=9)
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, bbox_inches="tight")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
