"""`cmake --install` puts an importable package where Debian's interpreter looks under the prefix."""

import os
import pathlib
import subprocess
import sys

import pytest


def test_the_installed_package_imports_and_works(tmp_path):
    build, cmake = os.environ.get("LENSMITH_BUILD_DIR"), os.environ.get("LENSMITH_CMAKE")
    if not build or not cmake:
        pytest.skip("LENSMITH_BUILD_DIR and LENSMITH_CMAKE are set by ctest")
    subprocess.run([cmake, "--install", build, "--prefix", str(tmp_path)], check=True, capture_output=True)
    packages = tmp_path / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "dist-packages"
    assert (packages / "lensmith" / "__init__.py").is_file()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(packages)
    done = subprocess.run([sys.executable, "-c", "import lensmith; print(lensmith.__file__); "
                           "print(lensmith.Lens.load('sasian-triplet').paraxial().efl_mm)"],
                          env=env, capture_output=True, text=True, check=True, cwd=tmp_path)
    where, efl = done.stdout.split()
    assert pathlib.Path(where).is_relative_to(packages)
    assert float(efl) == pytest.approx(50.0, abs=0.01)  # Sasian's triplet is a 50 mm design
