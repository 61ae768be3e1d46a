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
``uci`` of the Allan deviation (squared for the AV): R's band, or the
chi-squared band of a ``ci="chi2"`` result, as the legend says. A level whose
lower bound is not positive (e.g. the level m = N / 2 of R's band, where the
relative error is 1 / sqrt(2)) stays on the line but has no band, since a log
axis cannot show it.

Functions: :func:`plot_avar` (``AllanVariance.plot``), :func:`plot_avlr`
(``AvlrResult.plot``), :func:`plot_compare` (several curves on one axes),
and the IMU grids :func:`plot_imu_avar` and :func:`plot_imu_avlr` of
:mod:`avar.plotting.imu`.
"""

from __future__ import annotations

from typing import Any

from matplotlib.axes import Axes
from matplotlib.figure import Figure

from avar.plotting.base import (
    AD_COLOUR,
    CI_COLOUR,
    DEFAULT_TITLE,
    IMPLIED_COLOUR,
    axis_labels,
    band,
    band_label,
    check_colour,
    check_flag,
    check_legend_position,
    check_result,
    check_style,
    draw_empirical,
    draw_fit,
    finish,
    implied_curve,
    log_limits,
    new_axes,
    quantity,
    setup_log_axes,
    values_of,
)
from avar.stability.allan.results import AllanVariance


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
    their squares for the AV; levels with ``lci <= 0`` have no band. A result
    of ``avar.avar(..., ci="chi2")`` carries the chi-squared band instead
    (positive at every level); the legend names the band drawn.

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
                           band_label=band_label(x, name))
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
    implied: str = "sum",
) -> Figure:
    """An AVLR fit: the empirical Allan variance and the one implied by the model.

    The port of R ``plot.avlr``: :func:`plot_avar` of ``x.av`` plus the
    implied AV of the model, ``x.implied_av``: the sum of the processes'
    Allan variances (its square root with ``deviation=True``). R draws the
    square of the sum of the processes' deviations instead (DESIGN defect 6),
    ``x.implied_ad**2``; ``implied="r"`` draws that.

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
    implied : {"sum", "r"}
        Implied curve: sum of the processes' variances, or R's curve.

    Returns
    -------
    matplotlib.figure.Figure

    Notes
    -----
    The y range covers the empirical curve, its band and the implied total;
    decomposition lines are clipped to it.

    Examples
    --------
    >>> from avar.fit.avlr import avlr
    >>> from avar.models import RW, WN
    >>> x = (WN(sigma2=1) + RW(gamma2=1e-6)).simulate(20_000, seed=1)
    >>> fit = avlr(x, wn=range(1, 6), rw=range(10, 13))
    >>> fig = plot_avlr(fit, decomp=True, show_scales=True)
    >>> [line.get_label() for line in fig.axes[0].lines]
    ['Empirical AV', 'Implied AV', 'WN', 'RW', 'Scales used for WN', 'Scales used for RW']
    """
    from avar.fit.results import AvlrResult

    if not isinstance(x, AvlrResult):
        raise TypeError(f"x must be an AvlrResult (from avar.avlr), got {type(x).__name__}")
    implied_curve(x.implied_ad, x.implied_ad_decomp, implied)  # validate before drawing
    decomp = check_flag(decomp, "decomp")
    show_scales = check_flag(show_scales, "show_scales")
    check_colour(col_implied, "col_implied")
    fig = plot_avar(x.av, units=units, xlab=xlab, ylab=ylab, main=main, col_ad=col_ad, col_ci=col_ci,
                    ci=ci, deviation=deviation, legend_position=None, marker=marker,
                    markersize=markersize, ax=ax)
    ax = fig.axes[0] if ax is None else ax
    av = x.av
    curve = implied_curve(x.implied_ad, x.implied_ad_decomp, implied)
    implied = draw_fit(ax, av, curve, x.implied_ad_decomp if decomp else None,
                       x.scales_used if show_scales else None, deviation=deviation, colour=col_implied,
                       marker=marker, markersize=markersize, widths=(2.0, 1.3))
    lower, upper, valid = band(av, deviation)
    drawn = [values_of(av, deviation), implied] + ([lower[valid], upper[valid]] if ci else [])
    finish(ax, ax.get_xlabel(), ax.get_ylabel(), None, check_legend_position(legend_position),
           log_limits(*drawn))
    return fig
