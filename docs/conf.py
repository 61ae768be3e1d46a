"""Sphinx configuration of the avar documentation site.

Build it from the repository root (the ``docs`` extra installs Sphinx and its extensions)::

    pip install ".[docs]"
    python -m sphinx -W --keep-going -b html docs docs/_build/html

Pages: ``index.md`` (README.md's text and the table of contents), the user guides
(``guide_*.md``), the existing Markdown pages ``docs/*.md`` (myst-parser) and the API
reference ``api/*.rst``: one page per family of ``avar.__all__``, whose autosummary tables
write one page per name into ``api/generated/`` at build time (git-ignored). Names are
documented as ``avar.NAME``, the way users reach them; autodoc's import goes through the
lazy ``avar.__getattr__`` (PEP 562). Nothing is executed at build time: no notebooks,
no plots, no doctests.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
# A source checkout builds without installing the package (pip install -e . also works).
sys.path.insert(0, str(ROOT / "src"))

from sphinx.ext import autosummary as _autosummary  # noqa: E402

import avar  # noqa: E402

project = "avar"
author = "avar contributors"
copyright = "avar contributors, AGPL-3.0-or-later"  # noqa: A001 - Sphinx's name
version = release = avar.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "myst_parser",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
# Not pages: the build output, the figure script, editor and Python leftovers.
exclude_patterns = ["_build", "make_noise_report.py", "**/__pycache__", ".DS_Store", "Thumbs.db"]
templates_path = ["_templates"]
nitpicky = False

# autodoc / autosummary: one generated page per public name, members documented on the class page.
autosummary_generate = True
autosummary_imported_members = False
autodoc_default_options = {"member-order": "bysource"}
autodoc_typehints = "signature"
autodoc_preserve_defaults = True
autoclass_content = "class"

# The one-line summaries of the autosummary tables. Many docstrings open with a formula:
# "Overlapping Allan deviation, NIST SP 1065 eq. (11)::" and its literal block; autosummary would
# show "eq. (11)::." and cut other lines at "eq." as at a sentence's end;
# "x_t i.i.d." and "e_1 + ... + e_t" do not end a sentence either.
_autosummary.WELL_KNOWN_ABBREVIATIONS = (*_autosummary.WELL_KNOWN_ABBREVIATIONS, "eq.", "eqs.", "i.i.d.")
_autosummary.periods_re = re.compile(r"(?<!\.)\.(?:\s+)")
_extract_summary = _autosummary.extract_summary


def _summary(doc, settings) -> str:
    return re.sub(r"::\.?$", ".", _extract_summary(doc, settings))


_autosummary.extract_summary = _summary

# numpydoc renders the docstrings; classes list their members through autodoc (the template),
# not through numpydoc's tables, so a class does not turn into one warning per undocumented member.
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# myst-parser: the Markdown pages, as GitHub shows them (no dollar math: "$HOME" stays text).
# Headings get anchors so that ``[text](page.md#heading)`` resolves.
myst_heading_anchors = 3

html_title = f"avar {release}"
try:  # the docs extra installs it; without it the site builds with Sphinx's own theme
    import pydata_sphinx_theme  # noqa: F401
except ImportError:
    html_theme = "alabaster"
else:
    html_theme = "pydata_sphinx_theme"
    html_theme_options = {"navigation_with_keys": False, "show_toc_level": 2, "secondary_sidebar_items": ["page-toc"]}
html_static_path: list[str] = []
html_show_sourcelink = False

# Pages of files outside docs/: index.md includes README.md, and one stub page includes each of
# these. Their links are relative to the repository root, as GitHub shows them; in the site
# ``docs/cli.md`` becomes the page ``cli.md`` and ``CHANGELOG.md`` the page ``changelog.md``.
# Only links to files that exist move; a broken link stays broken and fails the build.
INCLUDED = {"README.md": "index.md", "CHANGELOG.md": "changelog.md", "CONTRIBUTING.md": "contributing.md",
            "benchmarks/README.md": "benchmarks.md"}
_LINK = re.compile(r"(\]\()([^)\s#]+)((?:#[^)\s]*)?\))")


def _site_link(match: re.Match, folder: Path) -> str:
    """A link of a file included from ``folder`` (outside docs/), as the page that includes it sees it."""
    target = match[2]
    if re.match(r"[A-Za-z][A-Za-z0-9+.-]*:", target):  # a URL
        return match[0]
    path = (folder / target).resolve()
    if not path.exists():
        return match[0]
    relative = path.relative_to(ROOT).as_posix() if path.is_relative_to(ROOT) else None
    if relative in INCLUDED:
        return f"{match[1]}{INCLUDED[relative]}{match[3]}"
    if path.is_relative_to(DOCS):
        return f"{match[1]}{path.relative_to(DOCS).as_posix()}{match[3]}"
    return match[0]


def _include_read(app, relative_path, parent_docname, content) -> None:
    path = (DOCS / relative_path).resolve()
    if not path.is_relative_to(DOCS):
        content[0] = _LINK.sub(lambda match: _site_link(match, path.parent), content[0])


def setup(app) -> dict:
    app.connect("include-read", _include_read)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
