"""Counts as physicists write them: every count argument takes an int or a float holding a
whole number (``1e4``, ``2.5e2``), as the binaries take ``--particles 1e4``; a float that is
not a whole count (``1.5``, ``nan``, ``inf``, ``1e30``, ``-1.0``) raises ``ValueError`` naming
the parameter and its accepted range."""

import math

import numpy as np
import pytest

import aggsim


def table_range(model, name):
    return next(r["range"] for r in aggsim._params(model) if r["name"] == name)


def test_dla_counts_as_floats_are_the_same_run():
    plain = aggsim.dla(particles=300, fit_from=50, seed=3)
    written = aggsim.dla(particles=3e2, fit_from=5.0e1, threads=1.0, serial_until=0.0, seed=3)
    assert written.state_hash == plain.state_hash
    assert written.particles == 300
    assert aggsim.dla(particles=np.int64(300), fit_from=50, seed=3).state_hash == plain.state_hash


def test_dlca_counts_as_floats_are_the_same_run():
    kw = dict(fill=0.05, seed=2, histogram=True, search="grid")
    plain = aggsim.dlca(
        size=[64, 32], target_clusters=10, max_sweeps=1000, grid_box=8,
        histogram_sweeps=[1, 10], fit_min_size=2, **kw,
    )
    written = aggsim.dlca(
        size=[6.4e1, 32.0], target_clusters=1e1, max_sweeps=1e3, grid_box=8.0,
        histogram_sweeps=[1.0, 1e1], fit_min_size=2.0, **kw,
    )
    assert written.state_hash == plain.state_hash
    lat = aggsim.DlcaLattice(size=64.0, particles=1e2, target_clusters=1, seed=2)
    assert lat.step(1e1) == 10


def test_animat_counts_as_floats_are_the_same_run():
    kw = dict(start_radius=40, seed=5)
    plain = aggsim.animat(steps=40, foxes=30, rabbits=300, hungry_at=10, **kw)
    written = aggsim.animat(steps=4e1, foxes=3e1, rabbits=3.0e2, hungry_at=1e1, **kw)
    assert written.state_hash == plain.state_hash
    world = aggsim.AnimatWorld(foxes=3e1, rabbits=3e2, **kw)
    assert world.step(2e1) == 20


@pytest.mark.parametrize("value, says", [
    (1.5, "is not a whole number"),
    (2.5e-1, "is not a whole number"),
    (math.nan, "is not a whole number"),
    (math.inf, "is not a whole number"),
    (1e30, "is outside the accepted range"),
    (-1.0, "is outside the accepted range"),
    (-1, "is outside the accepted range"),
    (10**40, "is outside the accepted range"),
])
def test_counts_that_are_not_whole_name_the_parameter_and_range(value, says):
    rng = table_range("dla", "particles")
    with pytest.raises(ValueError) as e:
        aggsim.dla(particles=value)
    assert str(e.value).startswith("particles = ") and says in str(e.value), e.value
    assert rng in str(e.value), (rng, e.value)


@pytest.mark.parametrize("call, name", [
    (lambda v: aggsim.dla(particles=10, threads=v), "threads"),
    (lambda v: aggsim.dla(particles=10, fit_from=v), "fit_from"),
    (lambda v: aggsim.dla(particles=10, serial_until=v), "serial_until"),
    (lambda v: aggsim.dlca(size=v, fill=0.1), "size"),
    (lambda v: aggsim.dlca(size=16, particles=v), "particles"),
    (lambda v: aggsim.dlca(size=16, fill=0.1, target_clusters=v), "target_clusters"),
    (lambda v: aggsim.dlca(size=16, fill=0.1, max_sweeps=v), "max_sweeps"),
    (lambda v: aggsim.dlca(size=16, fill=0.1, grid_box=v), "grid_box"),
    (lambda v: aggsim.dlca(size=16, fill=0.1, histogram=True, histogram_sweeps=[1, v]),
     "histogram_sweeps"),
    (lambda v: aggsim.dlca(size=16, fill=0.1, fit_min_size=v), "fit_min_size"),
    (lambda v: aggsim.DlcaLattice(size=16, fill=0.1).step(v), "n"),
    (lambda v: aggsim.animat(steps=v), "steps"),
    (lambda v: aggsim.animat(steps=1, foxes=v), "foxes"),
    (lambda v: aggsim.AnimatWorld(rabbits=v), "rabbits"),
    (lambda v: aggsim.AnimatWorld(starve=v), "starve"),
    (lambda v: aggsim.AnimatWorld().step(v), "n"),
])
def test_every_count_argument_names_itself(call, name):
    for bad in (1.5, math.nan, 1e30):
        with pytest.raises(ValueError) as e:
            call(bad)
        assert str(e.value).startswith(f"{name} = "), e.value
        assert "accepted range" in str(e.value), e.value


def test_a_count_of_another_type_names_the_parameter():
    for call, name in [
        (lambda: aggsim.dla(particles=[10]), "particles"),
        (lambda: aggsim.dla(particles="10"), "particles"),
        (lambda: aggsim.dlca(size={}, fill=0.1), "size"),
        (lambda: aggsim.animat(steps=None), "steps"),
    ]:
        with pytest.raises(TypeError) as e:
            call()
        assert str(e.value).startswith(f"{name} = "), e.value
