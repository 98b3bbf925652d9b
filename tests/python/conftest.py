"""Shared fixtures of the Python module's tests (run by ctest: tests/CMakeLists.txt).

ctest sets PYTHONPATH to this build's package (build/<name>/python), the CLI
binary (HAIRVOX_BINARY) and a table cache inside the build (HAIRVOX_CACHE_DIR).
A test that cannot find what it needs fails and says why; none is skipped.
"""

import copy
import os
import pathlib
import subprocess

import numpy as np
import pytest

import hairvox

# The scene of most tests: the default scene's look, small and fast — 300
# procedural strands on the mannequin's head sphere (the sphere itself, no
# mesh), two lights, 64 x 64.
SMALL_SCENE = {
    "groom": {"procedural": {"style": "wavy", "strands": 300, "points_per_strand": 16, "seed": 3}},
    "fiber": {"diameter": 7e-5, "density_multiplier": 20,
              "melanin": {"eumelanin": 0.12, "pheomelanin": 0.2}},
    "lights": [
        {"name": "key", "type": "directional", "direction": [-0.2, 0.55, 0.8], "intensity": 3.0},
        {"name": "back", "type": "directional", "direction": [0.3, 0.35, -0.9], "intensity": 4.0},
    ],
    "camera": {"position": [0.5, 0.02, 0.62], "look_at": [0.0, -0.1, 0.0], "fov": 40,
               "resolution": [64, 64]},
    "head": {"center": [0, 0, 0], "radius": 0.1},
    "background": [0.02, 0.02, 0.025],
    "output": {"exr": None, "png": None},
}


def small_scene(**changes):
    """A deep copy of SMALL_SCENE with top-level keys replaced."""
    scene = copy.deepcopy(SMALL_SCENE)
    scene.update(changes)
    return scene


def require_env(name):
    value = os.environ.get(name)
    if not value:
        pytest.fail(f"{name} is not set: run these tests through ctest (tests/CMakeLists.txt)")
    return value


@pytest.fixture(scope="session", autouse=True)
def this_build():
    """The module under test is this build's, not another checkout's."""
    package = pathlib.Path(require_env("PYTHONPATH").split(os.pathsep)[0]).resolve()
    assert pathlib.Path(hairvox.__file__).resolve().parent == package / "hairvox", (
        f"imported {hairvox.__file__}, expected the package in {package}")


@pytest.fixture(scope="session")
def cli():
    """Runs the hairvox CLI of this build; returns the CompletedProcess."""
    binary = require_env("HAIRVOX_BINARY")
    assert os.access(binary, os.X_OK), f"HAIRVOX_BINARY={binary} is not an executable"

    def run(*args, check=True):
        result = subprocess.run([binary, *map(str, args)], capture_output=True, text=True)
        if check:
            assert result.returncode == 0, f"hairvox {' '.join(map(str, args))}:\n{result.stderr}"
        return result

    return run


@pytest.fixture(scope="session")
def data_dir():
    path = pathlib.Path(require_env("HAIRVOX_DATA_DIR"))
    assert path.is_dir(), path
    return path


def strand_patch(strands=120, points=8, length=0.2, seed=1):
    """A groom built in numpy: strands hanging from a 6 cm patch in front of
    the head sphere (toward the camera), slightly bent, `points` points each."""
    rng = np.random.default_rng(seed)
    roots = np.stack([rng.uniform(-0.03, 0.03, strands), np.full(strands, 0.05),
                      rng.uniform(0.12, 0.18, strands)], axis=1)
    t = np.linspace(0.0, 1.0, points)[None, :, None]
    drop = np.array([0.0, -length, 0.0])[None, None, :]
    bend = np.array([0.0, 0.0, 0.3 * length])[None, None, :] * t**2
    pts = roots[:, None, :] + drop * t + bend
    offsets = np.arange(0, strands * points + 1, points)
    return pts.reshape(-1, 3).astype(np.float32), offsets
