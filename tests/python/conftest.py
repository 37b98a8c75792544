"""Shared fixtures of the Python module's tests (docs/python.md).

ctest runs each file with PYTHONPATH at the build tree's package and LENSMITH_CLI at the command,
so that the module's results can be compared with the command's --json output of the same build.
"""

import json
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(__file__).resolve().parents[2]
ZEMAX_DIR = SOURCE_DIR / "tests" / "data" / "zemax"


@pytest.fixture(scope="session")
def cli():
    """Runs the lensmith command; returns its parsed --json output (stdout) or raises with its stderr."""
    path = os.environ.get("LENSMITH_CLI")
    if not path:
        pytest.skip("LENSMITH_CLI is not set (ctest sets it to the built command)")

    def run(*args, parse=True):
        done = subprocess.run([path, "--quiet", *map(str, args)], capture_output=True, text=True)
        if done.returncode != 0:
            raise AssertionError(f"lensmith {' '.join(map(str, args))} exited {done.returncode}: {done.stderr}")
        return json.loads(done.stdout) if parse else done

    return run


def assert_same_json(ours, theirs, rel=1e-9, path="$"):
    """Equal structure and keys; numbers equal to `rel` relative (the module and the command run the
    same code, so anything looser than rounding is a difference in how options reach the library)."""
    if isinstance(theirs, dict):
        assert isinstance(ours, dict), f"{path}: {type(ours).__name__} instead of an object"
        assert list(ours) == list(theirs), f"{path}: keys {list(ours)} != {list(theirs)}"
        for key in theirs:
            assert_same_json(ours[key], theirs[key], rel, f"{path}.{key}")
    elif isinstance(theirs, list):
        assert isinstance(ours, list) and len(ours) == len(theirs), f"{path}: list of {len(ours)} != {len(theirs)}"
        for i, (a, b) in enumerate(zip(ours, theirs)):
            assert_same_json(a, b, rel, f"{path}[{i}]")
    elif isinstance(theirs, float) and not isinstance(theirs, bool):
        assert ours == pytest.approx(theirs, rel=rel, abs=1e-300), f"{path}: {ours!r} != {theirs!r}"
    else:
        assert ours == theirs, f"{path}: {ours!r} != {theirs!r}"
