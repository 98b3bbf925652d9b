"""Every bad input raises ValueError naming the field (the CLI's message:
the field, what is wrong and the valid range) — keywords, scene dicts,
numpy grooms, files — and nothing is half-done after it."""

import math
import re

import numpy as np
import pytest

import hairvox
from conftest import small_scene, strand_patch


def scene_with(path, value):
    """small_scene() with the value at a '/'-separated path replaced."""
    scene = small_scene()
    *parents, last = path.strip("/").split("/")
    node = scene
    for key in parents:
        node = node[int(key)] if isinstance(node, list) else node[key]
    if isinstance(node, list):
        node[int(last)] = value
    else:
        node[last] = value
    return scene


GROOM = hairvox.Groom(*strand_patch(strands=20))
POINTS, OFFSETS = strand_patch(strands=3, points=4)
NAN_POINTS = POINTS.copy()
NAN_POINTS[5, 1] = np.nan

# (what is called, the text the message must contain)
BAD_INPUTS = [
    # render's keywords
    (lambda: hairvox.render(small_scene(), width=0), "width = 0: expected an integer in [1, 8192]"),
    (lambda: hairvox.render(small_scene(), width="64"), "width = '64': expected an integer"),
    (lambda: hairvox.render(small_scene(), width=64.0), "width = 64.0: expected an integer"),
    (lambda: hairvox.render(small_scene(), width=True), "width = True"),
    (lambda: hairvox.render(small_scene(), height=9000), "height = 9000"),
    (lambda: hairvox.render(small_scene(), mode="fast"),
     "mode = 'fast': expected one of exact, grid, approx"),
    (lambda: hairvox.render(small_scene(), integrator="raytrace"), "integrator = 'raytrace'"),
    (lambda: hairvox.render(small_scene(), spp=4), "spp applies to the path integrator"),
    (lambda: hairvox.render(small_scene(), integrator="path", spp=0), "spp = 0"),
    (lambda: hairvox.render(small_scene(), integrator="path", seed=-1), "seed = -1"),
    (lambda: hairvox.render(small_scene(), threads=-1), "threads = -1"),
    (lambda: hairvox.render(small_scene(), progress=5), "progress: expected None, True"),
    # scenes
    (lambda: hairvox.render(5), "scene: expected None (the default scene), a scene file path"),
    (lambda: hairvox.render("no/such/scene.json"), "no/such/scene.json"),
    (lambda: hairvox.render(scene_with("/groom/procedural/strands", 0)),
     "scene: /groom/procedural/strands: expected an integer in [1, 10000000]"),
    (lambda: hairvox.render(scene_with("/lights/0/intensity", "bright")),
     "scene: /lights/0/intensity: expected a number in [0, 1e+06]"),
    (lambda: hairvox.render(scene_with("/lights/1/intensity", math.nan)),
     "scene: /lights/1/intensity"),
    (lambda: hairvox.render(scene_with("/camera/fovy", 40)), "scene: /camera/fovy: unknown key"),
    (lambda: hairvox.render(scene_with("/camera/position", {1, 2, 3})),
     "scene: /camera/position: a set is not a value of the scene schema"),
    (lambda: hairvox.render(scene_with("/camera/look_at", [0, 0, 0, 0])), "scene: /camera/look_at"),
    (lambda: hairvox.render(scene_with("/fiber/eta", 5)), "scene: /fiber/eta"),
    (lambda: hairvox.render(scene_with("/background", [0, 0, -1])), "scene: /background"),
    (lambda: hairvox.render({**small_scene(), 3: "x"}), "scene: /: key 3 is not a string"),
    (lambda: hairvox.render(scene_with("/groom/procedural/seed", 2**70)),
     "scene: /groom/procedural/seed: 1180591620717411303424 does not fit in 64 bits"),
    (lambda: hairvox.render(small_scene(groom={"file": "no/such.hair"})), "no/such.hair"),
    (lambda: hairvox.render(small_scene(camera={"position": [0, 0, 0.05], "look_at": [0, 0, 1]})),
     "camera"),
    # grooms from numpy
    (lambda: hairvox.Groom(POINTS[:, :2], OFFSETS), "hairvox.Groom: points: expected shape (N, 3), got (12, 2)"),
    (lambda: hairvox.Groom("points", OFFSETS), "hairvox.Groom: points: expected an array of numbers"),
    (lambda: hairvox.Groom(POINTS, [0, 4, 8]), "hairvox.Groom: strand_offsets: expected S + 1 offsets from 0 to the 12 points"),
    (lambda: hairvox.Groom(POINTS, [0, 4, 5, 12]), "hairvox.Groom: strand_offsets: strand 1 has 1 point(s)"),
    (lambda: hairvox.Groom(POINTS, [0.0, 4.0, 8.0, 12.0]), "hairvox.Groom: strand_offsets: expected a 1-D array of integers"),
    (lambda: hairvox.Groom(NAN_POINTS, OFFSETS), "hairvox.Groom: points: strand 1, point 1 has a non-finite coordinate"),
    (lambda: hairvox.Groom(POINTS, OFFSETS, thickness=-np.ones(12)), "hairvox.Groom: thickness: strand 0, point 0: -1"),
    (lambda: hairvox.Groom(POINTS, OFFSETS, thickness=np.ones(11)), "hairvox.Groom: thickness: expected shape (12,), got (11,)"),
    (lambda: hairvox.Groom(POINTS, OFFSETS, colors=np.ones((12, 4))), "hairvox.Groom: colors: expected shape (12, 3)"),
    (lambda: hairvox.Groom(POINTS, OFFSETS, colors=np.full((12, 3), np.inf)), "hairvox.Groom: colors: strand 0, point 0"),
    (lambda: hairvox.load_groom("no/such/groom.hair"), "no/such/groom.hair"),
    (lambda: hairvox.load_groom(""), "path = '': expected a path"),
    (lambda: hairvox.generate("frizzy"), "generate: /groom/procedural/style"),
    (lambda: hairvox.generate(strands=0), "generate: /groom/procedural/strands"),
    (lambda: hairvox.generate(strand=10), "generate: /groom/procedural/strand: unknown key"),
    # grids
    (lambda: hairvox.voxelize(5), "groom: expected a hairvox.Groom or a groom file path"),
    (lambda: hairvox.voxelize(GROOM, voxel_size=-1), "voxel_size = -1"),
    (lambda: hairvox.voxelize(GROOM, voxels_across=0), "voxels_across = 0"),
    (lambda: hairvox.voxelize(GROOM, voxel_size=0.01, voxels_across=8), "voxel_size and voxels_across"),
    (lambda: hairvox.voxelize(GROOM, diameter=0), "diameter: "),
    (lambda: hairvox.voxelize(GROOM, density_multiplier=1e9), "density_multiplier: "),
    (lambda: hairvox.voxelize(GROOM, orientation_tensor="yes"), "orientation_tensor = 'yes': expected True or False"),
    (lambda: hairvox.voxelize(GROOM, voxel_size=1e-7), "voxel"),
    (lambda: hairvox.transmittance(small_scene(), light="sun"), "light = 'sun': scene has no such light (its lights: key, back)"),
    (lambda: hairvox.transmittance(small_scene(), light={"type": "spot"}), "light: /lights/0/type"),
    (lambda: hairvox.transmittance(small_scene(lights=[])), "light: scene has no lights"),
    (lambda: hairvox.transmittance(small_scene(), mode="fast"), "mode = 'fast'"),
    (lambda: hairvox.transmittance(small_scene(), voxel_size=0), "voxel_size = 0"),
    (lambda: hairvox.FiberGrid.load("no/such/grid.vdb"), "no/such/grid.vdb"),
    # tables
    (lambda: hairvox.tables({"eta": 5}), "tables: /fiber/eta"),
    (lambda: hairvox.tables({"melanin": [1]}), "tables: /fiber/melanin"),
    (lambda: hairvox.tables({"sigma_a": [0.1, 0.2]}), "tables: /fiber/sigma_a"),
    (lambda: hairvox.tables(samples=2), "samples = 2: expected an integer in [3, 10001]"),
    (lambda: hairvox.tables(d_b=2), "d_b = 2: expected a number in [0, 1]"),
    # EXRs and comparisons
    (lambda: hairvox.read_exr("no/such/image.exr"), "no/such/image.exr"),
    (lambda: hairvox.compare("no/such/a.exr", "no/such/b.exr"), "no/such/a.exr"),
    (lambda: hairvox.compare(5, "b.exr"), "a: expected a hairvox.Render or an EXR path"),
]


@pytest.mark.parametrize("call, message", BAD_INPUTS, ids=[m for _, m in BAD_INPUTS])
def test_bad_input_raises_value_error_naming_the_field(call, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        call()


def test_bad_inputs_of_a_render_and_its_outputs(tmp_path):
    r = hairvox.render(small_scene())
    for call, message in [
        (lambda: hairvox.compare(r, r, block=0), "block = 0: expected an integer in [1, 4096]"),
        (lambda: hairvox.compare(r, r, what="both"), "what = 'both': expected one of hair, beauty"),
        (lambda: hairvox.compare(r, r, mask="nope"), "nope"),
        (lambda: hairvox.compare(r, r, layers="direct_R"), "layers: expected a list"),
        (lambda: r.save(tmp_path / "x.jpg"), "the extension must be .exr or .png"),
        (lambda: r.save(exr=3), "exr = 3: expected a path"),
        (lambda: r.preview(exposure=50), "exposure = 50"),
        (lambda: r.preview(tone_map="aces"), "tone_map = 'aces': expected one of filmic, clamp"),
    ]:
        with pytest.raises(ValueError, match=re.escape(message)):
            call()
    assert list(tmp_path.iterdir()) == []


def test_a_truncated_groom_file_names_the_file(tmp_path, data_dir):
    good = (data_dir / "Ratboy_mohawk.tfx").read_bytes()
    bad = tmp_path / "truncated.tfx"
    bad.write_bytes(good[: len(good) // 3])
    with pytest.raises(ValueError, match="truncated.tfx"):
        hairvox.load_groom(bad)
    with pytest.raises(ValueError, match="truncated.tfx"):
        hairvox.render(small_scene(groom={"file": str(bad)}))
    with pytest.raises(ValueError, match="truncated.tfx"):
        hairvox.voxelize(bad)


def test_a_render_after_errors_works():
    with pytest.raises(ValueError):
        hairvox.render(small_scene(), width=0)
    assert hairvox.render(small_scene()).layers["beauty"].shape == (64, 64, 4)
