"""checkpoint=DIR: a run stopped by Ctrl-C, SIGTERM, an exception of the progress callback or
memory about to run out leaves DIR/checkpoint.bin, and the same call continues it to the
state an uninterrupted run reaches (the same state_hash); a finished run removes the
checkpoint's files; a checkpoint of other parameters is refused. The files are the binaries'
(--resume DIR continues a checkpoint written from Python, and the other way round)."""

import inspect
import os
import signal
import threading
import time

import pytest

import aggsim

# Runs of a few tenths of a second from a release build: with progress reported at every poll
# (50 ms, the library's test hook below), the callback is first called while they run.
LONG = {
    "dla": dict(particles=200_000, seed=3),
    "dlca": dict(size=1024, fill=0.03, target_clusters=30, seed=2),
    "animat": dict(steps=1500, seed=4),
}
# Small runs for what a checkpoint taken at the start shows.
SMALL = {
    "dla": dict(particles=20_000, seed=3),
    "dlca": dict(size=128, fill=0.05, target_clusters=1, seed=2),
    "animat": dict(steps=100, foxes=100, rabbits=600, start_radius=30, seed=4),
}
# What a run leaves in DIR while it can be continued.
FILES = {
    "dla": {"checkpoint.bin", "positions.npy", "positions_parent.npy", "growth.csv"},
    "dlca": {"checkpoint.bin"},
    "animat": {"checkpoint.bin"},
}
MODELS = list(LONG)


def run(model, **kwargs):
    return getattr(aggsim, model)(**kwargs)


def files(d):
    return {p.name for p in d.iterdir()}


@pytest.fixture(autouse=True)
def report_at_every_poll(monkeypatch):
    """Progress reports at every poll rather than every half second, so that a run stops at its
    first report however fast the machine runs it."""
    monkeypatch.setenv("AGGSIM_TEST_REPORT_EVERY", "0")


def interrupt_at_first_report(done, total):
    """A progress callback that stops the run at its first report after some progress (the
    last report, of a finished run, is left alone)."""
    if 0 < done < total:
        raise KeyboardInterrupt


def stopped_at_start(model, kwargs, d, monkeypatch):
    """Leaves in ``d`` the checkpoint of a run stopped by the memory watch at its start: the
    watch is shown a machine of 1 MiB (the library's test hook)."""
    monkeypatch.setenv("AGGSIM_TEST_MEMORY_LIMIT", "1M")
    with pytest.raises(MemoryError, match="memory nearly exhausted"):
        run(model, checkpoint=d, **kwargs)
    monkeypatch.delenv("AGGSIM_TEST_MEMORY_LIMIT")
    assert FILES[model] <= files(d)


@pytest.mark.parametrize("model", MODELS)
def test_interrupted_run_continues_to_the_uninterrupted_state(model, tmp_path):
    kwargs = LONG[model]
    whole = run(model, **kwargs)
    d = tmp_path / "ck"
    with pytest.raises(KeyboardInterrupt):
        run(model, checkpoint=d, progress=interrupt_at_first_report, **kwargs)
    assert FILES[model] <= files(d)
    # Timed checkpoints on the way do not change the run either.
    resumed = run(model, checkpoint=d, checkpoint_interval=0.05, **kwargs)
    assert resumed.state_hash == whole.state_hash
    assert files(d) == set()


def test_rerunning_the_same_call_after_each_interrupt_finishes_the_run(tmp_path):
    kwargs = LONG["dla"]
    whole = aggsim.dla(**kwargs)
    interrupts = 0
    while True:
        try:
            r = aggsim.dla(checkpoint=tmp_path, progress=interrupt_at_first_report, **kwargs)
            break
        except KeyboardInterrupt:
            interrupts += 1
            assert (tmp_path / "checkpoint.bin").exists()
    assert interrupts >= 1
    assert r.state_hash == whole.state_hash
    assert r.positions.shape == whole.positions.shape
    assert (r.growth["n"] == whole.growth["n"]).all()
    assert files(tmp_path) == set()


def test_sigterm_checkpoints_and_stops_like_ctrl_c(tmp_path):
    # Long enough (0.7-1.5 s from a release build) that the signal, which comes after the first
    # timed checkpoint, comes well before its end.
    kwargs = dict(particles=400_000, seed=3)
    whole = aggsim.dla(**kwargs)
    before = signal.getsignal(signal.SIGTERM)
    ck = tmp_path / "checkpoint.bin"

    def terminate_after_the_first_checkpoint():
        # From another thread, as a batch system's signal comes, while the run goes on: once
        # the first timed checkpoint (50 ms into the run) shows that it is under way.
        while not ck.exists():
            time.sleep(0.002)
        os.kill(os.getpid(), signal.SIGTERM)

    sender = threading.Thread(target=terminate_after_the_first_checkpoint)
    sender.start()
    with pytest.raises(KeyboardInterrupt):
        aggsim.dla(checkpoint=tmp_path, checkpoint_interval=0.05, **kwargs)
    sender.join()
    assert signal.getsignal(signal.SIGTERM) is before
    assert FILES["dla"] <= files(tmp_path)
    assert aggsim.dla(checkpoint=tmp_path, **kwargs).state_hash == whole.state_hash
    assert signal.getsignal(signal.SIGTERM) is before


@pytest.mark.parametrize("model", MODELS)
def test_memory_running_out_checkpoints_and_raises_memory_error(model, tmp_path, monkeypatch):
    kwargs = SMALL[model]
    stopped_at_start(model, kwargs, tmp_path, monkeypatch)
    assert run(model, checkpoint=tmp_path, **kwargs).state_hash == run(model, **kwargs).state_hash
    assert files(tmp_path) == set()


@pytest.mark.parametrize("model", MODELS)
def test_a_finished_run_leaves_no_checkpoint(model, tmp_path):
    d = tmp_path / "new" / "dir"
    r = run(model, checkpoint=d, **SMALL[model])
    assert files(d) == set()
    assert r.state_hash == run(model, **SMALL[model]).state_hash


@pytest.mark.parametrize(
    "model, other, named",
    [
        ("dla", dict(birth_gap=7.0), "birth_gap 5.0 in the checkpoint, 7.0 given"),
        ("dla", dict(seed=4), "seed 3 in the checkpoint, 4 given"),
        ("dla", dict(step_min=0.2), "step_min 0.1 in the checkpoint, 0.2 given"),
        ("dla", dict(dim=3), "dim"),
        ("dlca", dict(temperature=0.5), "temperature 1.0 in the checkpoint, 0.5 given"),
        ("dlca", dict(fill=0.06), "fill/particles"),
        ("dlca", dict(seed=1), "seed 2 in the checkpoint, 1 given"),
        ("animat", dict(vision=20), "vision 60 in the checkpoint, 20 given"),
        ("animat", dict(seed=5), "seed 4 in the checkpoint, 5 given"),
    ],
)
def test_a_checkpoint_of_other_parameters_is_refused(model, other, named, tmp_path, monkeypatch):
    stopped_at_start(model, SMALL[model], tmp_path, monkeypatch)
    with pytest.raises(ValueError, match="checkpoint") as e:
        run(model, checkpoint=tmp_path, **{**SMALL[model], **other})
    assert named in str(e.value)
    # Nothing was touched: the right call still continues it.
    assert FILES[model] <= files(tmp_path)
    assert run(model, checkpoint=tmp_path, **SMALL[model]).state_hash == (
        run(model, **SMALL[model]).state_hash
    )


def test_a_checkpoint_of_another_model_is_refused(tmp_path, monkeypatch):
    stopped_at_start("animat", SMALL["animat"], tmp_path, monkeypatch)
    with pytest.raises(ValueError, match="checkpoint"):
        aggsim.dlca(checkpoint=tmp_path, **SMALL["dlca"])


def test_dla_particles_and_animat_steps_may_grow(tmp_path, monkeypatch):
    small, large = SMALL["dla"], {**SMALL["dla"], "particles": 30_000}
    stopped_at_start("dla", small, tmp_path / "dla", monkeypatch)
    grown = aggsim.dla(checkpoint=tmp_path / "dla", **large)
    assert grown.state_hash == aggsim.dla(**large).state_hash
    small, large = SMALL["animat"], {**SMALL["animat"], "steps": 150}
    stopped_at_start("animat", small, tmp_path / "animat", monkeypatch)
    grown = aggsim.animat(checkpoint=tmp_path / "animat", **large)
    assert grown.state_hash == aggsim.animat(**large).state_hash


def test_animat_steps_below_those_made_are_refused(tmp_path):
    kwargs = LONG["animat"]
    with pytest.raises(KeyboardInterrupt):
        aggsim.animat(checkpoint=tmp_path, progress=interrupt_at_first_report, **kwargs)
    with pytest.raises(ValueError, match="more than steps = 1"):
        aggsim.animat(checkpoint=tmp_path, **{**kwargs, "steps": 1})


@pytest.mark.parametrize("interval", [0, -1.0, float("inf"), float("nan")])
def test_checkpoint_interval_is_positive_seconds(interval, tmp_path):
    with pytest.raises(ValueError, match="checkpoint_interval"):
        aggsim.dla(particles=10, checkpoint=tmp_path, checkpoint_interval=interval)


@pytest.mark.parametrize("model", MODELS)
def test_signatures_show_the_binaries_interval(model):
    params = inspect.signature(getattr(aggsim, model)).parameters
    assert params["checkpoint"].default is None
    assert params["checkpoint_interval"].default == 300.0


def test_no_clock_with_interval_none(tmp_path):
    r = aggsim.dla(particles=2000, checkpoint=tmp_path, checkpoint_interval=None)
    assert r.particles == 2000 and files(tmp_path) == set()


def test_the_binaries_continue_a_checkpoint_written_from_python(cli, tmp_path, monkeypatch):
    kwargs = SMALL["dla"]
    stopped_at_start("dla", kwargs, tmp_path / "dla", monkeypatch)
    _, r = cli.run("dla", "--resume", tmp_path / "dla", "--particles", 20_000, "--seed", 3)
    assert r["results"]["state_hash"] == aggsim.dla(**kwargs).state_hash
    kwargs = SMALL["animat"]
    stopped_at_start("animat", kwargs, tmp_path / "animat", monkeypatch)
    flags = ["--steps", 100, "--foxes", 100, "--rabbits", 600, "--start-radius", 30]
    _, r = cli.run("animat", "--resume", tmp_path / "animat", "--seed", 4, *flags)
    assert r["results"]["state_hash"] == aggsim.animat(**kwargs).state_hash
    kwargs = SMALL["dlca"]
    stopped_at_start("dlca", kwargs, tmp_path / "dlca", monkeypatch)
    flags = ["--size", 128, "--fill", 0.05, "--target-clusters", 1, "--seed", 2]
    _, r = cli.run("dlca", "--resume", tmp_path / "dlca", *flags)
    assert r["results"]["state_hash"] == aggsim.dlca(**kwargs).state_hash


def test_python_continues_a_checkpoint_of_the_binaries(cli):
    out, _ = cli.run("dla", "--particles", 5000, "--seed", 3, "--checkpoint-every", 1000)
    r = aggsim.dla(checkpoint=out, **SMALL["dla"])
    assert r.state_hash == aggsim.dla(**SMALL["dla"]).state_hash
    assert r.positions.shape == (20_000, 2)
    assert not (out / "checkpoint.bin").exists()
    out, _ = cli.run(
        "animat", "--steps", 50, "--foxes", 100, "--rabbits", 600, "--start-radius", 30,
        "--seed", 4, "--checkpoint-every", 10,
    )
    assert aggsim.animat(checkpoint=out, **SMALL["animat"]).state_hash == (
        aggsim.animat(**SMALL["animat"]).state_hash
    )
    out, _ = cli.run(
        "dlca", "--size", 128, "--fill", 0.05, "--target-clusters", 1, "--seed", 2,
        "--checkpoint-every", 100,
    )
    assert aggsim.dlca(checkpoint=out, **SMALL["dlca"]).state_hash == (
        aggsim.dlca(**SMALL["dlca"]).state_hash
    )
