"""Shared fixtures: the repository, the `dlo` binary (built if missing) and a log folder that
CI reads with both reference MCAP readers."""

import json
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
CASES = ROOT / "planning_cases"


@pytest.fixture(scope="session")
def dlo_bin() -> pathlib.Path:
    exe = ROOT / "target" / "release" / "dlo"
    if not exe.exists():
        subprocess.run(
            ["cargo", "build", "--release", "--locked", "--bin", "dlo"], cwd=ROOT, check=True
        )
    return exe


@pytest.fixture(scope="session")
def log_dir() -> pathlib.Path:
    d = ROOT / "target" / "test-logs" / "python"
    d.mkdir(parents=True, exist_ok=True)
    return d


def cli_json(exe: pathlib.Path, *args: str) -> dict:
    """Runs `dlo ARGS --json` and returns its report (any exit code: the verdict is in it)."""
    out = subprocess.run([str(exe), *args, "--json"], capture_output=True, text=True, cwd=ROOT)
    assert out.stdout, out.stderr
    return json.loads(out.stdout)
