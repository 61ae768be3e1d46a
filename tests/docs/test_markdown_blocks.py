"""Every ```python block of the Markdown documentation runs as written, on its own.

The files: docs/*.md, CONTRIBUTING.md and benchmarks/README.md (README.md's blocks are
doctests that pytest collects itself, ``--doctest-glob=README.md``). Each block is one test,
named by its file and line, run in a fresh namespace in a temporary working directory, so a
block builds its own data and writes its files where the test cleans up. A block written as a
doctest (``>>>``) runs through doctest with the suite's option flags (pyproject.toml's
``doctest_optionflags``, as README.md's); any other block is executed and must not raise.
"""

from __future__ import annotations

import doctest
import linecache
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FILES = [*sorted((ROOT / "docs").glob("*.md")), ROOT / "CONTRIBUTING.md", ROOT / "benchmarks" / "README.md"]
#: A fenced block: the fence's indentation, its info string and its body (up to the closing fence).
FENCE = re.compile(r"^(?P<indent>[ \t]*)```(?P<info>[^\n`]*)\n(?P<body>.*?)^(?P=indent)```[ \t]*$", re.M | re.S)


def fenced_blocks():
    """Every fenced block of FILES: (file, line of its first code line, info string, code)."""
    for path in FILES:
        if not path.is_file():
            continue
        text = path.read_text(encoding="utf-8")
        for match in FENCE.finditer(text):
            indent = len(match["indent"])
            code = "".join(row[indent:] for row in match["body"].splitlines(keepends=True))
            info = (match["info"].split() or [""])[0]  # ```python title="x": the language alone
            yield path, text.count("\n", 0, match.start("body")) + 1, info, code


def python_blocks() -> list:
    """One pytest.param per ```python block, named by its file and line."""
    return [pytest.param(path, line, code, id=f"{path.relative_to(ROOT)}:{line}")
            for path, line, info, code in fenced_blocks() if info == "python"]


BLOCKS = python_blocks()


def doctest_flags(config) -> int:
    """The suite's ``doctest_optionflags`` (NORMALIZE_WHITESPACE, ELLIPSIS, NUMBER ...) as doctest's bits."""
    names = config.getini("doctest_optionflags") or []
    return sum(doctest.register_optionflag(name) for name in names)


def output_checker() -> doctest.OutputChecker:
    """pytest's checker (it implements NUMBER, as for README.md); doctest's own if pytest moves it."""
    try:
        from _pytest.doctest import _get_checker
    except ImportError:  # pragma: no cover
        return doctest.OutputChecker()
    return _get_checker()


def run_doctest(path: Path, line: int, code: str, flags: int) -> None:
    test = doctest.DocTestParser().get_doctest(code, {"__name__": "__docs__"}, path.name, str(path), line - 1)
    report: list[str] = []
    runner = doctest.DocTestRunner(checker=output_checker(), optionflags=flags, verbose=False)
    runner.run(test, out=report.append)
    assert runner.failures == 0, "".join(report)


def run_script(path: Path, line: int, code: str) -> None:
    # A traceback names the block and shows its code (line numbers count from the block's first line).
    name = f"{path.relative_to(ROOT)}, block at line {line}"
    linecache.cache[name] = (len(code), None, code.splitlines(keepends=True), name)
    exec(compile(code, name, "exec"), {"__name__": "__docs__"})


@pytest.mark.parametrize(("path", "line", "code"), BLOCKS)
def test_block_runs(path, line, code, tmp_path, monkeypatch, request):
    monkeypatch.chdir(tmp_path)
    try:
        if re.search(r"^\s*>>>", code, re.M):
            run_doctest(path, line, code, doctest_flags(request.config))
        else:
            run_script(path, line, code)
    finally:
        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close("all")


def test_blocks_are_found():
    assert len(BLOCKS) >= 5, [param.id for param in BLOCKS]


def test_no_python_block_hides_under_another_name():
    """```py, ```python3, ```pycon would not run: write them as ```python."""
    hidden = [f"{path.relative_to(ROOT)}:{line}" for path, line, info, _ in fenced_blocks()
              if info.lower() in {"py", "py3", "python3", "pycon", "ipython"}]
    assert hidden == []
