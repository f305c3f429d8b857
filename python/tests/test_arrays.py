"""The arrays have the documented shapes and dtypes, and positions are NumPy's own memory
handed over once (not copied again on every access)."""

import numpy as np
import pytest

import aggsim


@pytest.mark.parametrize("dim", [2, 3])
def test_dla_arrays(dim):
    r = aggsim.dla(dim=dim, particles=2000, seed=3)
    assert r.positions.shape == (2000, dim) and r.positions.dtype == np.float64
    assert r.positions.flags.c_contiguous and r.positions.flags.writeable
    np.testing.assert_array_equal(r.positions[0], np.zeros(dim))
    # The attribute is one array, not a copy made per access.
    assert r.positions is r.positions
    assert list(r.growth) == ["n", "radius_of_gyration", "r_ext", "seconds"]
    n = len(r.growth["n"])
    assert r.growth["n"].dtype == np.uint64 and r.growth["n"][-1] == 2000
    for k in ("radius_of_gyration", "r_ext", "seconds"):
        assert r.growth[k].dtype == np.float64 and r.growth[k].shape == (n,)
    assert np.all(np.diff(r.growth["n"].astype(np.int64)) > 0)
    # R_g of the positions is the reported one.
    c = r.positions - r.positions.mean(0)
    assert np.isclose(np.sqrt((c * c).sum(1).mean()), r.radius_of_gyration)
    assert np.isclose(np.linalg.norm(r.positions, axis=1).max(), r.r_ext)
    assert isinstance(r.state_hash, str) and len(r.state_hash) == 16
    assert isinstance(r.run_json, dict) and r.run_json["model"] == "dla"


def test_dla_parents_form_a_tree_of_touching_particles():
    r = aggsim.dla(particles=20_000, seed=4)
    p = r.parent
    assert p.dtype == np.int64 and p.shape == (20_000,)
    assert p[0] == -1 and np.all(p[1:] >= 0) and np.all(p[1:] < np.arange(1, 20_000))
    d = np.linalg.norm(r.positions[1:] - r.positions[p[1:]], axis=1)
    np.testing.assert_allclose(d, 1.0, atol=1e-8)
    b = r.branches
    assert list(b) == [
        "order", "branches", "particles", "mean_length", "bifurcation_ratio", "length_ratio",
    ]
    assert b["order"][-1] == r.strahler_order and b["particles"].sum() == 20_000
    assert np.isnan(b["bifurcation_ratio"][-1])
    np.testing.assert_allclose(b["bifurcation_ratio"][:-1], b["branches"][:-1] / b["branches"][1:])
    assert r.trees == 1 and 4.0 < r.bifurcation_ratio < 6.5


def test_dla_deposit_on_a_substrate():
    w = 64.0
    r = aggsim.dla(particles=4000, seed=2, substrate_width=w, drift=0.5)
    pos, p = r.positions, r.parent
    assert np.all(np.abs(pos[:, 0]) <= w / 2) and np.all(pos[:, 1] >= -1e-9)
    roots = p == -1
    np.testing.assert_allclose(pos[roots, 1], 0.0, atol=1e-8)
    dx = np.abs(pos[~roots, 0] - pos[p[~roots], 0])
    dx = np.minimum(dx, w - dx)
    dz = pos[~roots, 1] - pos[p[~roots], 1]
    np.testing.assert_allclose(np.hypot(dx, dz), 1.0, atol=1e-8)
    d = r.deposit
    assert list(d) == ["height", "particles", "density", "trees"]
    assert d["particles"].sum() == 4000 and d["trees"][0] == roots.sum()
    np.testing.assert_allclose(d["density"], d["particles"] / w)
    g = r.deposit_growth
    assert g["n"][-1] == 4000 and np.all(np.diff(g["height"]) >= 0)
    assert r.run_json["results"]["deposit_trees"] == roots.sum()
    assert aggsim.dla(particles=100, seed=2).deposit is None
    with pytest.raises(ValueError, match="--drift needs --substrate-width"):
        aggsim.dla(particles=100, drift=1.0)


def test_a_resumed_dla_keeps_its_parents(tmp_path, monkeypatch):
    from test_checkpoint import SMALL, stopped_at_start

    stopped_at_start("dla", SMALL["dla"], tmp_path, monkeypatch)
    resumed = aggsim.dla(checkpoint=tmp_path, **SMALL["dla"])
    whole = aggsim.dla(**SMALL["dla"])
    np.testing.assert_array_equal(resumed.parent, whole.parent)
    assert resumed.bifurcation_ratio == whole.bifurcation_ratio
    assert not (tmp_path / "positions_parent.npy").exists()


def test_dlca_arrays():
    r = aggsim.dlca(size=[40, 30], particles=100, seed=2, target_clusters=10, gyration=True)
    assert r.positions.shape == (100, 2) and r.positions.dtype == np.int64
    assert r.cluster.shape == (100,) and r.cluster.dtype == np.int64
    assert (r.positions >= 0).all() and (r.positions < [40, 30]).all()
    assert len(np.unique(r.cluster)) == r.clusters
    assert len({tuple(p) for p in r.positions}) == 100
    s = r.per_sweep
    assert set(s) == {"sweep", "clusters", "largest"}
    assert all(v.dtype == np.uint64 and v.shape == (r.sweeps + 1,) for v in s.values())
    assert s["clusters"][-1] == r.clusters and s["largest"][-1] == r.largest_cluster
    assert (r.sizes["size"] * r.sizes["count"]).sum() == 100
    assert r.sizes["count"].sum() == r.clusters
    assert r.gyration["wraps"].dtype == np.bool_
    assert r.gyration["radius_of_gyration"].dtype == np.float64
    assert r.histogram is None


def test_dlca_lattice_accessors():
    lat = aggsim.DlcaLattice("32x32", fill=0.1, seed=1, target_clusters=20)
    assert lat.size == (32, 32) and lat.sweeps == 0 and not lat.done
    assert lat.step(2) == 2 and lat.sweeps == 2
    assert lat.positions.shape == (lat.particles, 2) and lat.cluster.shape == (lat.particles,)
    assert len(np.unique(lat.cluster)) == lat.clusters
    assert lat.per_sweep["clusters"].shape == (3,)
    lat.run()
    assert lat.done and lat.clusters <= 20
    assert lat.step(5) == 0


def test_animat_arrays():
    r = aggsim.animat(steps=15, seed=3, foxes=30, rabbits=200, start_radius=30, timing=True)
    m = r.foxes + r.rabbits
    assert r.positions.shape == (m, 2) and r.positions.dtype == np.int64
    assert r.species.dtype == np.int64 and r.species.shape == (m,)
    assert (r.species == aggsim.FOX).sum() == r.foxes
    assert (r.species == aggsim.RABBIT).sum() == r.rabbits
    assert r.id.dtype == np.int64 and np.all(np.diff(r.id) > 0)
    assert r.age.dtype == np.int64 and r.hunger.dtype == np.int64
    assert (r.hunger[r.species == aggsim.RABBIT] == 0).all()
    p = r.populations
    assert list(p) == ["step", "foxes", "rabbits", "search_seconds", "distance_evaluations"]
    assert p["step"].dtype == np.uint64 and p["step"].shape == (16,)
    assert p["search_seconds"].dtype == np.float64
    assert (p["foxes"][-1], p["rabbits"][-1]) == (r.foxes, r.rabbits)


def test_animat_world_accessors():
    w = aggsim.AnimatWorld(2, foxes=10, rabbits=40, start_radius=15)
    assert (w.steps, w.foxes, w.rabbits) == (0, 10, 40)
    assert w.step(5) == 5 and w.steps == 5
    assert w.positions.shape == (w.foxes + w.rabbits, 2)
    assert w.populations["step"].tolist() == [0, 1, 2, 3, 4, 5]
    assert w.result().steps == 5


def test_defaults_are_the_libraries():
    d = aggsim.defaults("dla")
    assert d["dim"] == 2 and d["particles"] == 100_000 and d["threads"] == 1
    assert aggsim.defaults("dlca")["target_clusters"] == 100
    assert aggsim.defaults("animat")["steps"] == 1000
    with pytest.raises(ValueError, match="unknown model"):
        aggsim.defaults("ising")
