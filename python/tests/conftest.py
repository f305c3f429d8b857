"""Shared fixtures: the repository's ``dla``, ``dlca`` and ``animat`` binaries, run at small
sizes to compare the Python package with them (same seed and parameters, same results)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PROGRAMS = ("dla", "dlca", "animat")


def _bin_dir():
    """AGGSIM_BIN_DIR, else target/release or target/debug if every binary is there; else the
    debug binaries are built (cargo build, the workspace's default features)."""
    given = os.environ.get("AGGSIM_BIN_DIR")
    if given:
        return Path(given)
    for profile in ("release", "debug"):
        d = ROOT / "target" / profile
        if all((d / p).exists() for p in PROGRAMS):
            return d
    subprocess.run(
        ["cargo", "build", "-p", "dla-pdla", "-p", "dlca", "-p", "animat", "--bins"],
        cwd=ROOT,
        check=True,
    )
    return ROOT / "target" / "debug"


@pytest.fixture(scope="session")
def bin_dir():
    return _bin_dir()


class Cli:
    """Runs a binary into a fresh directory."""

    def __init__(self, bin_dir, tmp_path_factory):
        self.bin_dir = bin_dir
        self.tmp = tmp_path_factory

    def run(self, program, *flags):
        """Runs ``program --out DIR -qq flags`` and returns DIR and its run.json."""
        out = self.tmp.mktemp(program)
        cmd = [str(self.bin_dir / program), "--out", str(out), "-qq", *map(str, flags)]
        p = subprocess.run(cmd, capture_output=True, text=True)
        assert p.returncode == 0, f"{cmd}: {p.stderr}"
        return out, json.loads((out / "run.json").read_text())

    def error(self, program, *flags):
        """The message of ``program: error: MESSAGE`` a usage error prints (exit code 2)."""
        out = self.tmp.mktemp(program)
        cmd = [str(self.bin_dir / program), "--out", str(out / "o"), "-qq", *map(str, flags)]
        p = subprocess.run(cmd, capture_output=True, text=True)
        assert p.returncode == 2, f"{cmd}: exit {p.returncode}: {p.stderr}"
        line = p.stderr.strip().splitlines()[-1]
        prefix = f"{program}: error: "
        assert line.startswith(prefix), line
        return line[len(prefix):]


@pytest.fixture(scope="session")
def cli(bin_dir, tmp_path_factory):
    return Cli(bin_dir, tmp_path_factory)


def pytest_report_header(config):
    return f"aggsim binaries: {_bin_dir()} (python {sys.version.split()[0]})"
