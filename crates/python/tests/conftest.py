"""Shared fixtures: the repository root and the `prism` binary the results are checked
against (PRISM_BIN, set by crates/python/run-tests.sh; else the workspace's build)."""

import json
import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]


def _prism_binary():
    given = os.environ.get("PRISM_BIN")
    if given:
        return pathlib.Path(given)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for profile in ("debug", "release"):
        candidate = target / profile / "prism"
        if candidate.is_file():
            return candidate
    return None


@pytest.fixture(scope="session")
def root():
    return ROOT


@pytest.fixture(scope="session")
def prism_bin():
    binary = _prism_binary()
    if binary is None or not binary.is_file():
        pytest.fail(
            "no prism binary to compare with: set PRISM_BIN or build it "
            "(cargo build --bin prism); crates/python/run-tests.sh does both"
        )
    return binary


@pytest.fixture(scope="session")
def cli(prism_bin):
    """Runs the CLI; returns the CompletedProcess (text)."""

    def run(*args, check=True):
        done = subprocess.run(
            [str(prism_bin), *map(str, args)],
            cwd=ROOT,
            capture_output=True,
            text=True,
        )
        if check and done.returncode != 0:
            raise AssertionError(f"prism {' '.join(map(str, args))} failed:\n{done.stderr}")
        return done

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    def run(*args):
        return json.loads(cli(*args).stdout)

    return run
