"""Does a run release the GIL? Two models run one after the other, then at once in two
Python threads; the ratio of wall times is printed. With the GIL released during the runs the
concurrent pair takes about half the sequential time on two free cores (ratio near 0.5);
holding it would make the ratio 1 or more.

    python python/bench/gil.py [--repeats 3] [--particles 400000] [--steps 300]

A benchmark, not a test: the ratio depends on the machine and on what else runs on it.
"""

import argparse
import statistics
import threading
import time

import aggsim


def jobs(particles, steps):
    """Two runs of similar length on different models (one thread each)."""
    return [
        lambda: aggsim.dla(particles=particles, seed=1),
        lambda: aggsim.animat(steps=steps, seed=1),
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeats", type=int, default=3, help="interleaved pairs (default 3)")
    ap.add_argument("--particles", type=int, default=400_000, help="DLA particles")
    ap.add_argument("--steps", type=int, default=300, help="animat steps")
    a = ap.parse_args()
    work = jobs(a.particles, a.steps)
    for i, job in enumerate(work):
        start = time.perf_counter()
        job()
        print(f"job {i}: {time.perf_counter() - start:.2f} s alone")
    ratios = []
    for r in range(a.repeats):
        s = sequential(work)
        c = concurrent(work)
        ratios.append(c / s)
        print(f"pair {r + 1}: sequential {s:.2f} s, two threads {c:.2f} s, ratio {c / s:.3f}")
    print(f"median ratio (two threads / sequential): {statistics.median(ratios):.3f}")


if __name__ == "__main__":
    main()
