"""Results from Python equal the binaries' for the same seed and parameters: the state hash,
every deterministic scalar of run.json, and the arrays against the binaries' output files."""

import csv

import numpy as np
import pytest

import aggsim

# Results that measure the machine (time, memory) rather than the run.
MEASURED = {
    "wall_seconds",
    "cpu_seconds",
    "peak_rss_bytes",
    "bytes_per_particle",
    "simulation_peak_rss_bytes",
    "output_peak_rss_bytes",
    "pdla_parallel_seconds",
    "pdla_lock_wait_seconds",
}


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([r[k] for r in rows]) for k in rows[0]}


def same_results(result, run_json, ignore=()):
    """Every result of the binary's run.json, and its seed, model and threads, as attributes."""
    for key, value in run_json["results"].items():
        if key in MEASURED or key in ignore:
            continue
        assert getattr(result, key) == value, key
    for key in ("model", "seed", "threads", "version"):
        assert getattr(result, key) == run_json[key], key
    # The same keys: nothing of run.json is missing from the result.
    assert set(run_json["results"]) <= set(vars(result))


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        (["--particles", 3000, "--seed", 7], dict(particles=3000, seed=7)),
        (
            ["--dim", 3, "--particles", 1500, "--seed", 2, "--far-field", "jump",
             "--death-ratio", 20, "--step-min", 0.5, "--precision", 3, "--leaf-side", 4,
             "--fit-from", 100],
            dict(dim=3, particles=1500, seed=2, far_field="jump", death_ratio=20,
                 step_min=0.5, precision=3, leaf_side=4, fit_from=100),
        ),
        (
            ["--particles", 800, "--distance-map", "off", "--near-cache", "off",
             "--birth-gap", 2.5],
            dict(particles=800, distance_map=False, near_cache=False, birth_gap=2.5),
        ),
        (
            ["--particles", 900, "--paper-settings"],
            dict(particles=900, paper_settings=True),
        ),
        (["--dim", 4, "--particles", 600, "--seed", 3, "--fit-from", 100],
         dict(dim=4, particles=600, seed=3, fit_from=100)),
        (["--dim", 5, "--particles", 300, "--seed", 4, "--fit-from", 50],
         dict(dim=5, particles=300, seed=4, fit_from=50)),
    ],
)
def test_dla_equals_the_binary(cli, flags, kwargs):
    out, run = cli.run("dla", "--positions", "npy", *flags)
    r = aggsim.dla(**kwargs)
    assert r.state_hash == run["results"]["state_hash"]
    same_results(r, run)
    params = dict(run["params"], keep_positions=True)
    assert r.params == params
    np.testing.assert_array_equal(r.positions, np.load(out / "positions.npy"))
    g = read_csv(out / "growth.csv")
    np.testing.assert_array_equal(r.growth["n"], g["n"].astype(np.uint64))
    np.testing.assert_array_equal(r.growth["radius_of_gyration"], g["radius_of_gyration"].astype(float))
    np.testing.assert_array_equal(r.growth["r_ext"], g["r_ext"].astype(float))


def test_pdla_runs_and_reports_as_the_binary(cli):
    """Two threads are not deterministic: the same results exist, the cluster is complete."""
    _, run = cli.run("dla", "--particles", 3000, "--threads", 2, "--serial-until", 500)
    r = aggsim.dla(particles=3000, threads=2, serial_until=500)
    assert set(run["results"]) <= set(vars(r))
    assert r.particles == 3000 and r.positions.shape == (3000, 2)
    assert r.threads == 2 and r.pdla_phases >= 1


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        (["--size", 64, "--fill", 0.05, "--seed", 3, "--gyration", "--timing"],
         dict(size=64, fill=0.05, seed=3, gyration=True, timing=True)),
        (["--dim", 3, "--size", "16x12x10", "--particles", 90, "--boundary", "periodic,wall,wall",
          "--target-clusters", 5, "--gravity", 0.3, "--mobility-exponent", 0.5,
          "--search", "grid", "--histogram", "--histogram-sweeps", "1,3,10"],
         dict(size=[16, 12, 10], particles=90, boundary=["periodic", "wall", "wall"],
              target_clusters=5, gravity=0.3, mobility_exponent=0.5, search="grid",
              histogram=True, histogram_sweeps=[1, 3, 10])),
        (["--size", "40x30", "--fill", 0.1, "--max-sweeps", 7, "--temperature", 0.5,
          "--search", "all-pairs"],
         dict(size="40x30", fill=0.1, max_sweeps=7, temperature=0.5, search="all-pairs")),
    ],
)
def test_dlca_equals_the_binary(cli, flags, kwargs):
    out, run = cli.run("dlca", *flags)
    r = aggsim.dlca(**kwargs)
    assert r.state_hash == run["results"]["state_hash"]
    same_results(r, run)
    assert r.params == run["params"]
    s = read_csv(out / "sweeps.csv")
    for k in ("sweep", "clusters", "largest"):
        np.testing.assert_array_equal(r.per_sweep[k], s[k].astype(np.uint64))
    z = read_csv(out / "sizes.csv")
    np.testing.assert_array_equal(r.sizes["size"], z["size"].astype(np.uint64))
    np.testing.assert_array_equal(r.sizes["count"], z["count"].astype(np.uint64))
    p = read_csv(out / "particles.csv")
    axes = [f"x{a + 1}" for a in range(r.positions.shape[1])]
    np.testing.assert_array_equal(r.positions, np.stack([p[a].astype(np.int64) for a in axes], 1))
    np.testing.assert_array_equal(r.cluster, p["cluster"].astype(np.int64))
    if r.gyration is not None:
        c = read_csv(out / "clusters.csv")
        np.testing.assert_array_equal(r.gyration["cluster"], c["cluster"].astype(np.int64))
        np.testing.assert_array_equal(
            r.gyration["radius_of_gyration"], c["radius_of_gyration"].astype(float)
        )
    if r.histogram is not None:
        h = read_csv(out / "histogram.csv")
        np.testing.assert_array_equal(r.histogram["moves"], h["moves"].astype(np.uint64))


ANIMAT_SMALL = dict(foxes=30, rabbits=200, start_radius=30)


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        (["--steps", 40, "--seed", 5, "--foxes", 30, "--rabbits", 200, "--start-radius", 30],
         dict(steps=40, seed=5, **ANIMAT_SMALL)),
        (["--steps", 25, "--foxes", 20, "--rabbits", 150, "--density", 0.05, "--vision", 20,
          "--grid-box", "none"],
         dict(steps=25, foxes=20, rabbits=150, density=0.05, vision=20, grid_box="none")),
    ],
)
def test_animat_equals_the_binary(cli, flags, kwargs):
    out, run = cli.run("animat", "--positions", *flags)
    r = aggsim.animat(**kwargs)
    assert r.state_hash == run["results"]["state_hash"]
    same_results(r, run)
    assert r.params == run["params"]
    pops = read_csv(out / "populations.csv")
    for k in ("step", "foxes", "rabbits"):
        np.testing.assert_array_equal(r.populations[k], pops[k].astype(np.uint64))
    p = read_csv(out / "positions.csv")
    np.testing.assert_array_equal(r.id, p["id"].astype(np.int64))
    np.testing.assert_array_equal(r.positions[:, 0], p["x"].astype(np.int64))
    np.testing.assert_array_equal(r.positions[:, 1], p["y"].astype(np.int64))
    codes = np.where(p["species"] == "fox", aggsim.FOX, aggsim.RABBIT)
    np.testing.assert_array_equal(r.species, codes)
    np.testing.assert_array_equal(r.age, p["age"].astype(np.int64))
    np.testing.assert_array_equal(r.hunger, p["hunger"].astype(np.int64))


def test_animat_config_file_as_the_binary(cli, tmp_path):
    config = tmp_path / "small.toml"
    config.write_text("foxes = 25\nrabbits = 180\nstart_radius = 25\nhungry_at = 8\n")
    _, run = cli.run("animat", "--config", config, "--steps", 20, "--rabbits", 170)
    r = aggsim.animat(steps=20, config=config, rabbits=170)
    assert r.state_hash == run["results"]["state_hash"]
    assert r.params == run["params"]


def test_stepping_makes_the_same_run():
    whole = aggsim.dlca(size=48, fill=0.08, seed=4)
    lat = aggsim.DlcaLattice(48, 0.08, seed=4)
    while not lat.done:
        lat.step(3)
    assert lat.state_hash == whole.state_hash and lat.sweeps == whole.sweeps
    np.testing.assert_array_equal(lat.per_sweep["clusters"], whole.per_sweep["clusters"])
    assert lat.result().state_hash == whole.state_hash

    whole = aggsim.animat(steps=30, seed=9, **ANIMAT_SMALL)
    world = aggsim.AnimatWorld(9, **ANIMAT_SMALL)
    for _ in range(30):
        world.step()
    assert world.state_hash == whole.state_hash
    np.testing.assert_array_equal(world.populations["foxes"], whole.populations["foxes"])
    np.testing.assert_array_equal(world.positions, whole.positions)
