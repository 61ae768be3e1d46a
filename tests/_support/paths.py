"""Where the test data live, for every test module whatever its folder."""

from pathlib import Path

#: The repository's root (holds README.md, docs/, pyproject.toml).
REPOSITORY = Path(__file__).resolve().parents[2]
#: tests/data: published tables and records the tests read (each with its source).
DATA = REPOSITORY / "tests" / "data"
#: Stable32's tables and data files.
STABLE32 = DATA / "stable32"
