"""Matplotlib figures of Allan variance results.

Every function draws on the ``ax`` (single plots) or ``fig`` (grids) it is
given, or on a new :class:`matplotlib.figure.Figure` that is not registered
with :mod:`matplotlib.pyplot` (so nothing opens a window, no global state
changes, and the code runs headless). Every function returns the Figure: save
it with ``fig.savefig("av.png")``; it also displays itself in Jupyter. To
show a plot in a GUI window, create the axes with pyplot and pass them::

    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    res.plot(ax=ax)
    plt.show()

Plots are log-log. The empirical Allan variance (AV, default) or Allan
deviation (AD, ``deviation=True``) is drawn as points joined by a line, over
the shaded band between the lower and upper confidence bounds ``lci`` and
``uci`` of the Allan deviation (squared for the AV). A level whose lower
bound is not positive (e.g. the level m = N / 2, where the relative error is
1 / sqrt(2)) stays on the line but has no band, since a log axis cannot show
it.

Functions: :func:`plot_avar` (``AllanVariance.plot``), :func:`plot_avlr`
(``AvlrResult.plot``), :func:`plot_compare` (several curves on one axes),
and the IMU grids :func:`plot_imu_avar` and :func:`plot_imu_avlr` of
:mod:`avar.plotting_imu` (re-exported here).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import is_color_like
from matplotlib.figure import Figure, FigureBase

from avar.results import AllanVariance

__all__ = ["plot_avar", "plot_avlr", "plot_compare", "plot_imu_avar", "plot_imu_avlr"]

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


def check_style(deviation: Any, ci: Any, legend_position: Any, markersize: Any,
                colours: Mapping[str, Any], texts: Mapping[str, Any]) -> tuple[bool, bool, str | None, float]:
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
    return (check_flag(deviation, "deviation"), check_flag(ci, "ci"),
            check_legend_position(legend_position), float(markersize))


# --------------------------------------------------------------------------- building blocks
def new_axes(ax: Axes | None) -> tuple[Figure, Axes]:
    """The figure of ``ax``, or a new headless figure with one axes."""
    if ax is None:
        fig = Figure(figsize=SINGLE_FIGSIZE, layout="constrained")
        return fig, fig.add_subplot()
    if not isinstance(ax, Axes):
        raise TypeError(f"ax must be a matplotlib Axes or None, got {type(ax).__name__}")
    return root_figure(ax), ax


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


def band(av: AllanVariance, deviation: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lower and upper band and the mask of levels that get a band.

    The band of the AD is [lci, uci]; that of the AV is [lci**2, uci**2].
    A level gets a band only when lci > 0 (a log axis cannot show the rest;
    note that lci**2 would be positive but wrong when lci < 0).
    """
    lower, upper = av.lci, av.uci
    valid = np.isfinite(lower) & np.isfinite(upper) & (lower > 0)
    if not deviation:
        lower, upper = lower**2, upper**2
    return lower, upper, valid


def axis_labels(units: str | None, deviation: bool, xlab: str | None, ylab: str | None) -> tuple[str, str]:
    """Default x and y labels: averaging time (in ``units``) and AV or AD."""
    if xlab is None:
        xlab = r"Averaging time $\tau$" + (f" ({units})" if units else "")
    if ylab is None:
        ylab = r"Allan Deviation $\sigma(\tau)$" if deviation else r"Allan Variance $\sigma^2(\tau)$"
    return xlab, ylab


def log_limits(*arrays: np.ndarray, pad: float = 0.04) -> tuple[float, float] | None:
    """Limits spanning the positive finite values, padded by ``pad`` of their decades."""
    values = np.concatenate([np.asarray(a, dtype=np.float64).ravel() for a in arrays])
    values = values[np.isfinite(values) & (values > 0)]
    if values.size == 0:
        return None
    low, high = np.log10(values.min()), np.log10(values.max())
    margin = pad * (high - low) if high > low else 0.5
    return 10 ** (low - margin), 10 ** (high + margin)


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


def finish(ax: Axes, xlab: str, ylab: str, main: str | None, legend: str | None,
           limits: tuple[float, float] | None) -> None:
    """Labels, title, y limits and legend."""
    ax.set_xlabel(xlab)
    ax.set_ylabel(ylab)
    if main:
        ax.set_title(main)
    if limits is not None:
        ax.set_ylim(*limits)
    if legend is not None:
        ax.legend(loc=legend, fontsize="small", framealpha=0.9)


# --------------------------------------------------------------------------- public plots
def plot_avar(
    x: AllanVariance,
    units: str | None = None,
    xlab: str | None = None,
    ylab: str | None = None,
    main: str | None = None,
    col_ad: Any = AD_COLOUR,
    col_ci: Any = CI_COLOUR,
    ci: bool = True,
    deviation: bool = False,
    legend_position: str | None = "lower left",
    marker: str = "o",
    markersize: float = 5.0,
    ax: Axes | None = None,
) -> Figure:
    """Log-log plot of an empirical Allan variance with its confidence band.

    The port of R ``plot.avar``. The Allan variance AV(tau) (or the deviation
    AD(tau) = sqrt(AV) with ``deviation=True``, which is what R draws) is
    plotted as points and line against tau = m / freq. The band spans the
    bounds of the AD, ``lci``/``uci`` = AD (1 -/+ 2 errors) (about 95%), or
    their squares for the AV; levels with ``lci <= 0`` have no band.

    Parameters
    ----------
    x : AllanVariance
    units : str, optional
        Unit of tau for the default x label, e.g. ``"s"``.
    xlab, ylab, main : str, optional
        Axis labels and title; defaults ``"Averaging time $\\tau$ (units)"``,
        ``"Allan Variance $\\sigma^2(\\tau)$"`` (or ``"Allan Deviation
        $\\sigma(\\tau)$"``) and ``"Allan Variance Representation"``.
        ``main=""`` draws no title.
    col_ad, col_ci : matplotlib colour
        Colour of the curve and of the band.
    ci : bool
        Draw the confidence band.
    deviation : bool
        Plot the Allan deviation instead of the variance.
    legend_position : str or None
        A matplotlib location (``"lower left"``, ``"upper right"``, ``"best"``,
        ...) or an R one (``"bottomleft"``, ``"topright"``, ...); ``None``
        draws no legend.
    marker : str
        Matplotlib marker of the points (``""`` for none).
    markersize : float
        Marker size in points.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; by default a new Figure.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> res = avar.avar(np.random.default_rng(0).standard_normal(4096), freq=100.0)
    >>> fig = plot_avar(res, units="s")
    >>> ax = fig.axes[0]
    >>> ax.get_xscale(), ax.get_yscale(), ax.get_title()
    ('log', 'log', 'Allan Variance Representation')
    >>> bool(np.array_equal(ax.lines[0].get_ydata(), res.allan))
    True
    >>> fig = res.plot(deviation=True, legend_position="topright")
    >>> fig.axes[0].get_legend().get_texts()[0].get_text()
    'Empirical AD'
    """
    check_result(x)
    deviation, ci, legend, markersize = check_style(
        deviation, ci, legend_position, markersize, {"col_ad": col_ad, "col_ci": col_ci},
        {"units": units, "xlab": xlab, "ylab": ylab, "main": main})
    fig, ax = new_axes(ax)
    setup_log_axes(ax)
    name = quantity(deviation)
    drawn = draw_empirical(ax, x, deviation=deviation, colour=col_ad, band_colour=col_ci, ci=ci,
                           marker=marker, markersize=markersize, label=f"Empirical {name}",
                           band_label=f"CI({name}, 0.95)")
    xlab, ylab = axis_labels(units, deviation, xlab, ylab)
    finish(ax, xlab, ylab, DEFAULT_TITLE if main is None else main, legend, log_limits(*drawn))
    return fig


def plot_avlr(
    x: Any,
    decomp: bool = False,
    show_scales: bool = False,
    units: str | None = None,
    xlab: str | None = None,
    ylab: str | None = None,
    main: str | None = None,
    col_ad: Any = AD_COLOUR,
    col_ci: Any = CI_COLOUR,
    col_implied: Any = IMPLIED_COLOUR,
    ci: bool = True,
    deviation: bool = False,
    legend_position: str | None = "lower left",
    marker: str = "o",
    markersize: float = 5.0,
    ax: Axes | None = None,
) -> Figure:
    """An AVLR fit: the empirical Allan variance and the one implied by the model.

    The port of R ``plot.avlr``: :func:`plot_avar` of ``x.av`` plus the
    implied AV ``x.implied_ad**2`` (the implied AD with ``deviation=True``;
    like R, the implied AD is the sum of the processes' deviations).

    Parameters
    ----------
    x : AvlrResult
    decomp : bool
        Add one line per fitted process (its implied AV, or AD), each in its
        colour (WN green, QN purple, RW red, DR brown), with a legend entry.
    show_scales : bool
        Mark the empirical points on the scales each process was fitted on,
        in the process colour.
    units, xlab, ylab, main, col_ad, col_ci, ci, deviation, legend_position, marker, markersize, ax
        As in :func:`plot_avar`.
    col_implied : matplotlib colour
        Colour of the implied curve (R: ``"#F47F24"``).

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    The y range covers the empirical curve, its band and the implied total;
    decomposition lines are clipped to it.

    Examples
    --------
    >>> from avar.avlr import avlr
    >>> from avar.models import RW, WN
    >>> x = (WN(sigma2=1) + RW(gamma2=1e-6)).simulate(20_000, seed=1)
    >>> fit = avlr(x, wn=range(1, 6), rw=range(10, 13))
    >>> fig = plot_avlr(fit, decomp=True, show_scales=True)
    >>> [line.get_label() for line in fig.axes[0].lines]
    ['Empirical AV', 'Implied AV', 'WN', 'RW', 'Scales used for WN', 'Scales used for RW']
    """
    from avar.avlr import AvlrResult

    if not isinstance(x, AvlrResult):
        raise TypeError(f"x must be an AvlrResult (from avar.avlr), got {type(x).__name__}")
    decomp = check_flag(decomp, "decomp")
    show_scales = check_flag(show_scales, "show_scales")
    check_colour(col_implied, "col_implied")
    fig = plot_avar(x.av, units=units, xlab=xlab, ylab=ylab, main=main, col_ad=col_ad, col_ci=col_ci,
                    ci=ci, deviation=deviation, legend_position=None, marker=marker,
                    markersize=markersize, ax=ax)
    ax = fig.axes[0] if ax is None else ax
    av = x.av
    implied = draw_fit(ax, av, x.implied_ad, x.implied_ad_decomp if decomp else None,
                       x.scales_used if show_scales else None, deviation=deviation, colour=col_implied,
                       marker=marker, markersize=markersize, widths=(2.0, 1.3))
    lower, upper, valid = band(av, deviation)
    drawn = [values_of(av, deviation), implied] + ([lower[valid], upper[valid]] if ci else [])
    finish(ax, ax.get_xlabel(), ax.get_ylabel(), None, check_legend_position(legend_position),
           log_limits(*drawn))
    return fig


def __getattr__(name: str) -> Any:
    """The IMU grids and the comparison live in their own modules; re-exported lazily."""
    if name in ("plot_imu_avar", "plot_imu_avlr"):
        from avar import plotting_imu

        return getattr(plotting_imu, name)
    if name == "plot_compare":
        from avar import plotting_compare

        return plotting_compare.plot_compare
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
