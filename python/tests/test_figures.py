"""The figures a result writes (save_png, DlaResult.save_gif) are the binaries' files byte for
byte: the same run through the binary and through Python, the same raster size."""

import math

import numpy as np
import pytest

import aggsim


def same_bytes(a, b):
    return a.read_bytes() == b.read_bytes()


def png_size(path):
    """Width and height from a PNG's IHDR chunk."""
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


@pytest.mark.parametrize(
    "flags, kwargs, size",
    [
        (["--particles", 1500, "--seed", 3], dict(particles=1500, seed=3), None),
        # A raster narrower than the cluster: particles per pixel.
        (["--particles", 1500, "--seed", 3], dict(particles=1500, seed=3), 40),
        (["--dim", 3, "--particles", 800, "--seed", 2], dict(dim=3, particles=800, seed=2), 200),
    ],
)
def test_dla_png_is_the_binarys(cli, tmp_path, flags, kwargs, size):
    sized = [] if size is None else ["--png-size", size]
    out, _ = cli.run("dla", *flags, "--png", *sized)
    r = aggsim.dla(**kwargs)
    r.save_png(tmp_path / "dla.png", size=size)
    assert same_bytes(tmp_path / "dla.png", out / "dla.png")
    if size is not None:
        # The raster and the axes, header and legend around it.
        w, h = png_size(tmp_path / "dla.png")
        assert w > size and h > size


def test_dla_gif_is_the_binarys(cli, tmp_path):
    out, _ = cli.run(
        "dla", "--particles", 1200, "--seed", 5, "--animate", "--png-size", 64,
        "--animate-every", 300,
    )
    r = aggsim.dla(particles=1200, seed=5)
    assert r.save_gif(str(tmp_path / "dla.gif"), size=64, every=300) == 4
    assert same_bytes(tmp_path / "dla.gif", out / "dla.gif")
    # The defaults are the binary's too.
    out, _ = cli.run("dla", "--particles", 1200, "--seed", 5, "--animate")
    assert r.save_gif(tmp_path / "default.gif") == 100
    assert same_bytes(tmp_path / "default.gif", out / "dla.gif")


@pytest.mark.parametrize(
    "flags, kwargs, size",
    [
        (["--size", "60x40", "--fill", 0.1, "--seed", 2, "--target-clusters", 15],
         dict(size="60x40", fill=0.1, seed=2, target_clusters=15), None),
        # Several sites a pixel: the drawing order decides which shows.
        (["--size", 90, "--fill", 0.15, "--seed", 4, "--target-clusters", 30],
         dict(size=90, fill=0.15, seed=4, target_clusters=30), 32),
        (["--dim", 3, "--size", "16x12x8", "--fill", 0.1, "--seed", 1, "--target-clusters", 10],
         dict(size="16x12x8", fill=0.1, seed=1, target_clusters=10), 64),
    ],
)
def test_dlca_png_is_the_binarys(cli, tmp_path, flags, kwargs, size):
    sized = [] if size is None else ["--png-size", size]
    out, _ = cli.run("dlca", *flags, "--png", *sized)
    r = aggsim.dlca(**kwargs)
    r.save_png(tmp_path / "dlca.png", size=size)
    assert same_bytes(tmp_path / "dlca.png", out / "dlca.png")


def test_dlca_lattice_result_draws_the_state_at_its_sweep(cli, tmp_path):
    out, _ = cli.run(
        "dlca", "--size", 50, "--fill", 0.1, "--seed", 6, "--max-sweeps", 7, "--png"
    )
    lat = aggsim.DlcaLattice(50, fill=0.1, seed=6, max_sweeps=7)
    lat.run()
    lat.result().save_png(tmp_path / "dlca.png")
    assert same_bytes(tmp_path / "dlca.png", out / "dlca.png")


@pytest.mark.parametrize(
    "flags, kwargs, size, radius",
    [
        (["--steps", 30, "--seed", 4], dict(steps=30, seed=4), None, None),
        # Animats outside a small frame, counted in the header; several cells a pixel.
        (["--steps", 20, "--seed", 2, "--foxes", 50, "--rabbits", 400],
         dict(steps=20, seed=2, foxes=50, rabbits=400), 40, 30),
    ],
)
def test_animat_snapshot_is_the_binarys_last(cli, tmp_path, flags, kwargs, size, radius):
    steps = kwargs["steps"]
    extra = [] if size is None else ["--png-size", size]
    extra += [] if radius is None else ["--frame-radius", radius]
    out, _ = cli.run("animat", *flags, "--snapshot-every", steps, *extra)
    r = aggsim.animat(**kwargs)
    r.save_png(tmp_path / "world.png", size=size, frame_radius=radius)
    assert same_bytes(tmp_path / "world.png", out / f"snapshot_{steps:06d}.png")


def test_an_animat_world_draws_its_state_now(cli, tmp_path):
    out, _ = cli.run("animat", "--steps", 10, "--seed", 8, "--snapshot-every", 5)
    w = aggsim.AnimatWorld(seed=8)
    w.step(5)
    w.result().save_png(tmp_path / "five.png")
    assert same_bytes(tmp_path / "five.png", out / "snapshot_000005.png")


def gif_frames(path):
    """The number of images (frames) in a GIF, walking its blocks."""
    data = path.read_bytes()
    assert data[:6] == b"GIF89a"

    def table(flags):
        return 3 * 2 ** ((flags & 7) + 1) if flags & 0x80 else 0

    def sub_blocks(i):
        while data[i]:
            i += data[i] + 1
        return i + 1

    i = 13 + table(data[10])
    frames = 0
    while data[i] != 0x3B:
        if data[i] == 0x21:  # extension: label, then sub-blocks
            i = sub_blocks(i + 2)
        else:
            assert data[i] == 0x2C, f"unknown block {data[i]:#x} at {i}"
            frames += 1
            i += 10 + table(data[i + 9])
            i = sub_blocks(i + 1)  # after the LZW minimum code size
    return frames


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        # The defaults: a frame every 10 sweeps, 512 pixels.
        (["--size", 40, "--fill", 0.1, "--seed", 2, "--target-clusters", 12],
         dict(size=40, fill=0.1, seed=2, target_clusters=12)),
        (["--size", "48x32", "--fill", 0.12, "--seed", 5, "--target-clusters", 8,
          "--animate-every", 3, "--png-size", 96],
         dict(size="48x32", fill=0.12, seed=5, target_clusters=8, animate_every=3,
              animate_size=96)),
    ],
)
def test_dlca_animation_is_the_binarys(cli, tmp_path, flags, kwargs):
    out, run = cli.run("dlca", *flags, "--animate")
    r = aggsim.dlca(**kwargs, animate=tmp_path / "dlca.gif")
    assert r.state_hash == run["results"]["state_hash"]
    assert same_bytes(tmp_path / "dlca.gif", out / "dlca.gif")


@pytest.mark.parametrize(
    "flags, kwargs",
    [
        # The defaults: a frame every hundredth of the steps, on three start radii.
        (["--steps", 30, "--seed", 4], dict(steps=30, seed=4)),
        # A last step off the frame grid gets its own frame; a small frame, animats outside.
        (["--steps", 11, "--seed", 2, "--foxes", 50, "--rabbits", 400, "--animate-every", 4,
          "--png-size", 64, "--frame-radius", 20],
         dict(steps=11, seed=2, foxes=50, rabbits=400, animate_every=4, animate_size=64,
              frame_radius=20)),
    ],
)
def test_animat_animation_is_the_binarys(cli, tmp_path, flags, kwargs):
    out, run = cli.run("animat", *flags, "--animate")
    r = aggsim.animat(**kwargs, animate=str(tmp_path / "animat.gif"))
    assert r.state_hash == run["results"]["state_hash"]
    assert same_bytes(tmp_path / "animat.gif", out / "animat.gif")


def test_an_animation_has_a_frame_for_the_start_every_k_and_the_end(tmp_path):
    # 11 steps, a frame every 4: the start, steps 4 and 8, and step 11.
    aggsim.animat(steps=11, seed=2, animate=tmp_path / "a.gif", animate_every=4,
                  animate_size=32)
    assert gif_frames(tmp_path / "a.gif") == 4


@pytest.mark.parametrize(
    "run",
    [
        lambda **kw: aggsim.dlca(30, fill=0.1, seed=1, target_clusters=10, **kw),
        lambda **kw: aggsim.animat(steps=3, seed=1, **kw),
    ],
)
def test_animation_keywords_are_checked(tmp_path, run):
    gif = tmp_path / "x.gif"
    with pytest.raises(ValueError, match=r"^animate_every and animate_size .*give animate a path"):
        run(animate_every=2)
    with pytest.raises(ValueError, match=r"^animate_every and animate_size"):
        run(animate_size=64)
    with pytest.raises(ValueError, match=r"^animate_every = 0 is outside the accepted range 1\.\."):
        run(animate=gif, animate_every=0)
    with pytest.raises(ValueError, match=r"^animate_every = 1\.5 is not a whole number"):
        run(animate=gif, animate_every=1.5)
    with pytest.raises(ValueError, match=r"^animate_size = 16385 is outside the accepted range 16\.\.=16384"):
        run(animate=gif, animate_size=16385)
    with pytest.raises(ValueError, match=r"^animate_size = 15 is outside"):
        run(animate=gif, animate_size=15)
    # Nothing was written by a refused run.
    assert not gif.exists()
    # Counts as physicists write them.
    run(animate=gif, animate_every=1e1, animate_size=3.2e1)
    assert gif.exists()


def test_animat_frame_radius_needs_an_animation(tmp_path):
    with pytest.raises(ValueError, match=r"^frame_radius frames the animation"):
        aggsim.animat(steps=3, frame_radius=5)
    with pytest.raises(ValueError, match=r"^frame_radius = 0 is outside the accepted range 1\.\."):
        aggsim.animat(steps=3, animate=tmp_path / "a.gif", frame_radius=0)


def test_an_unwritable_animation_is_an_oserror(tmp_path):
    with pytest.raises(OSError, match="no-such-dir"):
        aggsim.animat(steps=3, animate=tmp_path / "no-such-dir" / "a.gif")


@pytest.fixture(scope="module")
def results():
    return [
        aggsim.dla(particles=200, seed=1),
        aggsim.dlca(30, fill=0.1, seed=1, target_clusters=10),
        aggsim.animat(steps=2, seed=1, foxes=5, rabbits=20),
    ]


def test_a_size_is_a_count_in_range(results, tmp_path):
    for r in results:
        r.save_png(tmp_path / "whole.png", size=1e2)
        r.save_png(tmp_path / "int.png", size=100)
        assert same_bytes(tmp_path / "whole.png", tmp_path / "int.png")
        for bad in (1.5, math.nan, -1, 15, 65537, 1e30):
            with pytest.raises(ValueError, match=r"^size = .*16\.\.=65536"):
                r.save_png(tmp_path / "bad.png", size=bad)
        with pytest.raises(TypeError, match="^size = "):
            r.save_png(tmp_path / "bad.png", size="big")
        assert not (tmp_path / "bad.png").exists()
    dla = results[0]
    with pytest.raises(ValueError, match=r"^size = 16385 .*16\.\.=16384"):
        dla.save_gif(tmp_path / "bad.gif", size=16385)
    with pytest.raises(ValueError, match="^every = 0"):
        dla.save_gif(tmp_path / "bad.gif", every=0)
    with pytest.raises(ValueError, match="^every = 2.5"):
        dla.save_gif(tmp_path / "bad.gif", every=2.5)
    with pytest.raises(ValueError, match="^frame_radius = 0"):
        results[2].save_png(tmp_path / "bad.png", frame_radius=0)
    assert not (tmp_path / "bad.gif").exists()


def test_arrays_that_do_not_fit_the_run_are_refused(tmp_path):
    r = aggsim.dla(particles=100, seed=1)
    r.positions = r.positions[:, :1].copy()
    with pytest.raises(ValueError, match="columns"):
        r.save_png(tmp_path / "a.png")
    d = aggsim.dlca(20, fill=0.1, seed=1, target_clusters=5)
    d.positions = d.positions + 20
    with pytest.raises(ValueError, match="outside the lattice"):
        d.save_png(tmp_path / "a.png")
    a = aggsim.animat(steps=1, seed=1, foxes=3, rabbits=3)
    a.species = np.full_like(a.species, 7)
    with pytest.raises(ValueError, match="species code 7"):
        a.save_png(tmp_path / "a.png")
    assert not (tmp_path / "a.png").exists()


def test_an_unwritable_path_is_an_os_error(tmp_path):
    r = aggsim.dla(particles=100, seed=1)
    with pytest.raises(OSError):
        r.save_png(tmp_path / "no" / "such" / "dir" / "a.png")
