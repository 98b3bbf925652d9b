#!/usr/bin/python3
"""Slices of the fiber grid and of the global term toward a light.

The default scene's groom splatted into its fiber grid, and the dual-
scattering global term toward its back light at every active voxel
(hairvox.transmittance). Three slices through the head's middle plane
(x = 0, the profile): the fiber length density λ, the direct visibility V
toward the light (the fraction of light that reaches the voxel through the
hair unscattered: 1 at the hair's lit surface, falling to 0 inside it and
behind the head) and the forward-scattered transmittance T_s (light that
reaches it scattered forward by the fibers in front: it peaks a few fibers
deep, where V has fallen and the forward scattering has built up). λ is laid out in
numpy from the voxels' coordinates; V is read through Debian's pyopenvdb
(LitGrid.to_openvdb(), copyToArray), the grids a .vdb would hold.

    /usr/bin/python3 examples/grid_slices.py [--out out/grid_slices.png] [--light back]
"""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import hairvox  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/grid_slices.png", help="the figure (PNG)")
    parser.add_argument("--light", default="back", help="a light of the default scene")
    args = parser.parse_args()

    lit = hairvox.transmittance(None, light=args.light)  # None: the default scene
    grid = lit.fiber_grid
    ijk = grid.ijk
    print(f"{len(grid):,} active voxels of {grid.voxel_size:.4g} m; light {lit.light}")

    # The slice x = 0: the voxels with i == 0, laid out over (j, k).
    lo, hi = ijk.min(axis=0), ijk.max(axis=0)
    shape = (hi[1] - lo[1] + 1, hi[2] - lo[2] + 1)
    on = ijk[:, 0] == 0
    j, k = ijk[on, 1] - lo[1], ijk[on, 2] - lo[2]

    density = np.full(shape, np.nan, np.float32)
    density[j, k] = grid.density[on]
    t_s = np.full(shape, np.nan, np.float32)
    t_s[j, k] = lit.T_s[on].mean(axis=1)

    # V through pyopenvdb: its dense copy of the slice (the background, 1,
    # where no voxel is active), then masked to the hair.
    vdb = lit.to_openvdb()
    dense = np.ones((1, *shape), np.float32)
    vdb["V"].copyToArray(dense, ijk=(0, int(lo[1]), int(lo[2])))
    visibility = np.where(np.isnan(density), np.nan, dense[0])

    h = grid.voxel_size
    extent = [lo[2] * h, (hi[2] + 1) * h, lo[1] * h, (hi[1] + 1) * h]  # z, y in metres
    fig, axes = plt.subplots(1, 3, figsize=(9.0, 4.2), dpi=110, constrained_layout=True)
    panels = [
        (density, "fiber length density λ (1/m²)", "magma", None),
        (visibility, f"direct visibility V toward '{args.light}'", "gray", (0, 1)),
        (t_s, "forward transmittance T_s (mean of RGB)", "viridis", None),
    ]
    for ax, (values, title, cmap, limits) in zip(axes, panels):
        image = ax.imshow(values, origin="lower", extent=extent, cmap=cmap,
                          vmin=limits[0] if limits else None, vmax=limits[1] if limits else None)
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("z (m, toward the face)", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.set_facecolor("#d8d8e0")
        fig.colorbar(image, ax=ax, shrink=0.8).ax.tick_params(labelsize=7)
    axes[0].set_ylabel("y (m, up)", fontsize=8)
    direction = lit.light.get("direction")
    fig.suptitle(f"hairvox {hairvox.__version__}: the default scene's fiber grid at x = 0 and its "
                 f"global term toward the light from {np.round(direction, 2).tolist()} "
                 f"({lit.mode} mode)", fontsize=9)
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
