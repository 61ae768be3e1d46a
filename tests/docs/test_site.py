"""The documentation site's API reference documents every public name (``avar.__all__``).

The reference is docs/api/: one page per family, listed in docs/api/index.rst, whose
autosummary tables (or ``auto*`` directives) name the objects. This test reads those sources
(reST or MyST Markdown) without Sphinx: a new public name without an entry, an entry of a name
that is no longer public, or a family page left out of the table of contents fails here, before
the site's build (``.ci/run``) would show it only as a missing page.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

import avar

ROOT = Path(__file__).resolve().parents[2]
API = ROOT / "docs" / "api"
PAGES = sorted(path for path in API.glob("*") if path.suffix in {".rst", ".md"} and path.stem != "index")

#: ``.. currentmodule:: avar`` (reST) or ```{currentmodule} avar (MyST).
CURRENT_MODULE = re.compile(r"^\s*(?:\.\. currentmodule::|```\{currentmodule\})\s*(?P<module>\S+)\s*$")
#: ``.. autofunction:: avar.adev`` and the other single-object directives, in either syntax.
AUTO_OBJECT = re.compile(r"^\s*(?:\.\. auto(?:function|class|data|module|exception)::|"
                         r"```\{auto(?:function|class|data|module|exception)\})\s*(?P<name>\S+)\s*$")
AUTOSUMMARY = re.compile(r"^(?P<indent>\s*)(?:\.\. autosummary::|```\{autosummary\})\s*$")


def documented(path: Path) -> list[str]:
    """The dotted names a page documents: its autosummary entries and auto* targets, made absolute."""
    module = ""
    names: list[str] = []
    lines = path.read_text(encoding="utf-8").splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        i += 1
        if match := CURRENT_MODULE.match(line):
            module = "" if match["module"] == "None" else match["module"]
            continue
        if match := AUTO_OBJECT.match(line):
            names.append(match["name"])
            continue
        match = AUTOSUMMARY.match(line)
        if not match:
            continue
        fenced = line.lstrip().startswith("```")
        entries = []
        while i < len(lines):
            row = lines[i]
            if fenced and row.strip().startswith("```"):
                i += 1
                break
            if not fenced and row.strip() and len(row) - len(row.lstrip()) <= len(match["indent"]):
                break  # the directive's content ends at the first line indented as the directive
            i += 1
            entry = row.strip()
            if entry and not entry.startswith(":") and not entry.startswith(".."):
                entries.append(entry.lstrip("~"))
        names.extend(entries)
    return [name if not module or name.startswith(f"{module}.") else f"{module}.{name}" for name in names]


DOCUMENTED = {path.name: documented(path) for path in PAGES}
ALL_ENTRIES = [name for names in DOCUMENTED.values() for name in names]


def public_name(entry: str) -> str | None:
    """The name of ``avar.__all__`` an entry documents (``avar.oadev``, ``avar.datasets.load``, or the
    defining module's path: ``avar.stability.classic.deviations.oadev``); None for any other object."""
    if entry.startswith("avar."):
        head = entry.removeprefix("avar.").split(".")[0]
        if head in avar.__all__ and (entry.count(".") == 1 or head in avar._SUBMODULES):
            return head
    for name, module in avar._EXPORTS.items():
        if entry == f"{module}.{name}":
            return name
    for name, module in avar._SUBMODULES.items():
        if entry == module or entry.startswith(f"{module}."):
            return name
    return None


def test_the_family_pages_are_found():
    assert len(PAGES) >= 9, [path.name for path in PAGES]
    assert all(DOCUMENTED.values()), [page for page, names in DOCUMENTED.items() if not names]


def test_every_public_name_has_an_entry():
    covered = {public_name(entry) for entry in ALL_ENTRIES}
    missing = sorted(set(avar.__all__) - covered)
    assert missing == [], f"public names with no entry in docs/api/*.rst: {missing}"


def test_every_entry_is_a_public_name():
    stale = [entry for entry in ALL_ENTRIES if public_name(entry) is None]
    assert stale == [], f"entries that are not (any longer) in avar.__all__: {stale}"


def test_no_name_is_documented_twice():
    seen: dict[str, str] = {}
    twice = []
    for page, names in DOCUMENTED.items():
        for name in names:
            if name in seen:
                twice.append((name, seen[name], page))
            seen[name] = page
    assert twice == []


@pytest.mark.parametrize("entry", sorted(set(ALL_ENTRIES)))
def test_entry_resolves(entry):
    """Each entry imports as written: ``avar.NAME`` through the lazy ``avar.__getattr__``, a
    defining module's path through that module (as autodoc imports it)."""
    parts = entry.split(".")
    for stop in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:stop]))
        except ImportError:
            continue
        for part in parts[stop:]:
            obj = getattr(obj, part)
        break
    else:
        pytest.fail(f"no module of {entry} imports")
    assert public_name(entry) is not None and obj is not None


def test_every_family_page_is_in_the_table_of_contents():
    index = next(path for path in API.glob("index.*") if path.suffix in {".rst", ".md"})
    listed = set(re.findall(r"^\s+([\w/-]+)\s*$", index.read_text(encoding="utf-8"), re.M))
    assert {path.stem for path in PAGES} <= listed
