"""The noise-report figure: :func:`plot_report` (``NoiseReport.plot()``).

One panel per channel (gyroscopes on the first row, accelerometers on the
second, channels of an unknown type on a row of their own), each a log-log
Allan *deviation* (the engineer's plot; ``deviation=False`` for the variance)
against tau in seconds, with the data unit on the y axis:

* the empirical deviation and its band (R ``avar``'s adev (1 -/+ 2 errors));
* one dashed line per term present, labelled with its value and unit
  (customary units for gyroscopes and accelerometers: deg/sqrt(h), deg/h,
  deg/h/sqrt(h); m/s/sqrt(h), ug, m/s^2/sqrt(h));
* Gauss-Markov and sinusoid terms, labelled by correlation time and frequency; those
  that model the sensor's own filtering or vibration (the table's ``Group`` "sensor
  filtering", :func:`avar.fit.report.rows.group_of`) in a legend section of their own,
  "sensor filtering:", after the IEEE 952 terms and the implied curve;
* the Allan-deviation minimum (a star, labelled in deg/h or ug): the
  datasheets' in-run bias stability; the B line says its convention;
* a panel whose fit fails the check says so in its title;
* the implied curve: the square root of the **sum of the terms' Allan
  variances** (independent processes: variances add); R ``avar``'s curve, the
  square of the sum of deviations (DESIGN defect 6), only with ``implied="r"``.

The title names the channel, the figure title the file or sensor.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from avar._escape import figure_text
from avar.plotting.base import (
    AD_COLOUR,
    CI_COLOUR,
    IMPLIED_COLOUR,
    PROCESS_COLOURS,
    check_flag,
    draw_empirical,
    log_limits,
    setup_log_axes,
)

__all__ = ["plot_report", "term_label"]

COLOURS = {**PROCESS_COLOURS, "FN": "#1F77B4", "AR1": "#8C564B", "SIN": "#E377C2"}
SYMBOLS = {"QN": "Q", "WN": "N", "FN": "B", "RW": "K", "DR": "R"}
BI_MARKER = "*"
#: The legend section of the terms of the sensor's own filtering or vibration (the table's ``Group``).
FILTERING = "sensor filtering"
PANEL_SIZE = (4.6, 3.6)


def term_label(report: Any, channel: str, process: str) -> str:
    """``"N = 0.412 deg/sqrt(h)"``: the symbol, value and unit of a term (customary when known)."""
    rows = report.terms[(report.terms["Channel"] == channel) & (report.terms["Process"] == process)].iloc[0]
    if rows["Customary unit"]:
        value, unit = rows["Customary"], rows["Customary unit"]
    else:
        value, unit = rows["Value"], rows["Unit"]
    return f"{SYMBOLS[process]} = {float(value):.3g} {unit}"


def _layout(report: Any) -> list[list[str]]:
    rows: dict[Any, list[str]] = {}
    for channel, kind in zip(report.channels, report.sensor_types):
        rows.setdefault(kind, []).append(channel)
    return list(rows.values())


def plot_report(
    report: Any,
    channels: Any = None,
    deviation: bool = True,
    implied: str = "sum",
    ci: bool = True,
    legend: bool = True,
    fig: Figure | None = None,
    customary_axis: bool = False,
) -> Figure:
    """Allan deviation of every channel of a noise report with its fitted terms.

    Parameters
    ----------
    report : NoiseReport
    channels : str or list of str, optional
        Channels to draw (default: all).
    deviation : bool
        Allan deviation (default) or variance.
    implied : {"sum", "r"}
        Implied curve: sum of the terms' variances (default), or R's square of
        the sum of deviations.
    ci : bool
        Draw the confidence band.
    legend : bool
        Legend in every panel.
    fig : matplotlib.figure.Figure, optional
        Figure to draw on (default: a new headless one).
    customary_axis : bool
        Add a right axis in deg/h (gyroscopes) or ug (accelerometers) to deviation panels.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import avar
    >>> x = (avar.WN(sigma2=1e-6) + avar.FN(b2=1e-9)).simulate(50_000, seed=1)
    >>> fig = avar.noise_report(x, gyro_units="rad/s", rate=100.0).plot()
    >>> [line.get_label() for line in fig.axes[0].lines][1:]
    ['N = 0.342 deg/sqrt(h)', 'B = 6.38 deg/h (IEEE 952: AD = 0.664 B)', 'AD minimum 3.66 deg/h at 41 s', 'Implied AD (sum of variances)']
    """
    from avar.fit.report.result import NoiseReport

    if not isinstance(report, NoiseReport):
        raise TypeError(f"report must be a NoiseReport (from avar.noise_report), got {type(report).__name__}")
    deviation, ci, legend = check_flag(deviation, "deviation"), check_flag(ci, "ci"), check_flag(legend, "legend")
    customary_axis = check_flag(customary_axis, "customary_axis")
    if implied not in ("sum", "r"):
        raise ValueError(f"implied must be 'sum' (sum of the processes' variances) or 'r' (R's curve), got {implied!r}")
    wanted = list(report.channels) if channels is None else [channels] if isinstance(channels, str) else list(channels)
    unknown = [c for c in wanted if c not in report.channels]
    if unknown or not wanted:
        raise ValueError(f"channels {unknown or wanted} are not channels of the report; it has {list(report.channels)}")
    grid = [[c for c in row if c in wanted] for row in _layout(report)]
    grid = [row for row in grid if row]
    n_rows, n_cols = len(grid), max(len(row) for row in grid)
    if fig is None:
        fig = Figure(figsize=(PANEL_SIZE[0] * n_cols, PANEL_SIZE[1] * n_rows + 0.4), layout="constrained")
    elif not isinstance(fig, Figure):
        raise TypeError(f"fig must be a matplotlib Figure or None, got {type(fig).__name__}")
    axes = fig.subplots(n_rows, n_cols, squeeze=False)
    power = 1 if deviation else 2
    for r, row in enumerate(grid):
        for c in range(n_cols):
            ax = axes[r][c]
            if c >= len(row):
                ax.set_visible(False)
                continue
            _panel(ax, report, row[c], deviation, power, implied, ci, legend)
            if customary_axis and deviation:
                _customary_axis(ax, report, row[c])
    fig.suptitle(f"Noise report: {figure_text(report.name)}" + (f" ({figure_text(report.topic)})" if report.topic else ""))
    return fig


def _customary_axis(ax: Any, report: Any, channel: str) -> None:
    """A right axis in deg/h or ug for a gyroscope or accelerometer in known units."""
    from avar.fit.report.noise_terms import ACCEL, GYRO, to_si

    index = report.channels.index(channel)
    kind, unit = report.sensor_types[index], report.units[index]
    if kind not in (GYRO, ACCEL) or unit is None:
        return
    factor = to_si(1.0, kind, unit) * (3600.0 * 180.0 / math.pi if kind == GYRO else 1.0 / 9.80665e-6)
    axis = ax.secondary_yaxis("right", functions=(lambda v: v * factor, lambda v: v / factor))
    axis.set_ylabel("deg/h" if kind == GYRO else "ug")


def _component_label(report: Any, channel: str, kind: str, number: int) -> str:
    if kind in SYMBOLS:
        text = term_label(report, channel, kind)
        return text + " (IEEE 952: AD = 0.664 B)" if kind == "FN" else text
    rows = report.terms[(report.terms["Channel"] == channel) & (report.terms["Process"] == f"{kind}_{number}")]
    row = rows.iloc[0]
    if kind == "AR1":
        return f"Gauss-Markov {number}: T = {float(row['Tau (s)']):.3g} s"
    return f"Sinusoid {number}: {1.0 / float(row['Tau (s)']):.3g} Hz"


def _group(report: Any, channel: str, kind: str, number: int) -> str:
    """The table's ``Group`` of a term (``IEEE 952`` when the table has none)."""
    if "Group" not in report.terms.columns:
        return "IEEE 952"
    process = kind if kind in SYMBOLS else f"{kind}_{number}"
    rows = report.terms[(report.terms["Channel"] == channel) & (report.terms["Process"] == process)]
    group = rows["Group"].iloc[0] if len(rows) else None
    return group if isinstance(group, str) and group else "IEEE 952"


def _draw_component(ax: Any, report: Any, channel: str, av: Any, component: Any, number: int, power: int,
                    linestyle: str = "--") -> None:
    variance = component.av(av.averaging_factors)
    ax.plot(av.levels, np.sqrt(variance) ** power, color=COLOURS.get(component.kind, "0.3"), linestyle=linestyle,
            linewidth=1.2, label=_component_label(report, channel, component.kind, number), zorder=2)


def _panel(ax: Any, report: Any, channel: str, deviation: bool, power: int, implied: str, ci: bool,
           legend: bool) -> None:
    av, fit = report.avs[channel], report.fits[channel]
    index = report.channels.index(channel)
    unit = report.units[index]
    setup_log_axes(ax)
    drawn = draw_empirical(ax, av, deviation=deviation, colour=AD_COLOUR, band_colour=CI_COLOUR, ci=ci,
                           marker="o", markersize=3.5, label="Empirical AD" if deviation else "Empirical AV",
                           band_label=None)
    counts: dict[str, int] = {}
    filtering = []
    for component in fit.components:
        counts[component.kind] = counts.get(component.kind, 0) + 1
        if _group(report, channel, component.kind, counts[component.kind]) == FILTERING:
            filtering.append((component, counts[component.kind]))
            continue
        _draw_component(ax, report, channel, av, component, counts[component.kind], power)
    extra = []
    rows = report.terms[(report.terms["Channel"] == channel) & (report.terms["Process"] == "MIN")]
    if len(rows):
        row = rows.iloc[0]
        tau_min = float(row["Tau (s)"])
        level = float(np.asarray(av.adev)[int(np.argmin(np.abs(np.log(np.asarray(av.levels) / tau_min))))]) ** power
        text = f"{float(row['Customary']):.3g} {row['Customary unit']}" if row["Customary unit"] else f"{level:.3g}"
        ax.plot([tau_min], [level], linestyle="none", marker=BI_MARKER, markersize=13, color=COLOURS["FN"],
                markeredgecolor="black", label=f"AD minimum {text} at {tau_min:.3g} s", zorder=6)
        extra.append(np.array([level]))
    total = report.implied_av(channel, implied)
    curve = np.sqrt(total) ** power
    label = "Implied AD" if deviation else "Implied AV"
    label += " (sum of variances)" if implied == "sum" else " (R: square of summed deviations)"
    ax.plot(av.levels, curve, color=IMPLIED_COLOUR, linewidth=2.0, label=label, zorder=4)
    if filtering:  # a legend section of its own: a header without a line, then its terms
        ax.plot([], [], linestyle="none", label=f"{FILTERING}:")
        for component, number in filtering:
            _draw_component(ax, report, channel, av, component, number, power, linestyle=":")
    limits = log_limits(*drawn, curve, *extra, pad=0.08)
    if limits is not None:
        ax.set_ylim(*limits)
    quantity = "Allan deviation" if deviation else "Allan variance"
    ax.set_ylabel(f"{quantity} [{unit}]" if unit and deviation else
                  f"{quantity} [({unit})^2]" if unit else quantity)
    ax.set_xlabel(r"Averaging time $\tau$ [s]")
    kind = report.sensor_types[index]
    title = figure_text(channel) + (f" ({kind.lower()})" if kind else "")  # a name from data, drawn literally
    curves = report.curves[report.curves["Channel"] == channel]
    if len(curves) and curves["Fits"].mean() < 0.9:
        title += f"\nfit fails at {int((~curves['Fits'].astype(bool)).sum())} of {len(curves)} levels"
        ax.title.set_color("#B00020")
    ax.set_title(title, fontsize="small")
    if legend:
        ax.legend(loc="best", fontsize="x-small", framealpha=0.8)
