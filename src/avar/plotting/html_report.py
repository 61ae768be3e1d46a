"""A noise report as one self-contained HTML page, read top down: summary, figure, details.

:func:`report_html` returns the page as a string; nothing is fetched when it is opened
(no scripts, no external style sheets or images), so it can be mailed or attached to a
test report as it is. Every text that comes from the data or the user (file and channel
names, the command line, warnings, table cells) is escaped with :func:`avar._escape.html_text`.

The page, in the order a person reads it:

1. one line on the input (file, rate, length) and a **summary table**, one row per axis:
   channel, sensor, noise density N (angle / velocity random walk), bias instability B,
   random walk K (rate / acceleration random walk), the Allan-deviation minimum and its
   tau, and the fit's status (the share of levels where the model is inside the band);
   customary units for gyroscopes and accelerometers (deg/sqrt(h), deg/h, deg/h/sqrt(h);
   m/s/sqrt(h), ug, m/s^2/sqrt(h)), a term the data only bound as "< bound";
2. the warnings;
3. the figure (inline SVG, scaled to the page's width);
4. the full table of terms and the curves, each folded in a ``<details>`` element
   (every column of the report's ``table`` and ``curves``, missing values as empty
   cells, floats to 4 significant digits);
5. how the report was made: input, topic, command, avar version.

The style sheet keeps the page within its width down to a 1,280 px window: tables take
the page's width and wrap their cells (``overflow-wrap: anywhere``), the figure scales.
"""

from __future__ import annotations

import io
import math
import re
from typing import Any

from avar._escape import html_text

__all__ = ["report_html", "svg_of", "summary_rows", "SUMMARY_COLUMNS"]

STYLE = """
html { -webkit-text-size-adjust: 100%; }
body { font-family: system-ui, sans-serif; margin: 1.5em auto; max-width: 80em; padding: 0 1em;
       box-sizing: border-box; color: #222; line-height: 1.4; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.9em; width: 100%; table-layout: auto; }
th, td { border: 1px solid #bbb; padding: 0.25em 0.5em; text-align: left; vertical-align: top;
         overflow-wrap: break-word; }
th { background: #eee; }
td.number { text-align: right; font-variant-numeric: tabular-nums; }
table.terms, table.curves { font-size: 0.75em; }
table.terms th, table.terms td, table.curves th, table.curves td { padding: 0.2em 0.3em; }
table.summary td { font-variant-numeric: tabular-nums; }
table.summary .interval { display: block; color: #666; font-size: 0.85em; }
td.fits { color: #1b5e20; }
td.departs { color: #8a4b00; font-weight: bold; }
dl.meta { display: grid; grid-template-columns: max-content minmax(0, 1fr); gap: 0.2em 1em; }
dl.meta dt { font-weight: bold; }
dl.meta dd { margin: 0; overflow-wrap: anywhere; }
.warnings li { color: #8a4b00; }
figure { margin: 1em 0; }
figure svg { display: block; max-width: 100%; height: auto; }
details { margin: 1em 0; }
summary { cursor: pointer; font-weight: bold; }
code { background: #f4f4f4; padding: 0.1em 0.3em; overflow-wrap: anywhere; }
"""

#: Columns of the summary table.
SUMMARY_COLUMNS = ["Channel", "Sensor", "Noise density N (ARW / VRW)", "Bias instability B",
                   "Random walk K (RRW / acceleration RW)", "AD minimum (in-run bias stability)", "Fit"]
#: The summary's terms, by the report table's Process.
SUMMARY_TERMS = ("WN", "FN", "RW", "MIN")


def svg_of(figure: Any) -> str:
    """A matplotlib figure as an inline ``<svg>`` element (no XML prolog or DOCTYPE)."""
    buffer = io.StringIO()
    figure.savefig(buffer, format="svg", bbox_inches="tight")
    text = buffer.getvalue()
    return re.sub(r"<metadata>.*?</metadata>\s*", "", text[text.index("<svg"):], count=1, flags=re.S)


def _missing(value: Any) -> bool:
    return value is None or type(value).__name__ in ("NAType", "NaTType") or (
        isinstance(value, float) and math.isnan(value))


def _cell(value: Any) -> tuple[str, bool]:
    """Text of one table cell and whether it is a number (missing: empty)."""
    if _missing(value):
        return "", False
    if isinstance(value, bool):
        return str(value), False
    if isinstance(value, float) or type(value).__name__.startswith("float"):
        return f"{float(value):.4g}", True
    if isinstance(value, int) or type(value).__name__.startswith("int"):
        return str(int(value)), True
    return str(value), False


def _breakable(text: str) -> str:
    """Escaped ``text`` with a line-break opportunity (``<wbr>``) after each ``/`` and ``_``: a long unit
    (``rad/s^2/sqrt(Hz)``) or name may wrap inside a narrow column instead of widening the page."""
    return re.sub(r"([/_])", r"\1<wbr>", html_text(text))


def _table(frame: Any, css: str) -> str:
    """A pandas DataFrame as an escaped HTML table, every column, no index."""
    head = "".join(f"<th>{html_text(str(c))}</th>" for c in frame.columns)
    rows = []
    for values in frame.itertuples(index=False, name=None):
        cells = []
        for value in values:
            text, number = _cell(value)
            cells.append(f'<td class="number">{html_text(text)}</td>' if number else f"<td>{_breakable(text)}</td>")
        rows.append("<tr>" + "".join(cells) + "</tr>")
    return (f'<table class="{css}"><thead><tr>{head}</tr></thead>\n<tbody>\n'
            + "\n".join(rows) + "\n</tbody></table>")


def _term_text(row: dict[str, Any] | None) -> tuple[str, str]:
    """(value and unit, interval) of one term for the summary: customary units when the row has them."""
    if row is None or row["Status"] == "absent":
        return "absent", ""
    customary = bool(row.get("Customary unit"))
    unit = row["Customary unit"] if customary else row["Unit"]
    value, lower, upper = (row[f"Customary{suffix}" if customary else name]
                           for suffix, name in (("", "Value"), (" lower", "Lower"), (" upper", "Upper")))
    if row["Status"] == "bound":
        return f"< {float(upper):.3g} {unit}", str(row.get("Note") or "upper bound, not resolved by the data")
    if _missing(value):
        return "", ""
    interval = "" if _missing(lower) or _missing(upper) else f"[{float(lower):.3g}, {float(upper):.3g}]"
    if row["Process"] == "MIN" and not _missing(row.get("Tau (s)")):
        interval = (interval + " " if interval else "") + f"at tau = {float(row['Tau (s)']):.3g} s"
    return f"{float(value):.3g} {unit}", interval


def summary_rows(report: Any) -> list[dict[str, Any]]:
    """One dict per channel: ``Channel``, ``Sensor``, the (text, interval) of N, B, K and the AD minimum
    (customary units when the sensor type is known), and ``Fit``: (text, fits) from the report's curves."""
    from avar.fit.report.checks import FIT_SHARE

    table = report.table
    curves = getattr(report, "curves", None)
    out = []
    for channel, kind in zip(report.channels, report.sensor_types):
        rows = {row["Process"]: row for row in table[table["Channel"] == channel].to_dict("records")}
        entry: dict[str, Any] = {"Channel": str(channel), "Sensor": kind or "unknown type"}
        for process, column in zip(SUMMARY_TERMS, SUMMARY_COLUMNS[2:6]):
            entry[column] = _term_text(rows.get(process))
        fit = ("", True)
        if curves is not None and len(curves) and "Fits" in curves:
            fits = curves.loc[curves["Channel"] == channel, "Fits"].astype(bool)
            if len(fits):
                good = int(fits.sum())
                fit = (f"fits {good} of {len(fits)} levels", good >= FIT_SHARE * len(fits))
        entry["Fit"] = fit
        out.append(entry)
    return out


def _summary_table(report: Any) -> str:
    head = "".join(f"<th>{html_text(c)}</th>" for c in SUMMARY_COLUMNS)
    rows = []
    for entry in summary_rows(report):
        cells = [f"<td>{html_text(entry['Channel'])}</td>", f"<td>{html_text(entry['Sensor'])}</td>"]
        for column in SUMMARY_COLUMNS[2:6]:
            text, interval = entry[column]
            extra = f'<span class="interval">{html_text(interval)}</span>' if interval else ""
            cells.append(f"<td>{html_text(text)}{extra}</td>")
        text, fits = entry["Fit"]
        cells.append(f'<td class="{"fits" if fits else "departs"}">{html_text(text)}</td>')
        rows.append("<tr>" + "".join(cells) + "</tr>")
    return (f'<table class="summary"><thead><tr>{head}</tr></thead>\n<tbody>\n' + "\n".join(rows)
            + "\n</tbody></table>")


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
    >>> page.index('class="summary"') < page.index("<svg") < page.index("<details")  # read top down
    True
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
    length = f"{report.n_samples} samples per channel ({seconds:.6g} s = {seconds / 3600:.3g} h)"
    intro = (f"{len(report.channels)} channel(s) at {report.rate:.6g} Hz, {length}; "
             f"{100 * report.confidence:g}% chi-squared intervals.")
    meta = [("Input", str(name)), ("ROS topic", report.topic or ""), ("Rate", f"{report.rate:.6g} Hz"),
            ("Length", length), ("Channels", ", ".join(str(c) for c in report.channels)),
            ("Intervals", f"{100 * report.confidence:g}% chi-squared"),
            ("Command", command or ""), ("avar version", __version__)]
    warnings = [str(w) for w in getattr(report, "warnings", ()) or ()]
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
             '<meta name="viewport" content="width=device-width, initial-scale=1">',
             f"<title>Noise report: {html_text(str(name))}</title>", f"<style>{STYLE}</style></head><body>",
             f"<h1>Noise report: {html_text(str(name))}</h1>", f"<p>{html_text(intro)}</p>",
             '<section id="summary"><h2>Summary</h2>' + _summary_table(report) + "</section>"]
    parts.append('<section class="warnings"><h2>Warnings</h2>' + (
        "<ul>" + "".join(f"<li>{html_text(w)}</li>" for w in warnings) + "</ul>" if warnings
        else "<p>none</p>") + "</section>")
    parts.append('<section id="figures"><h2>Figures</h2>' + "".join(f"<figure>{svg}</figure>" for svg in svgs)
                 + "</section>")
    parts.append('<section id="terms"><h2>Terms</h2><details><summary>'
                 + html_text(f"every term of every channel ({len(report.table)} rows)") + "</summary>"
                 + _table(report.table, "terms") + "</details></section>")
    curves = getattr(report, "curves", None)
    if curves is not None and len(curves):
        parts.append('<section id="curves"><h2>Curves</h2><details><summary>' + html_text(f"{len(curves)} rows")
                     + "</summary>" + _table(curves, "curves") + "</details></section>")
    parts.append('<section id="about"><h2>How this report was made</h2>' + _meta(meta) + "</section>")
    parts.append("</body></html>\n")
    return "\n".join(parts)
