"""Grow a 2D DLA cluster from Python, plot it, and fit its fractal dimension from the growth
samples: R_g ~ N^(1/D_f), so D_f = 1 / slope of log R_g against log N.

    pip install ./python matplotlib
    python examples/dla_fit.py [--particles 100000] [--seed 1] [--out dla_fit.png]

The fit uses N from 1000 (past the first few hundred particles, where the cluster is not yet
fractal) to the end, as the `dla` binary's own fit (--fit-from 1000); the 2D DLA value is
about 1.71. Writes a figure with the cluster, shaded by arrival order, and the fit.
"""

import argparse

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt
import numpy as np

import aggsim


def fit_fractal_dimension(growth, n_min):
    """D_f and its standard error from a least-squares line through (log N, log R_g), N >= n_min."""
    n = growth["n"].astype(float)
    keep = n >= n_min
    x, y = np.log(n[keep]), np.log(growth["radius_of_gyration"][keep])
    (slope, intercept), cov = np.polyfit(x, y, 1, cov=True)
    d_f = 1.0 / slope
    # d(1/s) = ds / s^2. Log-spaced samples of one growing cluster are correlated: this error
    # is a lower bound (an ensemble of seeds gives an honest one).
    return d_f, np.sqrt(cov[0, 0]) / slope**2, slope, intercept, keep


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--particles", type=int, default=100_000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--fit-from", type=int, default=1000)
    ap.add_argument("--out", default="dla_fit.png")
    a = ap.parse_args()

    r = aggsim.dla(dim=2, particles=a.particles, seed=a.seed, progress=True)
    print(r)
    d_f, err, slope, intercept, keep = fit_fractal_dimension(r.growth, a.fit_from)
    print(f"D_f = 1/slope of log R_g vs log N (N >= {a.fit_from}): {d_f:.4f} +- {err:.4f}")
    print(f"the run's own fit (log N vs log R_g): {r.fractal_dimension:.4f} "
          f"+- {r.fractal_dimension_stderr:.4f}")

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 6))
    x, y = r.positions[:, 0], r.positions[:, 1]
    ax1.scatter(x, y, c=np.arange(len(x)), s=0.4, cmap="viridis", linewidths=0)
    ax1.set_aspect("equal")
    ax1.set_title(f"2D DLA, {r.particles} particles (colour: arrival order)")
    n, rg = r.growth["n"].astype(float), r.growth["radius_of_gyration"]
    ax2.loglog(n, rg, ".", ms=2, color="0.6", label="growth samples")
    ax2.loglog(n[keep], np.exp(intercept) * n[keep] ** slope, "r-",
               label=f"fit N >= {a.fit_from}: D_f = {d_f:.3f}")
    ax2.set_xlabel("N (particles)")
    ax2.set_ylabel("R_g (diameters)")
    ax2.legend()
    fig.tight_layout()
    fig.savefig(a.out, dpi=120)
    print(f"figure: {a.out}")


if __name__ == "__main__":
    main()
