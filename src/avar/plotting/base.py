"""Shared pieces of every figure: argument checks, colours, log axes, bands, fit lines."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import is_color_like
from matplotlib.figure import Figure, FigureBase

from avar.stability.allan.results import AllanVariance
from avar.stability.shared.confidence import format_confidence

#: Colour of the empirical curve (R ``avar``: "darkblue").
AD_COLOUR = "darkblue"
#: Colour of the confidence band (R ``avar``: hcl(210, 100, 65) at alpha 0.2).
CI_COLOUR = "#00BBDC33"
#: Colour of the implied curve of a fit (R ``avar``: "#F47F24").
IMPLIED_COLOUR = "#F47F24"
#: Colour of every process in decompositions and scale markers.
PROCESS_COLOURS = {"WN": "#2CA02C", "QN": "#9467BD", "RW": "#D62728", "DR": "#8C564B"}
#: Default title of single plots.
DEFAULT_TITLE = "Allan Variance Representation"
#: Most entries of a legend (the last says how many series it leaves out), and longest label shown.
LEGEND_ENTRIES = 20
LEGEND_LABEL = 60
#: Accepted legend positions: matplotlib names, and R names mapped to them.
LEGEND_POSITIONS = {
    **{name: name for name in (
        "best", "upper right", "upper left", "lower left", "lower right", "right",
        "center left", "center right", "lower center", "upper center", "center",
    )},
    "topright": "upper right", "topleft": "upper left", "bottomleft": "lower left",
    "bottomright": "lower right", "top": "upper center", "bottom": "lower center",
    "left": "center left",
}
SINGLE_FIGSIZE = (7.0, 5.0)


# --------------------------------------------------------------------------- validation
def check_result(x: Any, role: str = "x") -> AllanVariance:
    """``x`` must be an :class:`~avar.AllanVariance`."""
    if not isinstance(x, AllanVariance):
        raise TypeError(f"{role} must be an AllanVariance (from avar.avar), got {type(x).__name__}")
    return x


def check_colour(colour: Any, role: str) -> Any:
    """A matplotlib colour, or a ``ValueError`` naming the argument."""
    if not is_color_like(colour):
        raise ValueError(f"{role}={colour!r} is not a matplotlib colour (e.g. 'darkblue', '#F47F24', (0, 0, 1, 0.2))")
    return colour


def check_legend_position(position: Any) -> str | None:
    """Matplotlib legend location for ``position``; ``None``/``False`` means no legend."""
    if position is None or position is False:
        return None
    if isinstance(position, str):
        key = " ".join(position.lower().replace("_", " ").split())
        for candidate in (key, key.replace(" ", "")):
            if candidate in LEGEND_POSITIONS:
                return LEGEND_POSITIONS[candidate]
    raise ValueError(
        f"unknown legend_position {position!r}; use None (no legend), a matplotlib location "
        "('lower left', 'upper right', 'best', ...) or an R one ('bottomleft', 'topright', ...)"
    )


def check_flag(value: Any, role: str) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{role} must be True or False, got {value!r}")
    return bool(value)


class Style(NamedTuple):
    """The common options of a figure, checked."""

    deviation: bool
    ci: bool
    legend: str | None
    markersize: float


def check_style(deviation: Any, ci: Any, legend_position: Any, markersize: Any,
                colours: Mapping[str, Any], texts: Mapping[str, Any]) -> Style:
    """Validate the common options; returns deviation, ci, legend location, markersize."""
    for role, colour in colours.items():
        check_colour(colour, role)
    for role, text in texts.items():
        if text is not None and not isinstance(text, str):
            raise TypeError(f"{role} must be a string or None, got {text!r}")
    if isinstance(markersize, (bool, np.bool_)) or not isinstance(markersize, (int, float, np.integer, np.floating)):
        raise TypeError(f"markersize must be a number of points, got {markersize!r}")
    if not np.isfinite(markersize) or markersize < 0:
        raise ValueError(f"markersize must be finite and >= 0, got {markersize!r}")
    return Style(check_flag(deviation, "deviation"), check_flag(ci, "ci"),
            check_legend_position(legend_position), float(markersize))


# --------------------------------------------------------------------------- building blocks
class FigureAxes(NamedTuple):
    """Where a figure function draws: the top-level figure and its axes."""

    fig: Figure
    ax: Axes


class AxisLabels(NamedTuple):
    """The x and y labels of a figure."""

    xlab: str
    ylab: str


class LogLimits(NamedTuple):
    """Limits of a log axis, both > 0."""

    low: float
    high: float


def new_axes(ax: Axes | None) -> FigureAxes:
    """The figure of ``ax``, or a new headless figure with one axes."""
    if ax is None:
        fig = Figure(figsize=SINGLE_FIGSIZE, layout="constrained")
        return FigureAxes(fig, fig.add_subplot())
    if not isinstance(ax, Axes):
        raise TypeError(f"ax must be a matplotlib Axes or None, got {type(ax).__name__}")
    return FigureAxes(root_figure(ax), ax)


def root_figure(artist: Any) -> Figure:
    """The top-level Figure of an axes, figure or subfigure."""
    try:
        return artist.get_figure(root=True)  # matplotlib >= 3.10
    except TypeError:
        fig = artist if isinstance(artist, FigureBase) else artist.figure
        while not isinstance(fig, Figure):
            fig = fig.figure
        return fig


def quantity(deviation: bool) -> str:
    """``"AD"`` or ``"AV"``."""
    return "AD" if deviation else "AV"


def values_of(av: AllanVariance, deviation: bool) -> np.ndarray:
    """The plotted values: the Allan deviation or variance."""
    return av.adev if deviation else av.allan


class Band(NamedTuple):
    """A result's confidence band and the levels that have one."""

    lower: np.ndarray
    upper: np.ndarray
    valid: np.ndarray


def band(av: AllanVariance, deviation: bool) -> Band:
    """Lower and upper band and the mask of levels that get a band.

    The band of the AD is [lci, uci]; that of the AV is [lci**2, uci**2].
    A level gets a band only when lci > 0 (a log axis cannot show the rest;
    note that lci**2 would be positive but wrong when lci < 0).
    """
    lower, upper = av.lci, av.uci
    valid = np.isfinite(lower) & np.isfinite(upper) & (lower > 0)
    if not deviation:
        lower, upper = lower**2, upper**2
    return Band(lower, upper, valid)


def band_label(av: AllanVariance, name: str) -> str:
    """Legend label of the band a result carries: R's (about 95%) or the chi-squared one.

    >>> import numpy as np, avar
    >>> x = np.random.default_rng(0).standard_normal(256)
    >>> band_label(avar.avar(x), "AD"), band_label(avar.avar(x, ci="chi2"), "AV")
    ('CI(AD, 0.95)', 'chi2 CI(AV, 0.683)')
    """
    return f"chi2 CI({name}, {format_confidence(av.confidence)})" if av.ci == "chi2" else f"CI({name}, 0.95)"


def axis_labels(units: str | None, deviation: bool, xlab: str | None, ylab: str | None) -> AxisLabels:
    """Default x and y labels: averaging time (in ``units``) and AV or AD."""
    if xlab is None:
        xlab = r"Averaging time $\tau$" + (f" ({units})" if units else "")
    if ylab is None:
        ylab = r"Allan Deviation $\sigma(\tau)$" if deviation else r"Allan Variance $\sigma^2(\tau)$"
    return AxisLabels(xlab, ylab)


def log_limits(*arrays: np.ndarray, pad: float = 0.04) -> LogLimits | None:
    """:class:`LogLimits` spanning the positive finite values, padded by ``pad`` of their decades;
    None when there is none.

    >>> log_limits(np.array([1e-3, 10.0, -1.0, np.nan]), pad=0.25)
    LogLimits(low=0.0001, high=100.0)
    """
    values = np.concatenate([np.asarray(a, dtype=np.float64).ravel() for a in arrays])
    values = values[np.isfinite(values) & (values > 0)]
    if values.size == 0:
        return None
    low, high = np.log10(values.min()), np.log10(values.max())
    margin = pad * (high - low) if high > low else 0.5
    return LogLimits(float(10 ** (low - margin)), float(10 ** (high + margin)))


def setup_log_axes(ax: Axes) -> None:
    """Log scales (decade ticks labelled 10^k) and a light major grid."""
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.grid(True, which="major", color="0.88", linewidth=0.8)
    ax.set_axisbelow(True)


def draw_empirical(
    ax: Axes, av: AllanVariance, *, deviation: bool, colour: Any, band_colour: Any, ci: bool,
    marker: str, markersize: float, label: str | None, band_label: str | None,
) -> list[np.ndarray]:
    """Band (optional) and points-and-line of one result; returns the arrays drawn."""
    values = values_of(av, deviation)
    ax.plot(av.levels, values, color=colour, marker=marker, markersize=markersize,
            linewidth=1.3, label=label, zorder=3)
    drawn = [values]
    if ci:
        lower, upper, valid = band(av, deviation)
        if valid.any():
            ax.fill_between(av.levels, lower, upper, where=valid, interpolate=False,
                            color=band_colour, linewidth=0, label=band_label, zorder=1)
            drawn += [lower[valid], upper[valid]]
    return drawn


def draw_fit(
    ax: Axes,
    av: AllanVariance,
    implied_ad: Any,
    decomposition: Mapping[str, Any] | None,
    scales: Mapping[str, Any] | None,
    *,
    deviation: bool,
    colour: Any,
    marker: str,
    markersize: float,
    widths: tuple[float, float],
) -> np.ndarray:
    """Overlay a fit on ``ax``: its implied curve, and when given the implied
    curve of each process (dashed) and the scales each process was fitted on.

    ``widths`` are the line widths of the implied total and of the processes.
    Returns the implied curve as drawn (AD or AV).
    """
    power = 1 if deviation else 2
    curve = np.asarray(implied_ad, dtype=np.float64) ** power
    ax.plot(av.levels, curve, color=colour, marker="o" if marker else "", markersize=markersize * 1.2,
            markerfacecolor="none", linewidth=widths[0], label=f"Implied {quantity(deviation)}", zorder=4)
    for process, ad in (decomposition or {}).items():
        ax.plot(av.levels, np.asarray(ad) ** power, color=PROCESS_COLOURS.get(process, "0.3"),
                linewidth=widths[1], linestyle="--", label=process, zorder=2)
    values = values_of(av, deviation)
    for process, used in (scales or {}).items():
        index = np.asarray(used, dtype=np.int64) - 1
        ax.plot(av.levels[index], values[index], linestyle="none", marker=marker or "o",
                markersize=markersize * 1.15, color=PROCESS_COLOURS.get(process, "0.3"),
                label=f"Scales used for {process}", zorder=5)
    return curve


def implied_curve(implied_ad: Any, decomposition: Mapping[str, Any], implied: str) -> np.ndarray:
    """The implied Allan deviation of a fit to draw.

    ``"sum"`` (default of the plots): sqrt of the sum of the processes'
    variances, the AD of a sum of independent processes. ``"r"``: R ``avar``
    0.1.3's curve, the sum of the processes' deviations (DESIGN defect 6).
    """
    if implied == "sum":
        return np.sqrt(np.sum([np.asarray(d, dtype=np.float64) ** 2 for d in decomposition.values()], axis=0))
    if implied == "r":
        return np.asarray(implied_ad, dtype=np.float64)
    raise ValueError(f"implied must be 'sum' (sum of the processes' variances) or 'r' (R's curve), got {implied!r}")


def finish(ax: Axes, xlab: str, ylab: str, main: str | None, legend: str | None,
           limits: LogLimits | None) -> None:
    """Labels, title, y limits and legend."""
    ax.set_xlabel(xlab)
    ax.set_ylabel(ylab)
    if main:
        ax.set_title(main)
    if limits is not None:
        ax.set_ylim(*limits)
    if legend is not None:
        handles, labels = ax.get_legend_handles_labels()
        labels = [label if len(label) <= LEGEND_LABEL else f"{label[:LEGEND_LABEL - 3]}..." for label in labels]
        if len(handles) > LEGEND_ENTRIES:  # 400 series would hide the plot: the first ones, and a count
            from matplotlib.lines import Line2D

            rest = len(handles) - LEGEND_ENTRIES + 1
            handles = handles[: LEGEND_ENTRIES - 1] + [Line2D([], [], linestyle="none")]
            labels = labels[: LEGEND_ENTRIES - 1] + [f"... and {rest} more (legend capped at {LEGEND_ENTRIES})"]
        if handles:
            ax.legend(handles, labels, loc=legend, fontsize="small", framealpha=0.9)


# --------------------------------------------------------------------------- public plots
