"""The package metadata a user meets on PyPI (``.ci/run`` builds and installs the wheel for real)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import avar

tomllib = pytest.importorskip("tomllib")
ROOT = Path(__file__).resolve().parent.parent
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_distribution_name_import_name_and_command():
    project = PROJECT["project"]
    assert project["name"] == "allanvar"  # "avar" on PyPI is unrelated software
    assert project["scripts"] == {"avar": "avar.cli:main"}
    assert project["version"] == avar.__version__
    assert (ROOT / "src" / "avar" / "__init__.py").is_file()


def test_licence_classifiers_and_urls():
    project = PROJECT["project"]
    assert project["license"] == "AGPL-3.0-or-later"  # PEP 639 SPDX expression
    assert not any(c.startswith("License ::") for c in project["classifiers"])  # PEP 639: no licence classifier
    assert "Typing :: Typed" in project["classifiers"]
    assert {"Homepage", "Source", "Issues", "Changelog"} <= set(project["urls"])
    build = PROJECT["build-system"]["requires"]
    assert any(re.fullmatch(r"setuptools>=(\d+)", r) and int(r.split(">=")[1]) >= 77 for r in build)


def test_data_sets_and_type_marker_are_package_data():
    data = PROJECT["tool"]["setuptools"]["package-data"]
    assert "data/*.npz" in data["avar.io"] and "py.typed" in data["avar"]
    assert (ROOT / "src" / "avar" / "py.typed").is_file()
    assert len(list((ROOT / "src" / "avar" / "io" / "data").glob("*.npz"))) == len(avar.datasets.list())


def test_readme_and_changelog_name_the_distribution():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert "pip install . && avar demo" in readme and 'pip install ".[test]" && pytest' in readme
    assert "pip install allanvar" in readme
    assert not re.search(r'pip install "?avar\[', readme)  # extras of the PyPI name, never of "avar"
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    assert f"[{avar.__version__}]" in changelog and "Unreleased" in changelog


def test_test_extra_brings_the_package_tools():
    test = " ".join(PROJECT["project"]["optional-dependencies"]["test"])
    assert "build" in test and "twine" in test
