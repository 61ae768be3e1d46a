"""Test configuration (doctests in src/ and tests/ alike).

Plots render headless. Nothing here reaches outside the repository: the data sets ship
inside the package. A bare ``pytest`` in an environment without the package's
dependencies stops at once with the command that installs them, instead of
one import error per test module.

The suite runs on up to four processes (pytest-xdist; ``addopts`` in pyproject.toml):
the numba kernels compile once per process, so a cold run takes half the time on two
cores. ``pytest -n 0`` runs it in one process.
"""

import importlib.util
import os
import sys

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")

# pytest.approx(x, rel=r) also accepts anything within 1e-12 of x: for the 1e-13 deviations
# of clocks and the 1e-15 variances of good gyros that makes every comparison pass. Here it is
# relative alone unless a test names its own abs.
_APPROX_SCALAR = type(pytest.approx(1.0))  # pytest's class; its module moved between versions
_APPROX_SCALAR.DEFAULT_ABSOLUTE_TOLERANCE = 0.0
if 1e-15 == pytest.approx(2e-15, rel=1e-6):  # a pytest that reads its tolerance elsewhere: say so
    raise RuntimeError("conftest.py could not make pytest.approx relative; check DEFAULT_ABSOLUTE_TOLERANCE")

#: What ``pip install ".[test]"`` brings that every test module needs (import name: package).
REQUIRED = {"numpy": "numpy", "scipy": "scipy", "pandas": "pandas", "matplotlib": "matplotlib",
            "numba": "numba", "yaml": "pyyaml", "tqdm": "tqdm", "avar": "avar", "xdist": "pytest-xdist"}


def pytest_addoption(parser):
    # Without pytest-xdist, the "--numprocesses" of pyproject's addopts would stop pytest at its command
    # line, before pytest_configure can name what is missing: accept it, then say so there.
    if importlib.util.find_spec("xdist") is None:
        parser.addoption("--numprocesses", dest="numprocesses", default=None)
        parser.addoption("--maxprocesses", dest="maxprocesses", default=None)


def pytest_configure(config):
    missing = [package for module, package in REQUIRED.items() if importlib.util.find_spec(module) is None]
    if missing:
        pytest.exit(f"this Python ({sys.executable}) lacks {', '.join(missing)}; run the README's test command, "
                    f"pip install \".[test]\" && pytest", returncode=4)
