"""Type stubs of the hairvox Python module (docs/python.md is its manual).

Conventions: bad input raises ValueError with the CLI's message (naming the
field and the valid range); internal errors RuntimeError; an interrupted long
call (Ctrl-C, _thread.interrupt_main(), hairvox.interrupt()) raises
KeyboardInterrupt. Arrays returned are read-only numpy views of memory the
returned object owns, unless a docstring says "a new array".
"""

import os
from collections.abc import Callable, Iterator, Mapping
from typing import Any, Literal, Optional, Union

import numpy as np
import numpy.typing as npt

__version__: str

PathLike = Union[str, "os.PathLike[str]"]
#: None, True (the CLI's progress bars on stderr) or a callable
#: (stage, done, total), called on the calling thread while the call runs.
ProgressArg = Union[None, bool, Callable[[str, int, int], Any]]
#: A scene: None (the embedded default scene), a scene file path, a dict in
#: the scene file's schema (docs/scene.md; a Groom may stand at "groom" or
#: "groom"/"file"), or a Groom alone (the default scene's settings).
SceneArg = Union[None, PathLike, Mapping[str, Any], "Groom"]

class HairvoxWarning(UserWarning):
    """What a call reports and goes on (the CLI's warnings)."""

class Groom:
    """Strands as polylines, root to tip, with optional per-point thickness
    (fiber diameter, scene units) and linear RGB colour. Immutable."""

    def __init__(
        self,
        points: npt.ArrayLike,
        strand_offsets: npt.ArrayLike,
        thickness: Optional[npt.ArrayLike] = None,
        colors: Optional[npt.ArrayLike] = None,
    ) -> None:
        """points (N, 3), strand_offsets (S + 1 integers from 0 to N), thickness
        (N,), colors (N, 3); validated as a groom file is (ValueError naming the
        field, strand and point); zero-length segments dropped with a warning."""
    @property
    def points(self) -> npt.NDArray[np.float32]:
        """(N, 3) float32, a read-only view."""
    @property
    def strand_offsets(self) -> npt.NDArray[np.uint32]:
        """(S + 1,) uint32: strand i is points[strand_offsets[i]:strand_offsets[i + 1]]."""
    @property
    def thickness(self) -> Optional[npt.NDArray[np.float32]]:
        """(N,) per-point fiber diameter, or None."""
    @property
    def colors(self) -> Optional[npt.NDArray[np.float32]]:
        """(N, 3) per-point linear RGB, or None."""
    @property
    def transparency(self) -> Optional[npt.NDArray[np.float32]]:
        """(N,) per-point transparency of a .hair file (not rendered), or None."""
    @property
    def strand_count(self) -> int: ...
    @property
    def point_count(self) -> int: ...
    @property
    def segment_count(self) -> int: ...
    def __len__(self) -> int:
        """The number of strands."""
    def strand(self, index: int) -> npt.NDArray[np.float32]:
        """The (n, 3) points of one strand, a read-only view."""
    def stats(self) -> dict[str, Any]:
        """strands, points, segments, bounds, total_length, segment lengths."""
    def save(self, path: PathLike) -> None:
        """Writes a Cem Yuksel .hair file (atomically)."""

def load_groom(path: PathLike) -> Groom:
    """Reads a .hair, .tfx or OBJ-polyline groom."""

def generate(style: Literal["straight", "wavy", "curly"] = "wavy", **params: Any) -> Groom:
    """A procedural groom; params are the scene schema's groom.procedural keys."""

class Layers(Mapping[str, npt.NDArray[np.float32]]):
    """Render.layers: EXR layer name -> float32 (height, width, channels), row 0
    at the top; "beauty" is RGBA, the AOVs keep their EXR names. Each array is
    laid out from the film on first access and viewed (no copy) after."""

    def __getitem__(self, name: str) -> npt.NDArray[np.float32]: ...
    def __iter__(self) -> Iterator[str]: ...
    def __len__(self) -> int: ...
    def __contains__(self, name: object) -> bool: ...
    def keys(self) -> list[str]: ...  # type: ignore[override]
    def values(self) -> list[npt.NDArray[np.float32]]: ...  # type: ignore[override]
    def items(self) -> list[tuple[str, npt.NDArray[np.float32]]]: ...  # type: ignore[override]
    def get(self, name: str, default: Any = None) -> Any: ...  # type: ignore[override]

class Render:
    """A finished render."""

    @property
    def layers(self) -> Layers: ...
    @property
    def report(self) -> dict[str, Any]:
        """times per stage, lights, raster or path_trace counts (what was skipped),
        the grid, warnings, and "text": the CLI's closing report."""
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def scene_name(self) -> str: ...
    @property
    def warnings(self) -> list[str]: ...
    def save(
        self,
        path: Optional[PathLike] = None,
        *,
        exr: Optional[PathLike] = None,
        png: Optional[PathLike] = None,
    ) -> list[str]:
        """Writes what `hairvox render` writes (the same bytes), atomically: the
        scene's outputs, or the one `path`'s extension names, or exr= / png=.
        Returns the paths written."""
    def preview(
        self, exposure: Optional[float] = None, tone_map: Optional[Literal["filmic", "clamp"]] = None
    ) -> npt.NDArray[np.uint8]:
        """The PNG preview's pixels, (height, width, 3) sRGB; a new array."""

class FrameReuse:
    """What consecutive renders given it share (the fiber grid, the lights'
    preparation) where unchanged; the images are the same bytes."""

    def __init__(self) -> None: ...

def render(
    scene: SceneArg = None,
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    integrator: Optional[str] = None,
    mode: Optional[Literal["exact", "grid", "approx"]] = None,
    spp: Optional[int] = None,
    seed: Optional[int] = None,
    threads: Optional[int] = None,
    progress: ProgressArg = None,
    reuse: Optional[FrameReuse] = None,
) -> Render:
    """Renders a scene (the GIL released); nothing is written until Render.save()."""

def default_scene() -> dict[str, Any]:
    """The embedded default scene as a dict in the scene file's schema."""

def read_exr(path: PathLike) -> dict[str, npt.NDArray[np.float32]]:
    """An EXR's layers, named as Render.layers names them."""

class FiberGrid:
    """The fiber grid's active voxels: arrays in one shared order."""

    @property
    def voxel_size(self) -> float: ...
    @property
    def active_voxel_count(self) -> int: ...
    def __len__(self) -> int: ...
    @property
    def ijk(self) -> npt.NDArray[np.int32]:
        """(N, 3) index coordinates; a voxel sits at ijk * voxel_size."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(N, 3) world positions; a new array."""
    @property
    def density(self) -> npt.NDArray[np.float32]:
        """(N,) fiber length per unit volume λ."""
    @property
    def orientation(self) -> npt.NDArray[np.float32]:
        """(N, 3) mean unit tangent E[u]."""
    @property
    def tensor_diag(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def tensor_off_diag(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def type_fractions(self) -> list[npt.NDArray[np.float32]]: ...
    @property
    def info(self) -> dict[str, Any]: ...
    @property
    def memory_bytes(self) -> int: ...
    @property
    def warnings(self) -> list[str]: ...
    def to_openvdb(self) -> dict[str, Any]:
        """The .vdb's grids as pyopenvdb grids (python3-openvdb), by name."""
    def save(self, path: PathLike) -> None: ...
    @staticmethod
    def load(path: PathLike) -> "FiberGrid": ...

def voxelize(
    groom: Union[Groom, PathLike],
    *,
    voxel_size: Optional[float] = None,
    voxels_across: Optional[int] = None,
    diameter: Optional[float] = None,
    density_multiplier: Optional[float] = None,
    orientation_tensor: Optional[bool] = None,
    memory_budget: Optional[float] = None,
    threads: Optional[int] = None,
    progress: ProgressArg = None,
) -> FiberGrid:
    """Splats a groom into a FiberGrid, as `hairvox voxelize` does."""

class LitGrid:
    """The global term toward one light at the fiber grid's active voxels."""

    @property
    def fiber_grid(self) -> FiberGrid: ...
    @property
    def ijk(self) -> npt.NDArray[np.int32]: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]: ...
    @property
    def n(self) -> npt.NDArray[np.float32]:
        """(N,) expected fibers crossed toward the light."""
    @property
    def V(self) -> npt.NDArray[np.float32]:
        """(N,) direct visibility e^-n."""
    @property
    def P(self) -> npt.NDArray[np.float32]:
        """(N, 3) mean product of forward attenuations."""
    @property
    def T_s(self) -> npt.NDArray[np.float32]:
        """(N, 3) forward-scattered transmittance."""
    @property
    def sigma2_f(self) -> npt.NDArray[np.float32]:
        """(N, 3) accumulated forward variance (rad²)."""
    @property
    def light(self) -> dict[str, Any]: ...
    @property
    def mode(self) -> str: ...
    @property
    def stats(self) -> dict[str, int]: ...
    def to_openvdb(self) -> dict[str, Any]:
        """n, V, T_s, sigma2_f as pyopenvdb grids with `hairvox transmittance`'s metadata."""
    def save(self, path: PathLike) -> None: ...

def transmittance(
    scene: SceneArg = None,
    *,
    light: Union[None, str, Mapping[str, Any]] = None,
    mode: Optional[Literal["exact", "grid", "approx"]] = None,
    voxel_size: Optional[float] = None,
    threads: Optional[int] = None,
    progress: ProgressArg = None,
) -> LitGrid:
    """The global term toward one light (a scene light's name, a light dict, or
    the scene's first) at every active voxel of the scene's fiber grid."""

def tables(
    fiber: Union[None, Mapping[str, Any], PathLike] = None,
    *,
    d_b: Optional[float] = None,
    samples: Optional[int] = None,
    cache_dir: Optional[PathLike] = None,
) -> dict[str, Any]:
    """The dual-scattering tables: "theta", "a_f", "a_b", "alpha_f", "alpha_b",
    "beta2_f", "beta2_b", "A_b", "Delta_b", "sigma2_b", "N_G", "N_G_phi",
    "params", "from_cache"."""

def compare(
    a: Union[Render, PathLike],
    b: Union[Render, PathLike],
    *,
    block: Optional[int] = None,
    what: Optional[Literal["hair", "beauty"]] = None,
    layers: Optional[list[str]] = None,
    mask: Optional[str] = None,
) -> dict[str, Any]:
    """rel_l1, rel_rmse, rel_bias, pixels of `a` against reference `b`; with a
    path-traced reference also noise_floor_l1, *_noise_removed and resolved."""

def interrupt() -> None:
    """Stops the long call now running; it raises KeyboardInterrupt."""
