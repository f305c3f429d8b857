"""Does a run release the GIL? Two models run one after the other, then at once in two
Python threads; the ratio of wall times is printed. With the GIL released during the runs the
concurrent pair takes about half the sequential time on two free cores (ratio near 0.5);
holding it would make the ratio 1 or more.

    python python/bench/gil.py [--repeats 3] [--particles 300000] [--size 1024]

A benchmark, not a test: the ratio depends on the machine and on what else runs on it (on
a machine whose cores are busy with other work it stays near 1 whatever the GIL does). So it
also counts the iterations of a pure Python loop in the main thread while a model runs in
another thread, against the loop alone: near 1 when the model releases the GIL, near 0 when
it holds it.
"""

import argparse
import statistics
import threading
import time

import aggsim


def jobs(particles, size):
    """Two runs of similar length (2 to 3 s each here) on different models, one thread each."""
    return [
        lambda: aggsim.dla(particles=particles, seed=1),
        lambda: aggsim.dlca(size=size, fill=0.05, seed=1),
    ]


def sequential(work):
    start = time.perf_counter()
    for job in work:
        job()
    return time.perf_counter() - start


def concurrent(work):
    threads = [threading.Thread(target=job) for job in work]
    start = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return time.perf_counter() - start


def python_loop(seconds):
    """Iterations of a pure Python loop in ``seconds``."""
    n, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        n += 1
    return n


def loop_share(job, seconds=1.0):
    """Python loop iterations while ``job`` runs in another thread, over those alone."""
    alone = python_loop(seconds)
    t = threading.Thread(target=job)
    t.start()
    during = python_loop(seconds)
    t.join()
    return during / alone


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=3, help="interleaved pairs (default 3)")
    ap.add_argument("--particles", type=int, default=300_000, help="DLA particles")
    ap.add_argument("--size", type=int, default=1024, help="DLCA lattice side (fill 0.05)")
    a = ap.parse_args()
    work = jobs(a.particles, a.size)
    for i, job in enumerate(work):
        start = time.perf_counter()
        job()
        print(f"job {i}: {time.perf_counter() - start:.2f} s alone")
    for i, job in enumerate(work):
        print(f"job {i}: the main thread's Python loop keeps {loop_share(job):.2f} of its speed")
    ratios = []
    for r in range(a.repeats):
        s = sequential(work)
        c = concurrent(work)
        ratios.append(c / s)
        print(f"pair {r + 1}: sequential {s:.2f} s, two threads {c:.2f} s, ratio {c / s:.3f}")
    print(f"median ratio (two threads / sequential): {statistics.median(ratios):.3f}")


if __name__ == "__main__":
    main()
