"""DLCA's fractal dimension pooled over an ensemble: ``aggsim.dlca_pooled_fit`` over runs made
in Python gives the binary's ``ensemble.json`` ``pooled.fractal_dimension`` for the same seeds
and parameters."""

import json
import subprocess

import pytest

import aggsim

FLAGS = dict(size=128, fill=0.01, target_clusters=10)


def test_the_pooled_fit_is_the_binarys_ensemble_result(bin_dir, tmp_path):
    out = tmp_path / "ensemble"
    cmd = [
        str(bin_dir / "dlca"), "--size", "128", "--fill", "0.01", "--target-clusters", "10",
        "--gyration", "--seeds", "1..=4", "--jobs", "1", "-qq", "--out", str(out),
    ]
    p = subprocess.run(cmd, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    ensemble = json.loads((out / "ensemble.json").read_text())
    expected = ensemble["pooled"]["fractal_dimension"]
    runs = [aggsim.dlca(seed=s, gyration=True, **FLAGS) for s in range(1, 5)]
    got = aggsim.dlca_pooled_fit(runs)
    assert got == expected
    # Beside it, the mean of the members' own fits is the ensemble's per-member mean.
    assert got["per_member_mean"] == pytest.approx(ensemble["results"]["fractal_dimension"]["mean"])
    assert got["members"] == 4 and got["stderr_method"] == "jackknife over members"
    assert got["fractal_dimension_stderr"] > 0


def test_runs_without_gyration_or_clusters_are_refused():
    with pytest.raises(ValueError, match=r"results\[0\] was run without gyration=True"):
        aggsim.dlca_pooled_fit([aggsim.dlca(seed=1, **FLAGS)])
    with pytest.raises(ValueError, match="nothing to pool"):
        aggsim.dlca_pooled_fit([])
    one = aggsim.dlca_pooled_fit([aggsim.dlca(seed=1, gyration=True, **FLAGS)])
    assert one["fractal_dimension_stderr"] is None and one["members"] == 1
