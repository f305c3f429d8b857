"""The cost of Python: a 2D DLA of 1e6 particles from Python against the `dla` binary with the
same seed and parameters, in interleaved pairs (binary, then Python, repeated), each timed by
wall clock around the whole call (for the binary: the process, start to exit).

    cargo build --release -p dla-pdla        # target/release/dla
    pip install ./python                     # release build of the package
    python python/bench/overhead.py [--pairs 4] [--particles 1000000]

Prints each pair's wall and CPU seconds (CPU: getrusage of the binary's process, and of this
process during the Python call), the medians and the ratios Python / binary, and checks that
both runs ended in the same state (state hash). CPU seconds vary less than wall seconds on a
shared machine. Build first: timing while compiling measures the compiler.
"""

import argparse
import json
import resource
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import aggsim

ROOT = Path(__file__).resolve().parents[2]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pairs", type=int, default=4)
    ap.add_argument("--particles", type=int, default=1_000_000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--binary", type=Path, default=ROOT / "target" / "release" / "dla")
    a = ap.parse_args()
    wall = {"binary": [], "python": []}
    cpu = {"binary": [], "python": []}

    def cpu_of(who):
        u = resource.getrusage(who)
        return u.ru_utime + u.ru_stime

    with tempfile.TemporaryDirectory() as tmp:
        for i in range(a.pairs):
            out = Path(tmp) / f"run{i}"
            cmd = [str(a.binary), "--particles", str(a.particles), "--seed", str(a.seed),
                   "-q", "--out", str(out)]
            c0, start = cpu_of(resource.RUSAGE_CHILDREN), time.perf_counter()
            subprocess.run(cmd, check=True, stderr=subprocess.DEVNULL)
            wall["binary"].append(time.perf_counter() - start)
            cpu["binary"].append(cpu_of(resource.RUSAGE_CHILDREN) - c0)
            c0, start = cpu_of(resource.RUSAGE_SELF), time.perf_counter()
            r = aggsim.dla(particles=a.particles, seed=a.seed)
            wall["python"].append(time.perf_counter() - start)
            cpu["python"].append(cpu_of(resource.RUSAGE_SELF) - c0)
            hash_cli = json.loads((out / "run.json").read_text())["results"]["state_hash"]
            assert r.state_hash == hash_cli, (r.state_hash, hash_cli)
            del r
            print(f"pair {i + 1}: wall binary {wall['binary'][-1]:.3f} s, python "
                  f"{wall['python'][-1]:.3f} s; cpu binary {cpu['binary'][-1]:.3f} s, python "
                  f"{cpu['python'][-1]:.3f} s")
    for name, t in (("wall", wall), ("cpu", cpu)):
        b, p = statistics.median(t["binary"]), statistics.median(t["python"])
        ratios = [y / x for x, y in zip(t["binary"], t["python"])]
        print(f"{name}: median binary {b:.3f} s, python {p:.3f} s, ratio of medians "
              f"{p / b:.4f}; per-pair ratios median {statistics.median(ratios):.4f} "
              f"(min {min(ratios):.4f}, max {max(ratios):.4f})")

if __name__ == "__main__":
    main()
