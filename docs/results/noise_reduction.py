"""Noise-reduced DLA (f = 0.25) against fastDLA's clusters with the same factor: R_g(N) of
each code's clusters, mean and standard error over an ensemble, side by side.

    python docs/results/noise_reduction.py FASTDLA [DLA] [--clusters 8] [--particles 100000]

FASTDLA is mathsjames/fastDLA built from its public source outside this repository
(`g++ --std=gnu++11 -O3 -o fastDLA fastDLA.cpp`, its `compile` script); DLA is the `dla`
binary (default target/release/dla). Writes noise_reduction.csv and noise_reduction.md beside
this script. fastDLA's particles have radius 1 (diameter 2): its coordinates are halved so
that both are in diameters; its noiseReductionFactor places a particle at f of the way from
the particle it touched to its contact point, as `dla --noise-reduction f` does (fastDLA
leaves the first particle at full distance from the seed). Needs numpy.
"""

import argparse
import json
import math
import pathlib
import subprocess
import tempfile

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
F = 0.25


def rg_curve(points, sizes):
    """R_g of the first n points for every n in sizes (points: (N, 2) in diameters)."""
    c = np.cumsum(points, axis=0)
    c2 = np.cumsum((points * points).sum(axis=1))
    out = []
    for n in sizes:
        mean = c[n - 1] / n
        out.append(math.sqrt(max(c2[n - 1] / n - (mean * mean).sum(), 0.0)))
    return np.array(out)


def slope(sizes, rg):
    """D from the least-squares line of ln N against ln R_g."""
    return np.polyfit(np.log(rg), np.log(sizes), 1)[0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("fastdla")
    ap.add_argument("dla", nargs="?", default=str(HERE.parents[1] / "target/release/dla"))
    ap.add_argument("--clusters", type=int, default=8)
    ap.add_argument("--particles", type=int, default=100_000)
    ap.add_argument("--factor", type=float, default=F, help="noise-reduction factor")
    ap.add_argument("--out", default="noise_reduction", help="stem of the files written")
    a = ap.parse_args()
    f = a.factor
    n = a.particles
    sizes = np.unique(np.round(np.logspace(2, math.log10(n), 21)).astype(int))
    ours, theirs = [], []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        for seed in range(1, a.clusters + 1):
            out = tmp / f"dla-{seed}"
            subprocess.run(
                [a.dla, "--particles", str(n), "--seed", str(seed), "--noise-reduction", str(f),
                 "--positions", "npy", "--no-checkpoint", "-qq", "--out", str(out)],
                check=True,
            )
            ours.append(rg_curve(np.load(out / "positions.npy"), sizes))
            path = tmp / f"fast-{seed}.bin"
            subprocess.run([a.fastdla, str(n), str(path), str(seed), str(f)], check=True,
                           stdout=subprocess.DEVNULL)
            z = np.fromfile(path, dtype=np.complex128)[:n] / 2.0
            theirs.append(rg_curve(np.stack([z.real, z.imag], axis=1), sizes))
    ours, theirs = np.array(ours), np.array(theirs)
    k = a.clusters
    rows = []
    for i, s in enumerate(sizes):
        mo, so = ours[:, i].mean(), ours[:, i].std(ddof=1) / math.sqrt(k)
        mt, st = theirs[:, i].mean(), theirs[:, i].std(ddof=1) / math.sqrt(k)
        z = (mo - mt) / math.hypot(so, st)
        rows.append((s, mo, so, mt, st, mo / mt, z))
    with open(HERE / f"{a.out}.csv", "w") as out:
        out.write("n,dla_rg,dla_rg_stderr,fastdla_rg,fastdla_rg_stderr,ratio,z\n")
        for r in rows:
            out.write(",".join(str(x) for x in r) + "\n")
    fit = sizes >= 1000
    d_ours = [slope(sizes[fit], c[fit]) for c in ours]
    d_theirs = [slope(sizes[fit], c[fit]) for c in theirs]
    pm = lambda v: f"{np.mean(v):.4f} ± {np.std(v, ddof=1) / math.sqrt(len(v)):.4f}"
    md = [
        f"# Noise-reduced DLA against fastDLA (f = {f})",
        "",
        f"Written by `python docs/results/noise_reduction.py FASTDLA` ({k} clusters of {n} "
        f"particles per code, seeds 1 to {k}, 2D, noise-reduction factor {f}; fastDLA "
        "(mathsjames/fastDLA, built from its public source outside the repository with its "
        "`compile` script) in its own units halved to diameters). R_g of the first N "
        "particles of each cluster, mean ± standard error over the clusters; z is the "
        "difference over its standard error. Data: "
        f"[`{a.out}.csv`]({a.out}.csv).",
        "",
        "| N | dla R_g | fastDLA R_g | ratio | z |",
        "|---|---|---|---|---|",
    ]
    for s, mo, so, mt, st, ratio, z in rows:
        if s in (100, 1000, 10000, 100000) or s == sizes[-1]:
            md.append(f"| {s} | {mo:.3f} ± {so:.3f} | {mt:.3f} ± {st:.3f} | {ratio:.4f} | {z:+.2f} |")
    md += [
        "",
        f"D from ln N against ln R_g over N = 1000 to {n}, mean over the clusters: dla "
        f"{pm(d_ours)}, fastDLA {pm(d_theirs)}.",
        "",
    ]
    (HERE / f"{a.out}.md").write_text("\n".join(md))
    print("\n".join(md))
    print(json.dumps({"max_abs_z": max(abs(r[-1]) for r in rows)}))


if __name__ == "__main__":
    main()
