"""hairvox.Groom: numpy in and out, the readers' validation, in-memory grooms
in scenes (rendering as the same groom read from a file)."""

import warnings

import numpy as np
import pytest

import hairvox
from conftest import small_scene, strand_patch


def test_a_groom_round_trips_through_numpy_and_a_file(tmp_path):
    points, offsets = strand_patch(strands=40, points=6)
    thickness = np.linspace(50e-6, 90e-6, len(points), dtype=np.float32)
    colors = np.tile(np.array([[0.6, 0.4, 0.25]], np.float32), (len(points), 1))
    colors[::7] = [0.1, 0.05, 0.03]
    g = hairvox.Groom(points, offsets, thickness=thickness, colors=colors)
    assert (len(g), g.strand_count, g.point_count, g.segment_count) == (40, 40, 240, 200)
    np.testing.assert_array_equal(g.points, points)
    np.testing.assert_array_equal(g.strand_offsets, offsets)
    np.testing.assert_array_equal(g.thickness, thickness)
    np.testing.assert_array_equal(g.colors, colors)
    assert g.transparency is None
    assert g.points.dtype == np.float32 and g.strand_offsets.dtype == np.uint32
    # Out: views of the groom, read-only, the same memory on every access.
    for name in ("points", "strand_offsets", "thickness", "colors"):
        a, b = getattr(g, name), getattr(g, name)
        assert not a.flags.owndata and not a.flags.writeable, name
        assert a.__array_interface__["data"][0] == b.__array_interface__["data"][0], name
    # In: copied, so the caller's arrays stay the caller's.
    points[0] = 99.0
    assert g.points[0, 0] != 99.0
    points[0] = g.points[0]
    np.testing.assert_array_equal(g.strand(3), points[18:24])

    g.save(tmp_path / "g.hair")
    back = hairvox.load_groom(tmp_path / "g.hair")
    for name in ("points", "strand_offsets", "thickness", "colors"):
        np.testing.assert_array_equal(getattr(back, name), getattr(g, name), err_msg=name)
    stats = back.stats()
    assert stats["strands"] == 40 and stats["segments"] == 200
    assert stats["total_length"] == pytest.approx(
        np.linalg.norm(np.diff(points.reshape(40, 6, 3), axis=1), axis=2).sum(), rel=1e-5)


def test_groom_inputs_of_other_dtypes_and_a_file_groom(data_dir):
    points, offsets = strand_patch(strands=10, points=4)
    g = hairvox.Groom(points.astype(np.float64).tolist(), offsets.astype(np.int32))
    np.testing.assert_array_equal(g.points, points)
    assert g.thickness is None and g.colors is None
    ratboy = hairvox.load_groom(data_dir / "Ratboy_mohawk.tfx")
    assert ratboy.strand_count > 1000 and ratboy.points.shape == (ratboy.point_count, 3)


def test_zero_length_segments_are_dropped_with_a_warning():
    points = np.array([[0, 0, 0], [0, 0, 0], [0, 0.01, 0], [0.1, 0, 0], [0.1, 0.02, 0]],
                      np.float32)
    with pytest.warns(hairvox.HairvoxWarning, match="dropped 1 zero-length segment"):
        g = hairvox.Groom(points, [0, 3, 5])
    assert g.point_count == 4
    np.testing.assert_array_equal(g.strand_offsets, [0, 2, 4])


def test_generate_is_the_scenes_procedural_groom():
    a = hairvox.generate("curly", strands=30, seed=4)
    b = hairvox.generate("curly", strands=30, seed=4)
    np.testing.assert_array_equal(a.points, b.points)
    assert a.strand_count == 30 and a.point_count == 30 * 64  # curly: 64 points a strand
    assert not np.array_equal(a.points, hairvox.generate("curly", strands=30, seed=5).points)
    colored = hairvox.generate("wavy", strands=20, colors=[[0.5, 0.3, 0.2], [0.1, 0.1, 0.1]])
    assert colored.colors is not None


def test_a_numpy_groom_renders_as_the_same_groom_from_a_file(tmp_path):
    points, offsets = strand_patch()
    thickness = np.full(len(points), 80e-6, np.float32)
    g = hairvox.Groom(points, offsets, thickness=thickness)
    g.save(tmp_path / "patch.hair")
    in_memory = hairvox.render(small_scene(groom=g), mode="exact")
    from_file = hairvox.render(small_scene(groom={"file": str(tmp_path / "patch.hair")}),
                               mode="exact")
    hair = in_memory.layers["hair.A"]
    assert (hair > 0.5).sum() > 50, "the numpy groom is not seen"
    assert sorted(in_memory.layers) == sorted(from_file.layers)
    for name in in_memory.layers:
        np.testing.assert_array_equal(in_memory.layers[name], from_file.layers[name],
                                      err_msg=name)
    # The groom is shared with the scene, never changed by a render.
    np.testing.assert_array_equal(g.thickness, thickness)


def test_a_groom_in_place_of_a_file_takes_the_groom_keys():
    points, offsets = strand_patch(strands=60)
    colors = np.tile(np.array([[0.004, 0.003, 0.002]], np.float32), (len(points), 1))
    g = hairvox.Groom(points, offsets, colors=colors)
    used = hairvox.render(small_scene(groom={"file": g}))
    ignored = hairvox.render(small_scene(groom={"file": g, "color": "ignore"}))
    assert used.report["fiber_types"] == 1
    assert any("fiber type(s) from the groom's colours" in n for n in used.report["notes"])
    # Black hair against the scene's light melanin: the colours are rendered.
    assert used.layers["direct_TT"].sum() < 0.5 * ignored.layers["direct_TT"].sum()
    assert used.layers["direct_TT"].sum() > 0
    with pytest.raises(ValueError, match='/groom: expected exactly one of "file" and "procedural"'):
        hairvox.render(small_scene(groom={"file": g, "procedural": {}}))
    with pytest.raises(ValueError, match="/lights/0: a hairvox.Groom goes in /groom"):
        hairvox.render(small_scene(lights=[g]))


def test_a_groom_alone_is_a_scene():
    g = hairvox.Groom(*strand_patch(strands=30))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hairvox.HairvoxWarning)  # the default camera may miss it
        r = hairvox.render(g, width=32, height=32)
    assert r.scene_name == "groom" and r.width == 32
    assert r.report["raster"]["segments"] == 30 * 7
