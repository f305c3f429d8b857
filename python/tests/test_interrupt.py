"""Ctrl-C (SIGINT) during a long run raises KeyboardInterrupt promptly, and a step-wise
object is left consistent: it continues to the run it would have made uninterrupted."""

import _thread
import signal
import threading
import time

import numpy as np
import pytest

import aggsim

# Seconds after the signal within which the run must have stopped: a particle, a sweep or a
# step of the runs below takes milliseconds, and the signal is checked every 50 ms. Generous
# for a busy machine; this bounds a hang, it is not a speed measurement.
PROMPT = 3.0
# Seconds into the run at which the signal comes.
AFTER = 0.3


@pytest.fixture(autouse=True)
def python_handles_sigint():
    """Python's own SIGINT handler (which raises KeyboardInterrupt) for each test: a Python
    started with SIGINT ignored, as a background job of a non-interactive shell is, keeps it
    ignored, and then neither signal below would reach the run."""
    before = signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)


def interrupted(call, send):
    """Runs ``call`` with ``send()`` from another thread after AFTER seconds; returns the seconds
    from the signal to KeyboardInterrupt."""
    timer = threading.Timer(AFTER, send)
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        timer.cancel()
    return time.monotonic() - start - AFTER


SENDERS = {
    "interrupt_main": _thread.interrupt_main,
    "SIGINT": lambda: signal.raise_signal(signal.SIGINT),
}


@pytest.mark.parametrize("send", SENDERS.values(), ids=list(SENDERS))
@pytest.mark.parametrize(
    "call",
    [
        lambda: aggsim.dla(particles=100_000_000),
        lambda: aggsim.dla(particles=10_000_000, threads=2),
        lambda: aggsim.dlca(size=1024, fill=0.03, target_clusters=1),
        lambda: aggsim.animat(steps=10**9),
    ],
    ids=["dla", "pdla", "dlca", "animat"],
)
def test_long_runs_stop_promptly(call, send):
    assert interrupted(call, send) < PROMPT


def test_interrupted_lattice_continues_as_if_never_stopped():
    lat = aggsim.DlcaLattice(1024, 0.03, seed=2, target_clusters=1)
    assert interrupted(lambda: lat.step(10**9), _thread.interrupt_main) < PROMPT
    done = lat.sweeps
    assert 0 < done and not lat.done
    assert len(lat.per_sweep["sweep"]) == done + 1
    lat.step(3)
    fresh = aggsim.DlcaLattice(1024, 0.03, seed=2, target_clusters=1)
    fresh.step(done + 3)
    assert lat.state_hash == fresh.state_hash
    np.testing.assert_array_equal(lat.per_sweep["clusters"], fresh.per_sweep["clusters"])


def test_interrupted_world_continues_as_if_never_stopped():
    world = aggsim.AnimatWorld(4)
    assert interrupted(lambda: world.step(10**9), _thread.interrupt_main) < PROMPT
    done = world.steps
    assert 0 < done
    assert world.populations["step"][-1] == done
    world.step(2)
    fresh = aggsim.AnimatWorld(4)
    fresh.step(done + 2)
    assert world.state_hash == fresh.state_hash


def test_an_exception_in_the_progress_callback_stops_the_run():
    def fail(done, total):
        raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough"):
        aggsim.dla(particles=100_000_000, progress=fail)
