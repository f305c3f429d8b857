"""Bad parameters raise ValueError with the binary's message for the same bad flag (checked
against the binary where it reaches the library's validation rather than clap's parser)."""

import pytest

import aggsim

DLA = [
    (["--particles", 0], dict(particles=0)),
    (["--particles", 10, "--dim", 6], dict(particles=10, dim=6)),
    (["--particles", 10, "--step-min", 0], dict(particles=10, step_min=0)),
    (["--particles", 10, "--step-min", 1e-300], dict(particles=10, step_min=1e-300)),
    (["--particles", 10, "--precision", 0.5], dict(particles=10, precision=0.5)),
    (["--particles", 10, "--birth-gap", 0.5], dict(particles=10, birth_gap=0.5)),
    (["--particles", 10, "--leaf-side", 3], dict(particles=10, leaf_side=3)),
    (["--particles", 10, "--threads", 0], dict(particles=10, threads=0)),
    (["--particles", 10, "--fit-from", 1], dict(particles=10, fit_from=1)),
    (["--particles", 10, "--death-ratio", 5], dict(particles=10, death_ratio=5)),
    (["--particles", 10, "--far-field", "jump", "--death-ratio", 1],
     dict(particles=10, far_field="jump", death_ratio=1)),
    (["--particles", 10, "--serial-until", 5], dict(particles=10, serial_until=5)),
]

DLCA = [
    (["--size", 64, "--fill", 1.5], dict(size=64, fill=1.5)),
    (["--size", 64, "--fill", 1e-9], dict(size=64, fill=1e-9)),
    (["--size", 64, "--particles", 5000], dict(size=64, particles=5000)),
    (["--size", "8x8x8", "--fill", 0.1], dict(size="8x8x8", fill=0.1, dim=2)),
    (["--dim", 6, "--size", 8, "--fill", 0.1], dict(size=8, fill=0.1, dim=6)),
    (["--size", 64, "--fill", 0.1, "--boundary", "sticky"],
     dict(size=64, fill=0.1, boundary="sticky")),
    (["--size", 64, "--fill", 0.1, "--boundary", "wall,wall,wall"],
     dict(size=64, fill=0.1, boundary="wall,wall,wall")),
    (["--size", 64, "--fill", 0.1, "--temperature", 0], dict(size=64, fill=0.1, temperature=0)),
    (["--size", 64, "--fill", 0.1, "--gravity", 1], dict(size=64, fill=0.1, gravity=1)),
    (["--size", 64, "--fill", 0.1, "--target-clusters", 0],
     dict(size=64, fill=0.1, target_clusters=0)),
    (["--size", 64, "--fill", 0.1, "--grid-box", 12], dict(size=64, fill=0.1, grid_box=12)),
    (["--size", 64, "--fill", 0.1, "--grid-box", 32], dict(size=64, fill=0.1, grid_box=32)),
    (["--size", 64, "--fill", 0.1, "--fit-min-size", 1],
     dict(size=64, fill=0.1, fit_min_size=1)),
    (["--size", 4096, "--fill", 0.1, "--search", "lattice", "--max-memory", "1M"],
     dict(size=4096, fill=0.1, search="lattice", max_memory="1M")),
]

ANIMAT = [
    (["--vision", 0], dict(vision=0)),
    (["--foxes", 100000], dict(foxes=100000)),
    (["--density", 0.9], dict(density=0.9)),
    (["--grid-box", 0], dict(grid_box=0)),
]


@pytest.mark.parametrize("flags, kwargs", DLA)
def test_dla_messages(cli, flags, kwargs):
    with pytest.raises(ValueError) as e:
        aggsim.dla(**kwargs)
    assert str(e.value) == cli.error("dla", *flags)


@pytest.mark.parametrize("flags, kwargs", DLCA)
def test_dlca_messages(cli, flags, kwargs):
    expected = cli.error("dlca", *flags)
    with pytest.raises(ValueError) as e:
        aggsim.dlca(**kwargs)
    assert str(e.value) == expected
    with pytest.raises(ValueError) as e:
        aggsim.DlcaLattice(**kwargs)
    assert str(e.value) == expected


@pytest.mark.parametrize("flags, kwargs", ANIMAT)
def test_animat_messages(cli, flags, kwargs):
    expected = cli.error("animat", *flags)
    with pytest.raises(ValueError) as e:
        aggsim.animat(steps=1, **kwargs)
    assert str(e.value) == expected
    with pytest.raises(ValueError) as e:
        aggsim.AnimatWorld(**kwargs)
    assert str(e.value) == expected


def test_animat_config_messages(cli, tmp_path):
    """A rule between two values of a config file is refused by both with the same message."""
    config = tmp_path / "bad.toml"
    config.write_text("hungry_at = 31\nstarve = 30\n")
    expected = cli.error("animat", "--config", config)
    with pytest.raises(ValueError) as e:
        aggsim.animat(config=config)
    assert str(e.value) == expected
    assert expected.startswith("hungry_at = 31 is above starve = 30")


def test_values_the_command_line_cannot_spell():
    """Arguments clap would refuse before the library sees them: a ValueError naming the flag."""
    cases = [
        (lambda: aggsim.dla(particles=-5), "particles = -5 is outside the accepted range 1.."),
        (lambda: aggsim.dla(particles=10, far_field="bounce"), "'--far-field'"),
        (lambda: aggsim.dla(particles=10, paper_settings=True, step_min=0.2), "--paper-settings"),
        (lambda: aggsim.dlca(size=64, fill=0.1, particles=10), "exactly one of --fill"),
        (lambda: aggsim.dlca(size=64), "exactly one of --fill"),
        (lambda: aggsim.dlca(size=64, fill=0.1, search="kd"), "'--search'"),
        (lambda: aggsim.dlca(size="64x", fill=0.1), "is not a size"),
        (lambda: aggsim.dlca(size=64, fill=0.1, max_memory="lots"), "is not a byte count"),
        (lambda: aggsim.dlca(size=64, fill=0.1, histogram_sweeps=[1]), "--histogram"),
        (lambda: aggsim.animat(start_radius=50, density=0.1), "--density"),
        (lambda: aggsim.animat(fox_rules=["eat", "fly"]), "unknown fox rule \"fly\""),
        (lambda: aggsim.animat(fox_breed_p=1.5), "--fox-breed-p 1.5 is outside"),
        (lambda: aggsim.animat(start_radius=-1), "start_radius = -1 is outside"),
        (lambda: aggsim.animat(grid_box="huge"), "grid_box = huge: invalid grid box"),
        (lambda: aggsim.animat(hungry_at=-1), "hungry_at = -1 is outside"),
        (lambda: aggsim.DlcaLattice(64, 0.1).step(-1), "n = -1 is outside"),
    ]
    for call, text in cases:
        with pytest.raises(ValueError) as e:
            call()
        assert text in str(e.value), str(e.value)


def test_a_config_file_key_that_is_not_a_parameter_is_refused(tmp_path):
    """The Python config reader names the file, the line and the key, and lists the keys."""
    config = tmp_path / "wings.toml"
    config.write_text("foxes = 10\nwings = 2\n")
    with pytest.raises(ValueError) as e:
        aggsim.animat(config=config)
    assert str(e.value).startswith(f"config {config}, line 2: unknown key `wings`"), str(e.value)
    assert "fox_breed_p" in str(e.value)
    config.write_text("fox-breed-p = 0.05\nfoxes = \"many\"\n")
    with pytest.raises(ValueError) as e:
        aggsim.AnimatWorld(config=config)
    assert str(e.value).startswith(f"config {config}, line 2: `foxes` = \"many\""), str(e.value)
    config.write_text("start_radius = 30\ndensity = 0.1\n")
    with pytest.raises(ValueError, match="start_radius cannot be used with density"):
        aggsim.animat(config=config)
