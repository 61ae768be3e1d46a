"""Grids of IMU Allan variance plots: :func:`plot_imu_avar`, :func:`plot_imu_avlr`.

One row per sensor type (gyroscopes, then accelerometers, in the order of the
data) and one column per axis; panels of a row share their y range. Drawn on
the ``fig`` given or on a new headless :class:`matplotlib.figure.Figure`; see
:mod:`avar.plotting` for the conventions (bands, colours, legend positions).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from matplotlib.figure import Figure, FigureBase

from avar._escape import figure_text
from avar.plotting.base import (
    AD_COLOUR,
    CI_COLOUR,
    IMPLIED_COLOUR,
    band_label,
    check_flag,
    check_style,
    draw_empirical,
    draw_fit,
    implied_curve,
    log_limits,
    quantity,
    root_figure,
    setup_log_axes,
)
from avar.stability.allan.results import ImuAllanVariance

__all__ = ["plot_imu_avar", "plot_imu_avlr"]


def grid_layout(imu: ImuAllanVariance) -> tuple[tuple[str, ...], tuple[str, ...], dict[tuple[int, int], str]]:
    """Row types, column axes and the channel of every (row, column) panel."""
    rows = imu.present_types
    columns = tuple(dict.fromkeys(imu.axes))
    cells: dict[tuple[int, int], str] = {}
    for name, kind, axis in zip(imu.channels, imu.sensor_types, imu.axes):
        cell = (rows.index(kind), columns.index(axis))
        if cell in cells:
            raise ValueError(
                f"channels {cells[cell]!r} and {name!r} are both {kind} axis {axis!r}; "
                "a grid needs one channel per sensor type and axis"
            )
        cells[cell] = name
    return rows, columns, cells


def row_label(kind: str, unit: str | None, deviation: bool, ylab: str | None) -> str:
    """``"Gyroscope"`` over the quantity, with its unit when known."""
    if ylab is None:
        ylab = r"$\sigma(\tau)$" if deviation else r"$\sigma^2(\tau)$"
        if unit:
            ylab += f" [{unit}]" if deviation else f" [({unit})$^2$]"
    return f"{kind}\n{ylab}"


def draw_grid(
    imu: ImuAllanVariance,
    implied: Mapping[str, np.ndarray] | None,
    decomposition: Mapping[str, Mapping[str, np.ndarray]] | None = None,
    scales: Mapping[str, Mapping[str, np.ndarray]] | None = None,
    *,
    xlab: str | None,
    ylab: str | None,
    main: str | None,
    col_ad: Any,
    col_ci: Any,
    col_implied: Any,
    ci: bool,
    deviation: bool,
    legend_position: Any,
    marker: str,
    markersize: float,
    fig: FigureBase | None,
) -> Figure:
    """The grid of :func:`plot_imu_avar`; for fits also the implied AD per channel, its
    ``decomposition`` per channel and process, and the fitted ``scales`` per sensor type."""
    if not isinstance(imu, ImuAllanVariance):
        raise TypeError(f"x must be an ImuAllanVariance (avar.avar of an IMU), got {type(imu).__name__}")
    if len(imu) == 0:
        raise ValueError("the IMU Allan variance has no channels to plot")
    deviation, ci, legend, markersize = check_style(
        deviation, ci, legend_position, markersize,
        {"col_ad": col_ad, "col_ci": col_ci, "col_implied": col_implied}, {"xlab": xlab, "ylab": ylab, "main": main})
    rows, columns, cells = grid_layout(imu)
    if fig is None:
        fig = Figure(figsize=(3.4 * len(columns) + 1.2, 2.9 * len(rows) + 1.0), layout="constrained")
    elif not isinstance(fig, FigureBase):
        raise TypeError(f"fig must be a matplotlib Figure or SubFigure or None, got {type(fig).__name__}")
    elif fig.axes:
        raise ValueError("fig already has axes; pass an empty Figure (or SubFigure) for the grid")
    grid = fig.subplots(len(rows), len(columns), sharex=True, sharey="row", squeeze=False)
    name = quantity(deviation)
    legend_axes = None
    for r, kind in enumerate(rows):
        drawn = []
        for c, axis in enumerate(columns):
            ax = grid[r, c]
            channel = cells.get((r, c))
            if channel is None:
                ax.set_axis_off()
                continue
            av = imu.channels[channel]
            setup_log_axes(ax)
            drawn += draw_empirical(ax, av, deviation=deviation, colour=col_ad, band_colour=col_ci, ci=ci,
                                    marker=marker, markersize=markersize, label=f"Empirical {name}",
                                    band_label=band_label(av, name))
            if implied is not None and channel in implied:
                drawn.append(draw_fit(ax, av, implied[channel], (decomposition or {}).get(channel),
                                      (scales or {}).get(kind), deviation=deviation, colour=col_implied,
                                      marker=marker, markersize=markersize, widths=(1.8, 1.1)))
            if all((rr, c) not in cells for rr in range(r)):
                ax.set_title(f"Axis - {figure_text(axis)}")
            if all((r, cc) not in cells for cc in range(c)):
                ax.set_ylabel(row_label(kind, imu.units.get(kind), deviation, ylab))
            if legend_axes is None:
                legend_axes = ax
        limits = log_limits(*drawn)
        if limits is not None:
            next(ax for ax in grid[r] if ax.axison).set_ylim(*limits)
    for c in range(len(columns)):  # tick labels on the lowest panel of a column ...
        bottom = max((r for r in range(len(rows)) if (r, c) in cells), default=None)
        if bottom is not None:
            grid[bottom, c].xaxis.set_tick_params(labelbottom=True)
    for r in range(len(rows)):  # ... and on the leftmost panel of a row
        grid[r, min(c for rr, c in cells if rr == r)].yaxis.set_tick_params(labelleft=True)
    fig.supxlabel(r"Averaging time $\tau$ (s)" if xlab is None else xlab)
    if main is None:
        main = f"Allan Variance Representation - {figure_text(imu.sensor)} @ {imu.freq:g} Hz"
    if main:
        fig.suptitle(main)
    if legend is not None and legend_axes is not None:
        legend_axes.legend(loc=legend, fontsize="small", framealpha=0.9)
    return root_figure(fig)


def plot_imu_avar(
    x: ImuAllanVariance,
    xlab: str | None = None,
    ylab: str | None = None,
    main: str | None = None,
    col_ad: Any = AD_COLOUR,
    col_ci: Any = CI_COLOUR,
    ci: bool = True,
    deviation: bool = False,
    legend_position: str | None = "lower left",
    marker: str = "o",
    markersize: float = 4.0,
    fig: FigureBase | None = None,
) -> Figure:
    """Grid of the Allan variances of an IMU: one row per sensor type, one column per axis.

    The port of R ``plot.imu_avar``. Every panel is the log-log plot of
    :func:`avar.plotting.plot_avar` for one channel (AV, or AD with
    ``deviation=True``, with its confidence band; levels whose lower bound is
    not positive keep their point but have no band). Panels of a row share
    one y range; columns are titled ``"Axis - X"``, rows labelled with their
    sensor type (and unit, when the IMU has units).

    Parameters
    ----------
    x : ImuAllanVariance
    xlab : str, optional
        Common x label; default ``"Averaging time $\\tau$ (s)"``.
    ylab : str, optional
        y label under each row's sensor type; default the quantity and unit.
    main : str, optional
        Figure title; default ``"Allan Variance Representation - {sensor} @
        {freq} Hz"`` (``""`` for none).
    col_ad, col_ci, ci, deviation, marker, markersize
        As in :func:`avar.plotting.plot_avar`.
    legend_position : str or None
        Legend of the first panel (matplotlib or R location); ``None`` for none.
    fig : matplotlib.figure.Figure or SubFigure, optional
        An empty figure to draw the grid in; by default a new Figure.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> from avar.imu import IMU
    >>> data = np.random.default_rng(3).standard_normal((4096, 4))
    >>> res = avar.avar(IMU(data, freq=10, gyro=[0, 1], accel=[2, 3], name="demo"))
    >>> fig = plot_imu_avar(res)
    >>> fig._suptitle.get_text()
    'Allan Variance Representation - demo @ 10 Hz'
    >>> [ax.get_title() for ax in fig.axes]
    ['Axis - X', 'Axis - Y', '', '']
    """
    return draw_grid(x, None, xlab=xlab, ylab=ylab, main=main, col_ad=col_ad, col_ci=col_ci,
                     col_implied=IMPLIED_COLOUR, ci=ci, deviation=deviation, legend_position=legend_position,
                     marker=marker, markersize=markersize, fig=fig)


def plot_imu_avlr(
    x: Any,
    decomp: bool = False,
    show_scales: bool = False,
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
    markersize: float = 4.0,
    fig: FigureBase | None = None,
    implied: str = "sum",
) -> Figure:
    """Grid of an IMU AVLR fit: :func:`plot_imu_avar` plus the implied AV of the fit.

    The port of R ``plot.imu_avlr``: every channel's panel also shows the
    Allan variance implied by its fitted model, ``x.implied_av[channel]``, the
    sum of the processes' variances (its square root with ``deviation=True``;
    R's square of the summed deviations, ``x.implied_ad[channel]**2``, with
    ``implied="r"``: DESIGN defect 6); the panels' shared y range covers it.

    Parameters
    ----------
    x : ImuAvlrResult
    decomp : bool
        Add every process's implied AV per panel (beyond R), coloured as in
        :func:`avar.plotting.plot_avlr`.
    show_scales : bool
        Mark the scales each process was fitted on (beyond R).
    col_implied : matplotlib colour
        Colour of the implied curves (R: ``"#F47F24"``).
    implied : {"sum", "r"}
        Implied curves: sum of the processes' variances, or R's curves.
    xlab, ylab, main, col_ad, col_ci, ci, deviation, legend_position, marker, markersize, fig
        As in :func:`plot_imu_avar`.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> from avar.imu import IMU
    >>> data = np.random.default_rng(3).standard_normal((4096, 4))
    >>> res = avar.avar(IMU(data, freq=10, gyro=[0, 1], accel=[2, 3], name="demo"))
    >>> fit = avar.avlr(res, wn_gyro=range(1, 6), wn_acc=range(1, 6))
    >>> fig = plot_imu_avlr(fit)
    >>> [line.get_label() for line in fig.axes[0].lines]
    ['Empirical AV', 'Implied AV']
    >>> bool(np.array_equal(fig.axes[3].lines[1].get_ydata(), fit.implied_av["Accel. Y"]))
    True
    """
    from avar.fit.results import ImuAvlrResult

    if not isinstance(x, ImuAvlrResult):
        raise TypeError(f"x must be an ImuAvlrResult (from avar.avlr of an IMU), got {type(x).__name__}")
    decomp = check_flag(decomp, "decomp")
    show_scales = check_flag(show_scales, "show_scales")
    curves = {name: implied_curve(x.implied_ad[name], x.implied_ad_decomp[name], implied) for name in x.implied_ad}
    return draw_grid(x.imu_av, curves, x.implied_ad_decomp if decomp else None,
                     x.scales_used if show_scales else None, xlab=xlab, ylab=ylab, main=main, col_ad=col_ad,
                     col_ci=col_ci, col_implied=col_implied, ci=ci, deviation=deviation,
                     legend_position=legend_position, marker=marker, markersize=markersize, fig=fig)
