"""hairvox: hair rendering with a voxel-grid dual-scattering global term.

The same C++ libraries as the `hairvox` command line, from Python (Debian's
/usr/bin/python3). The manual is docs/python.md; every function and class has
its own docstring, and __init__.pyi gives their types.

    import hairvox
    r = hairvox.render(width=256, height=256)   # the embedded default scene
    beauty = r.layers["beauty"]                  # float32 (256, 256, 4), no copy
    r.save("out/default.exr")                    # what `hairvox render` writes
"""

from collections.abc import Mapping as _Mapping

from ._hairvox import (
    FiberGrid,
    FrameReuse,
    Groom,
    HairvoxWarning,
    Layers,
    LitGrid,
    Render,
    __version__,
    compare,
    default_scene,
    generate,
    interrupt,
    load_groom,
    read_exr,
    render,
    tables,
    transmittance,
    voxelize,
)

_Mapping.register(Layers)

__all__ = [
    "FiberGrid",
    "FrameReuse",
    "Groom",
    "HairvoxWarning",
    "Layers",
    "LitGrid",
    "Render",
    "__version__",
    "compare",
    "default_scene",
    "generate",
    "interrupt",
    "load_groom",
    "read_exr",
    "render",
    "tables",
    "transmittance",
    "voxelize",
]
