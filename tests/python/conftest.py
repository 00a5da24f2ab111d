"""Shared fixtures of the Python suite. CTest sets PYTHONPATH to the build tree's package,
OMNICAL_SOURCE_DIR and OMNICAL_BINARY (the CLI, to compare against)."""
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("OMNICAL_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
DATA = SOURCE_DIR / "datasets-synthetic"


@pytest.fixture
def data():
    """datasets-synthetic/ of the source tree."""
    return DATA


@pytest.fixture
def cli():
    """Runs the omnical CLI: cli(*args) -> CompletedProcess (text, not checked)."""
    binary = os.environ.get("OMNICAL_BINARY")
    if not binary:
        pytest.skip("OMNICAL_BINARY not set (run through ctest)")

    def run(*args):
        return subprocess.run([binary, *map(str, args)], capture_output=True, text=True)
    return run


def cli_error(completed):
    """The one-line message the CLI printed for bad input (after 'omnical: error: ')."""
    assert completed.returncode != 0, completed.stdout
    lines = [line for line in completed.stderr.splitlines() if line.startswith("omnical: error: ")]
    assert len(lines) == 1, completed.stderr
    return lines[0][len("omnical: error: "):]
