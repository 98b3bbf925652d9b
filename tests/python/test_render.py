"""hairvox.render and hairvox.Render: the same pixels and files as the CLI,
layers that are views (no copy), the report, save()'s outputs."""

import copy
import gc
import json

import matplotlib.image
import numpy as np
import pytest

import hairvox
from conftest import small_scene


def write_scene(path, scene):
    path.write_text(json.dumps(scene))
    return path


@pytest.mark.parametrize("integrator", ["dual_scattering", "path"])
def test_render_equals_the_cli_pixel_for_pixel(tmp_path, cli, integrator):
    scene = small_scene(integrator={"type": "path", "spp": 4} if integrator == "path"
                        else "dual_scattering")
    scene_file = write_scene(tmp_path / "scene.json", scene)
    cli("render", scene_file, "--exr", tmp_path / "cli.exr", "--png", tmp_path / "cli.png",
        "--quiet")

    r = hairvox.render(scene_file)
    written = r.save(exr=tmp_path / "py.exr", png=tmp_path / "py.png")
    assert written == [str(tmp_path / "py.exr"), str(tmp_path / "py.png")]
    # The same files, byte for byte (pixels, layers, attributes, compression).
    assert (tmp_path / "py.exr").read_bytes() == (tmp_path / "cli.exr").read_bytes()
    assert (tmp_path / "py.png").read_bytes() == (tmp_path / "cli.png").read_bytes()

    # And the arrays in memory are the CLI's EXR pixel for pixel: exactly for
    # 32-bit layers, after the EXR's rounding to half for the others.
    exr = hairvox.read_exr(tmp_path / "cli.exr")
    assert sorted(exr) == sorted(r.layers)
    for name, layer in r.layers.items():
        stored = exr[name]
        assert stored.shape == layer.shape, name
        as_stored = layer if np.array_equal(stored, layer) else \
            layer.astype(np.float16).astype(np.float32)
        np.testing.assert_array_equal(as_stored, stored, err_msg=name)
    assert r.layers["beauty"][..., 3].max() > 0.5, "the image shows no hair"


def test_layers_are_views_of_the_render_not_copies():
    r = hairvox.render(small_scene())
    names = list(r.layers)
    assert names[0] == "beauty" and "direct_R" in names and "Z" in names
    assert isinstance(r.layers, hairvox.Layers)
    from collections.abc import Mapping
    assert isinstance(r.layers, Mapping)

    addresses = {}
    for name in names:
        first = r.layers[name]
        again = r.layers[name]
        address = first.__array_interface__["data"][0]
        # Every access views the same memory: nothing copied, nothing laid out again.
        assert again.__array_interface__["data"][0] == address, name
        assert np.shares_memory(first, again)
        assert not first.flags.owndata and not first.flags.writeable, name
        assert first.dtype == np.float32 and first.flags.c_contiguous
        addresses[name] = address
    assert len(set(addresses.values())) == len(names), "two layers share memory"

    beauty = r.layers["beauty"]
    assert beauty.shape == (64, 64, 4)
    assert r.layers["direct_R"].shape == (64, 64, 3)
    assert r.layers["Z"].shape == (64, 64, 1)
    with pytest.raises(ValueError):
        beauty[0, 0, 0] = 1.0  # read-only: the film is the render's
    with pytest.raises(KeyError, match="no such layer"):
        r.layers["nope"]

    # The arrays keep the render alive: still valid after it is dropped.
    total = float(beauty.sum())
    del r
    gc.collect()
    assert float(beauty.sum()) == total


def test_beauty_alpha_is_the_films_A_and_the_aovs_sum_to_the_beauty():
    # No head and a black background: the beauty is the hair alone.
    scene = small_scene(background=[0, 0, 0])
    del scene["head"]
    layers = hairvox.render(scene, mode="exact").layers
    hair = sum(layers[n] for n in ("direct_R", "direct_TT", "direct_TRT", "back_direct", "scatter"))
    assert (layers["hair.A"] > 0).sum() > 100
    np.testing.assert_allclose(layers["beauty"][..., 3:], layers["hair.A"], atol=1e-6)
    np.testing.assert_allclose(layers["beauty"][..., :3], hair, rtol=1e-4, atol=1e-6)


def test_report_says_what_each_stage_did():
    r = hairvox.render(small_scene(), width=48)
    assert (r.width, r.height) == (48, 48)  # one side keeps the aspect ratio
    report = r.report
    assert report["integrator"] == "dual_scattering" and report["mode"] == "grid"
    times = report["times"]
    assert set(times) >= {"load", "voxelize", "tables", "global_term", "raster", "shade", "total"}
    assert times["total"] == pytest.approx(sum(v for k, v in times.items() if k != "total"))
    assert [light["name"] for light in report["lights"]] == ["key", "back"]
    assert report["active_voxels"] > 0 and report["raster"]["fragments"] > 0
    assert report["raster"]["segments"] > 0
    assert "hairvox: scene, grid mode, 48x48" in report["text"]


def test_save_writes_the_scene_outputs_or_the_ones_given(tmp_path):
    scene = small_scene(output={"exr": str(tmp_path / "a.exr"), "png": str(tmp_path / "a.png")})
    r = hairvox.render(scene)
    assert not (tmp_path / "a.exr").exists()  # nothing is written by render()
    assert r.save() == [str(tmp_path / "a.exr"), str(tmp_path / "a.png")]
    assert r.save(tmp_path / "b.png") == [str(tmp_path / "b.png")]
    assert not (tmp_path / "b.exr").exists()

    # The PNG is the preview's pixels.
    png = matplotlib.image.imread(tmp_path / "b.png")
    np.testing.assert_array_equal(np.round(png[..., :3] * 255).astype(np.uint8), r.preview())
    assert r.preview(exposure=2.0).mean() > r.preview().mean()

    with pytest.raises(ValueError, match="path = '.*x.tif': the extension must be .exr or .png"):
        r.save(tmp_path / "x.tif")
    with pytest.raises(ValueError, match="are the same file"):
        r.save(exr=tmp_path / "same", png=tmp_path / "same")
    with pytest.raises(ValueError, match="both set the exr output"):
        r.save(tmp_path / "c.exr", exr=tmp_path / "d.exr")
    nothing = hairvox.render(small_scene())
    with pytest.raises(ValueError, match="output.exr and output.png are both null"):
        nothing.save()


def test_save_never_overwrites_the_scene_or_groom_file(tmp_path):
    groom = hairvox.generate("straight", strands=50, seed=2)
    groom.save(tmp_path / "g.hair")
    scene = small_scene(groom={"file": str(tmp_path / "g.hair")})
    scene_file = write_scene(tmp_path / "s.json", scene)
    r = hairvox.render(scene_file)
    before = (tmp_path / "g.hair").read_bytes()
    with pytest.raises(ValueError, match="is the groom file"):
        r.save(png=tmp_path / "g.hair")
    with pytest.raises(ValueError, match="is the scene file"):
        r.save(exr=scene_file)
    assert (tmp_path / "g.hair").read_bytes() == before


def test_scene_forms_and_keywords():
    # A path, a dict, None (checked in the CLI test) and keyword overrides.
    r = hairvox.render(small_scene(), integrator="path", spp=2, seed=5, threads=1)
    assert r.report["path_trace"]["spp"] == 2 and r.report["mode"] is None
    assert "multiple" in r.layers
    # The same seed gives the same image with any thread count.
    again = hairvox.render(small_scene(), integrator="path", spp=2, seed=5, threads=2)
    np.testing.assert_array_equal(r.layers["beauty"], again.layers["beauty"])
    other = hairvox.render(small_scene(), integrator="path", spp=2, seed=6)
    assert not np.array_equal(r.layers["beauty"], other.layers["beauty"])
    # numpy values and tuples are accepted in a scene dict.
    scene = small_scene()
    scene["camera"]["position"] = np.array([0.5, 0.02, 0.62])
    scene["camera"]["resolution"] = (np.int64(64), 64)
    np.testing.assert_array_equal(hairvox.render(scene).layers["beauty"],
                                  hairvox.render(small_scene()).layers["beauty"])


def test_read_exr_of_a_saved_render(tmp_path):
    r = hairvox.render(small_scene())
    r.save(exr=tmp_path / "r.exr")
    exr = hairvox.read_exr(tmp_path / "r.exr")
    assert exr["Z"].dtype == np.float32
    np.testing.assert_array_equal(exr["Z"], r.layers["Z"])  # depth is stored as 32-bit float


def test_the_default_scene_renders_from_python(cli, tmp_path):
    r = hairvox.render(width=64, height=64)
    assert r.scene_name == "default scene"
    r.save(exr=tmp_path / "py.exr")
    cli("render", "--width", 64, "--height", 64, "--exr", tmp_path / "cli.exr", "--quiet")
    assert (tmp_path / "py.exr").read_bytes() == (tmp_path / "cli.exr").read_bytes()
    # default_scene() is that scene as a dict.
    as_dict = hairvox.render(hairvox.default_scene(), width=64, height=64)
    np.testing.assert_array_equal(as_dict.layers["beauty"], r.layers["beauty"])


def test_frame_reuse_shares_the_grid_between_renders():
    reuse = hairvox.FrameReuse()
    first = hairvox.render(small_scene(), reuse=reuse)
    assert not first.report["grid_reused"]
    # Another colour: the same grid, the lights prepared again; the same image as alone.
    darker = small_scene(fiber={**small_scene()["fiber"],
                                "melanin": {"eumelanin": 2.0, "pheomelanin": 0.2}})
    second = hairvox.render(darker, reuse=reuse)
    assert second.report["grid_reused"]
    assert [light["reused"] for light in second.report["lights"]] == [False, False]
    alone = hairvox.render(darker)
    for name in alone.layers:
        np.testing.assert_array_equal(second.layers[name], alone.layers[name], err_msg=name)
    # The camera moves: the grid and both lights are kept.
    moved = copy.deepcopy(darker)
    moved["camera"]["position"] = [0.45, 0.05, 0.65]
    third = hairvox.render(moved, reuse=reuse)
    assert third.report["grid_reused"]
    assert [light["reused"] for light in third.report["lights"]] == [True, True]
    with pytest.raises(ValueError, match="reuse: expected None or a hairvox.FrameReuse"):
        hairvox.render(small_scene(), reuse=True)
