"""hairvox.voxelize / FiberGrid, hairvox.transmittance / LitGrid,
hairvox.tables and hairvox.compare: numpy views of the libraries' arrays,
pyopenvdb grids, and the values the CLI writes."""

import json

import numpy as np
import pyopenvdb
import pytest

import hairvox
from conftest import small_scene, strand_patch


def test_a_fiber_grid_as_numpy_conserves_the_fiber_length():
    groom = hairvox.generate("wavy", strands=400, seed=2)
    grid = hairvox.voxelize(groom, voxels_across=64, diameter=7e-5, density_multiplier=3)
    n = len(grid)
    assert n == grid.active_voxel_count > 100
    assert grid.ijk.shape == (n, 3) and grid.ijk.dtype == np.int32
    assert grid.density.shape == (n,) and grid.orientation.shape == (n, 3)
    assert grid.tensor_diag is None and grid.type_fractions == []
    for a in (grid.ijk, grid.density, grid.orientation):
        assert not a.flags.owndata and not a.flags.writeable
    assert grid.density.__array_interface__["data"][0] == \
        grid.density.__array_interface__["data"][0]
    np.testing.assert_allclose(grid.positions, grid.ijk * grid.voxel_size)
    # The splat conserves length: Σ λ h³ is the groom's total fiber length.
    h = grid.voxel_size
    assert float(grid.density.astype(np.float64).sum()) * h**3 == pytest.approx(
        groom.stats()["total_length"], rel=1e-4)
    coherence = np.linalg.norm(grid.orientation, axis=1)
    assert coherence.max() <= 1 + 1e-5 and coherence.mean() > 0.5
    info = grid.info
    assert info["strands"] == 400 and info["fiber_diameter"] == pytest.approx(7e-5)
    assert info["source_file"] == "in-memory groom"

    tensor = hairvox.voxelize(groom, voxels_across=64, orientation_tensor=True)
    np.testing.assert_allclose(tensor.tensor_diag.sum(axis=1), 1, atol=1e-4)  # trace 1


def test_to_openvdb_gives_pyopenvdb_grids_with_the_same_voxels(tmp_path):
    groom = hairvox.generate("straight", strands=200, seed=1)
    grid = hairvox.voxelize(groom, voxels_across=48)
    vdb = grid.to_openvdb()
    assert set(vdb) == {"density", "orientation"}
    density = vdb["density"]
    assert isinstance(density, pyopenvdb.FloatGrid)
    assert density.activeVoxelCount() == len(grid)
    assert density.transform.voxelSize()[0] == pytest.approx(grid.voxel_size)
    assert density["voxel_size"] == pytest.approx(grid.voxel_size)
    accessor = density.getConstAccessor()
    orientation = vdb["orientation"].getConstAccessor()
    for i in range(0, len(grid), max(1, len(grid) // 50)):
        ijk = tuple(int(c) for c in grid.ijk[i])
        assert accessor.getValue(ijk) == grid.density[i]
        assert orientation.getValue(ijk) == pytest.approx(tuple(grid.orientation[i]))
    # The same grids as the .vdb the module (and `hairvox voxelize`) writes.
    grid.save(tmp_path / "g.vdb")
    grids, _ = pyopenvdb.readAll(str(tmp_path / "g.vdb"))
    assert {g.name for g in grids} == {"density", "orientation"}
    again = hairvox.FiberGrid.load(tmp_path / "g.vdb")
    np.testing.assert_array_equal(again.density, grid.density)
    np.testing.assert_array_equal(again.ijk, grid.ijk)


def test_voxelize_a_file_as_the_cli_does(tmp_path, cli, data_dir):
    groom_file = data_dir / "Ratboy_mohawk.tfx"
    grid = hairvox.voxelize(groom_file, voxels_across=64)
    cli("voxelize", groom_file, "--voxels-across", 64, "-o", tmp_path / "cli.vdb")
    from_cli = hairvox.FiberGrid.load(tmp_path / "cli.vdb")
    np.testing.assert_array_equal(from_cli.ijk, grid.ijk)
    np.testing.assert_array_equal(from_cli.density, grid.density)


def test_transmittance_toward_a_light(tmp_path, cli):
    scene = small_scene()
    lit = hairvox.transmittance(scene, light="key")
    n = len(lit.fiber_grid)
    assert lit.n.shape == (n,) and lit.T_s.shape == (n, 3) and lit.sigma2_f.shape == (n, 3)
    assert not lit.V.flags.owndata and not lit.V.flags.writeable
    np.testing.assert_array_equal(lit.ijk, lit.fiber_grid.ijk)
    assert lit.light["name"] == "key" and lit.mode == "grid"
    assert (lit.V >= 0).all() and (lit.V <= 1).all() and (lit.T_s >= 0).all()
    # Voxels the head hides from the light get no light at all (V = 0, n = 0);
    # elsewhere V = e^-n.
    blocked = (lit.V == 0) & (lit.n == 0)
    assert blocked.sum() == lit.stats["blocked_by_surface"] > 0
    np.testing.assert_allclose(lit.V[~blocked], np.exp(-lit.n[~blocked]), rtol=1e-4, atol=1e-6)
    assert lit.n.max() > 1, "nothing in the groom shadows anything"
    assert lit.stats["queries"] == n

    # A light dict: from straight above, voxels higher up see fewer fibers.
    above = hairvox.transmittance(scene, light={"type": "directional", "direction": [0, 1, 0]})
    y = above.positions[:, 1]
    assert above.n[y > np.quantile(y, 0.8)].mean() < above.n[y < np.quantile(y, 0.2)].mean()

    # The pyopenvdb grids and the .vdb hold the same values and the CLI's metadata.
    vdb = lit.to_openvdb()
    assert set(vdb) == {"n", "V", "T_s", "sigma2_f"}
    V = vdb["V"].getConstAccessor()
    for i in range(0, n, max(1, n // 40)):
        assert V.getValue(tuple(int(c) for c in lit.ijk[i])) == lit.V[i]
    assert vdb["V"]["light_type"] == "directional" and vdb["V"]["mode"] == "grid"
    # The CLI's `hairvox transmittance` of the same scene and light: the same
    # voxels and values, and the same .vdb grids as LitGrid.save writes.
    above.save(tmp_path / "lit.vdb")
    scene_file = tmp_path / "scene.json"
    scene_file.write_text(json.dumps(scene))
    cli("transmittance", "--scene", scene_file, "--light-dir", "0,1,0", "-o", tmp_path / "cli.vdb")
    ours = {g.name: g for g in pyopenvdb.readAll(str(tmp_path / "lit.vdb"))[0]}
    theirs = {g.name: g for g in pyopenvdb.readAll(str(tmp_path / "cli.vdb"))[0]}
    assert set(ours) == set(theirs) == {"n", "V", "T_s", "sigma2_f"}
    for name in ("n", "V"):
        assert ours[name].activeVoxelCount() == theirs[name].activeVoxelCount() == n
        accessor = theirs[name].getConstAccessor()
        values = getattr(above, name)
        for i in range(0, n, max(1, n // 200)):
            assert accessor.getValue(tuple(int(c) for c in above.ijk[i])) == values[i], name


def test_tables_as_numpy(tmp_path):
    blond = hairvox.tables({"melanin": {"eumelanin": 0.1, "pheomelanin": 0.1}}, cache_dir=tmp_path)
    dark = hairvox.tables({"melanin": {"eumelanin": 4, "pheomelanin": 0.5}}, cache_dir=tmp_path)
    assert not blond["from_cache"]
    s = len(blond["theta"])
    assert s == 181 and blond["theta"][0] == pytest.approx(-np.pi / 2)
    for key in ("a_f", "a_b", "alpha_f", "alpha_b", "beta2_f", "beta2_b", "A_b", "Delta_b",
                "sigma2_b"):
        assert blond[key].shape == (s, 3) and np.isfinite(blond[key]).all(), key
        assert not blond[key].flags.owndata and not blond[key].flags.writeable
    assert blond["N_G"].shape == (s, 37, 3, 3) and blond["N_G_phi"][-1] == pytest.approx(np.pi)
    # Dark hair forwards less light than blond at every inclination.
    assert (dark["a_f"] < blond["a_f"]).all()
    assert hairvox.tables({"melanin": {"eumelanin": 0.1, "pheomelanin": 0.1}},
                          cache_dir=tmp_path)["from_cache"]
    # A scene's fiber, as `hairvox tables --scene`.
    scene = hairvox.tables(small_scene(), cache_dir=tmp_path)
    melanin = 0.12 * np.array([0.419, 0.697, 1.37]) + 0.2 * np.array([0.187, 0.4, 1.05])
    assert scene["params"]["sigma_a"] == pytest.approx(melanin, rel=1e-5)


def test_compare_renders_and_files(tmp_path):
    exact = hairvox.render(small_scene(), mode="exact")
    grid = hairvox.render(small_scene(), mode="grid")
    same = hairvox.compare(exact, exact)
    assert same["rel_l1"] == 0 and same["pixels"] > 0 and not same["noisy_reference"]
    differ = hairvox.compare(grid, exact, block=4)
    assert 0 < differ["rel_l1"] < 1 and differ["block"] == 4
    exact.save(exr=tmp_path / "exact.exr")
    grid.save(exr=tmp_path / "grid.exr")
    assert hairvox.compare(tmp_path / "grid.exr", exact, block=4)["rel_l1"] == \
        pytest.approx(differ["rel_l1"], rel=0.02)  # the EXR rounds to half
    path = hairvox.render(small_scene(), integrator="path", spp=16)
    against_path = hairvox.compare(grid, path, block=4)
    assert against_path["noisy_reference"] and against_path["noise_floor_l1"] > 0
    beauty = hairvox.compare(grid, exact, what="beauty", mask="A")
    assert beauty["rel_l1"] > 0


def test_an_internal_error_is_a_runtime_error(monkeypatch):
    # Without pyopenvdb the grids cannot be handed over: not bad input, an
    # environment the module cannot work in — RuntimeError, saying what to install.
    grid = hairvox.voxelize(hairvox.generate("straight", strands=20), voxels_across=16)
    monkeypatch.setitem(__import__("sys").modules, "pyopenvdb", None)
    with pytest.raises(RuntimeError, match="python3-openvdb"):
        grid.to_openvdb()
