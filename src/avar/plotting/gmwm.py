"""Figures of GMWM fits: :func:`plot_gmwm` (one series) and :func:`plot_imu_gmwm` (IMU channels)."""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from avar._escape import figure_text
from avar.plotting.base import (
    IMPLIED_COLOUR,
    band,
    check_colour,
    check_flag,
    check_legend_position,
    draw_fit,
    finish,
    log_limits,
    values_of,
)
from avar.plotting.single import plot_avar

__all__ = ["plot_gmwm", "plot_imu_gmwm"]


def plot_gmwm(
    x: Any, decomp: bool = True, deviation: bool = True, ci: bool = True, units: str | None = None,
    main: str | None = None, col_implied: Any = IMPLIED_COLOUR, legend_position: str | None = "lower left",
    marker: str = "o", markersize: float = 5.0, ax: Axes | None = None,
) -> Figure:
    """A GMWM fit: the empirical Allan deviation with its band, the implied one and each process.

    Parameters
    ----------
    x : GmwmResult
    decomp : bool
        Add one dashed line per fitted process (its theoretical AD, or AV).
    deviation : bool
        Plot deviations (default) or variances.
    ci, units, main, legend_position, marker, markersize, ax
        As in :func:`avar.plotting.plot_avar`.
    col_implied : matplotlib colour
        Colour of the implied curve.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from avar.fit.gmwm import gmwm
    >>> from avar.models import RW, WN
    >>> fit = gmwm((WN(sigma2=1) + RW(gamma2=1e-5)).simulate(20_000, seed=1), "WN + RW")
    >>> [line.get_label() for line in fit.plot().axes[0].lines]
    ['Empirical AD', 'Implied AD', 'WN', 'RW']
    """
    from avar.fit.gmwm.results import GmwmResult

    if not isinstance(x, GmwmResult):
        raise TypeError(f"x must be a GmwmResult (from avar.gmwm), got {type(x).__name__}")
    decomp = check_flag(decomp, "decomp")
    check_colour(col_implied, "col_implied")
    legend = check_legend_position(legend_position)
    title = f"GMWM fit: {x.model!r}" if main is None else main
    fig = plot_avar(x.av, units=units, main=title, ci=ci, deviation=deviation, legend_position=None,
                    marker=marker, markersize=markersize, ax=ax)
    ax = fig.axes[0] if ax is None else ax
    parts = {label: np.sqrt(av) for label, av in x.decomposition.items()} if decomp else None
    implied = draw_fit(ax, x.av, x.implied_ad, parts, None, deviation=deviation, colour=col_implied,
                       marker=marker, markersize=markersize, widths=(2.0, 1.3))
    lower, upper, valid = band(x.av, deviation)
    drawn = [values_of(x.av, deviation), implied] + ([lower[valid], upper[valid]] if ci else [])
    finish(ax, ax.get_xlabel(), ax.get_ylabel(), None, legend, log_limits(*drawn))
    return fig


def plot_imu_gmwm(x: Any, decomp: bool = True, deviation: bool = True, **kwargs: Any) -> Figure:
    """One :func:`plot_gmwm` panel per IMU channel: a row per sensor type, a column per axis.

    Examples
    --------
    >>> import numpy as np
    >>> from avar.fit.gmwm import gmwm
    >>> from avar.imu import IMU
    >>> data = np.random.default_rng(0).standard_normal((4096, 2))
    >>> fit = gmwm(IMU(data, freq=100, gyro=[0], accel=[1]), model_gyro="WN", model_acc="WN")
    >>> len(fit.plot().axes)
    2
    """
    from avar.fit.gmwm.results import ImuGmwmResult

    if not isinstance(x, ImuGmwmResult):
        raise TypeError(f"x must be an ImuGmwmResult (from avar.gmwm on IMU data), got {type(x).__name__}")
    imu = x.imu_av
    rows = imu.present_types
    columns = tuple(dict.fromkeys(imu.axes))
    fig = Figure(figsize=(4.2 * len(columns), 3.6 * len(rows)), layout="constrained")
    panels = fig.subplots(len(rows), len(columns), squeeze=False)
    used = set()
    for name, kind, axis in zip(imu.channels, imu.sensor_types, imu.axes):
        cell = (rows.index(kind), columns.index(axis))
        used.add(cell)
        plot_gmwm(x.fits[name], decomp=decomp, deviation=deviation, main=figure_text(name),
                  legend_position="lower left" if not used - {cell} else None, ax=panels[cell], **kwargs)
    for cell in np.ndindex(panels.shape):
        if cell not in used:
            panels[cell].set_visible(False)
    return fig
