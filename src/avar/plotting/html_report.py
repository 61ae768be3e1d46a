"""A noise report as one self-contained HTML page: inline SVG figures, tables, provenance.

:func:`report_html` returns the page as a string; nothing is fetched when it is opened
(no scripts, no external style sheets or images), so it can be mailed or attached to a
test report as it is. Every text that comes from the data or the user (file and channel
names, the command line, warnings, table cells) is escaped with :func:`avar._escape.html_text`.

The tables are rendered generically: every column of the report's ``table`` (and of
its ``curves`` when the report has them), with missing values as empty cells and
floats to 4 significant digits.
"""

from __future__ import annotations

import io
import math
import re
from typing import Any

from avar._escape import html_text

__all__ = ["report_html", "svg_of"]

STYLE = """
body { font-family: system-ui, sans-serif; margin: 2em auto; max-width: 75em; color: #222; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.9em; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; text-align: left; }
th { background: #eee; }
td.number { text-align: right; font-variant-numeric: tabular-nums; }
dl.meta { display: grid; grid-template-columns: max-content auto; gap: 0.2em 1em; }
dl.meta dt { font-weight: bold; }
.warnings li { color: #8a4b00; }
figure svg { max-width: 100%; height: auto; }
div.scroll { overflow-x: auto; }
code { background: #f4f4f4; padding: 0.1em 0.3em; }
"""


def svg_of(figure: Any) -> str:
    """A matplotlib figure as an inline ``<svg>`` element (no XML prolog or DOCTYPE)."""
    buffer = io.StringIO()
    figure.savefig(buffer, format="svg", bbox_inches="tight")
    text = buffer.getvalue()
    return re.sub(r"<metadata>.*?</metadata>\s*", "", text[text.index("<svg"):], count=1, flags=re.S)


def _cell(value: Any) -> tuple[str, bool]:
    """Text of one table cell and whether it is a number (missing: empty)."""
    if value is None or type(value).__name__ in ("NAType", "NaTType") or (
            isinstance(value, float) and math.isnan(value)):
        return "", False
    if isinstance(value, bool):
        return str(value), False
    if isinstance(value, float) or type(value).__name__.startswith("float"):
        return f"{float(value):.4g}", True
    if isinstance(value, int) or type(value).__name__.startswith("int"):
        return str(int(value)), True
    return str(value), False


def _table(frame: Any, css: str) -> str:
    """A pandas DataFrame as an escaped HTML table, every column, no index."""
    head = "".join(f"<th>{html_text(str(c))}</th>" for c in frame.columns)
    rows = []
    for values in frame.itertuples(index=False, name=None):
        cells = []
        for value in values:
            text, number = _cell(value)
            cells.append(f'<td class="number">{html_text(text)}</td>' if number else f"<td>{html_text(text)}</td>")
        rows.append("<tr>" + "".join(cells) + "</tr>")
    return (f'<div class="scroll"><table class="{css}"><thead><tr>{head}</tr></thead>\n<tbody>\n'
            + "\n".join(rows) + "\n</tbody></table></div>")


def _meta(items: list[tuple[str, str]]) -> str:
    return '<dl class="meta">' + "".join(
        f"<dt>{html_text(k)}</dt><dd>{html_text(v)}</dd>" for k, v in items if v) + "</dl>"


def report_html(report: Any, command: str | None = None, source: str | None = None,
                figures: list[Any] | None = None) -> str:
    """The noise report as one self-contained HTML page (see the module notes).

    Parameters
    ----------
    report : NoiseReport
        From :func:`avar.noise_report`; its ``warnings`` and ``curves`` are shown when present.
    command : str, optional
        The command line that made the report.
    source : str, optional
        The input's name (default: the report's ``source`` or ``name``).
    figures : list of matplotlib Figure, optional
        Figures to inline as SVG (default: ``report.plot()``, closed afterwards).

    Returns
    -------
    str
        The HTML document.

    Examples
    --------
    >>> import avar
    >>> x = avar.WN(sigma2=1e-4).simulate(4_000, seed=1)
    >>> page = report_html(avar.noise_report(x, gyro_units="rad/s", rate=100.0), command="avar report x<1>.csv")
    >>> page.startswith("<!DOCTYPE html>"), "<svg" in page, "x&lt;1&gt;.csv" in page
    (True, True, True)
    """
    from avar import __version__

    own = figures is None
    if own:
        figures = [report.plot()]
    try:
        svgs = [svg_of(figure) for figure in figures]
    finally:
        if own:
            import matplotlib.pyplot as plt

            for figure in figures:
                plt.close(figure)
    name = source or report.source or report.name
    seconds = report.n_samples / report.rate if report.rate else float("nan")
    meta = [("Input", str(name)), ("ROS topic", report.topic or ""),
            ("Rate", f"{report.rate:.6g} Hz"),
            ("Length", f"{report.n_samples} samples per channel ({seconds:.6g} s = {seconds / 3600:.3g} h)"),
            ("Channels", ", ".join(str(c) for c in report.channels)),
            ("Intervals", f"{100 * report.confidence:g}% chi-squared"),
            ("Command", command or ""), ("avar version", __version__)]
    warnings = [str(w) for w in getattr(report, "warnings", ()) or ()]
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
             f"<title>Noise report: {html_text(str(name))}</title>", f"<style>{STYLE}</style></head><body>",
             f"<h1>Noise report: {html_text(str(name))}</h1>", _meta(meta)]
    parts.append('<section class="warnings"><h2>Warnings</h2>' + (
        "<ul>" + "".join(f"<li>{html_text(w)}</li>" for w in warnings) + "</ul>" if warnings
        else "<p>none</p>") + "</section>")
    parts.append("<section><h2>Terms</h2>" + _table(report.table, "terms") + "</section>")
    parts.append("<section><h2>Figures</h2>" + "".join(f"<figure>{svg}</figure>" for svg in svgs) + "</section>")
    curves = getattr(report, "curves", None)
    if curves is not None and len(curves):
        parts.append("<section><h2>Curves</h2><details><summary>" + html_text(f"{len(curves)} rows")
                     + "</summary>" + _table(curves, "curves") + "</details></section>")
    parts.append("</body></html>\n")
    return "\n".join(parts)
