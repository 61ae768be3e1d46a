"""The figure of a time-and-frequency deviation (``Deviation.plot()``).

Like every figure of :mod:`avar.plotting`, it draws on the ``ax`` given or on a
new :class:`matplotlib.figure.Figure` not registered with pyplot (headless,
no global state), and returns the Figure.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from avar.plotting.base import (
    AD_COLOUR,
    check_colour,
    check_legend_position,
    finish,
    log_limits,
    new_axes,
    setup_log_axes,
)
from avar.stability.shared.confidence import format_confidence
from avar.stability.shared.deviation import Deviation


def plot_deviation(
    x: Deviation,
    xlab: str | None = None,
    ylab: str | None = None,
    main: str | None = None,
    colour: Any = AD_COLOUR,
    error_bars: bool = True,
    legend_position: str | None = "lower left",
    marker: str = "o",
    ax: Axes | None = None,
    mask: Any = None,
) -> Figure:
    """Log-log plot of a deviation against tau with its chi-squared error bars.

    The points are ``x.deviation`` at ``x.taus``; the asymmetric error bar of
    each level spans ``[x.lci, x.uci]`` (the ``x.confidence`` chi-squared
    interval); levels whose bounds are not finite and positive get no bar.

    Parameters
    ----------
    x : Deviation
        From :func:`avar.adev` ... :func:`avar.totdev`.
    xlab, ylab, main : str, optional
        Axis labels and title; by default ``"Averaging time tau (s)"``, the
        estimator's name (``"OADEV sigma_y(tau)"``; TDEV ``"TDEV sigma_x(tau) (s)"``)
        and its long name with the noise of the input.
    colour : matplotlib colour
    error_bars : bool
        Draw the confidence bars.
    legend_position : str or None
        A matplotlib or R legend location; ``None`` draws no legend.
    marker : str
        Matplotlib marker of the points.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; by default a new Figure.
    mask : str or Mask, optional
        An ITU-T mask drawn as a dashed line over the MTIE or TDEV: a name of
        :data:`avar.MASKS`, a clock's name (``"G.8262 EEC option 1"``: its mask of
        this statistic) or a :class:`avar.Mask`; see :func:`avar.mask_check` for the
        verdict.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> res = avar.oadev(np.random.default_rng(0).standard_normal(1000))
    >>> ax = plot_deviation(res).axes[0]
    >>> ax.get_xscale(), ax.get_yscale(), ax.get_ylabel()
    ('log', 'log', 'OADEV $\\\\sigma_y(\\\\tau)$')
    >>> tdev = avar.tdev(np.random.default_rng(1).standard_normal(1000) * 1e-9, data_type="phase")
    >>> line = tdev.plot(mask="G.8262 EEC option 1").axes[0].lines[-1]
    >>> line.get_label(), line.get_xdata().tolist()
    ('G.8262 EEC option 1 TDEV', [0.1, 25.0, 25.0, 100.0, 100.0, 1000.0])
    """
    if not isinstance(x, Deviation):
        raise TypeError(f"x must be a Deviation (from avar.adev, avar.oadev, ...), got {type(x).__name__}")
    check_colour(colour, "colour")
    legend = check_legend_position(legend_position)
    if not isinstance(error_bars, (bool, np.bool_)):
        raise TypeError(f"error_bars must be True or False, got {error_bars!r}")
    for role, text in {"xlab": xlab, "ylab": ylab, "main": main}.items():
        if text is not None and not isinstance(text, str):
            raise TypeError(f"{role} must be a string or None, got {text!r}")
    fig, ax = new_axes(ax)
    setup_log_axes(ax)
    label = f"{x.name}, N = {x.n_samples}"
    # one line per run of increasing taus (ThêoH: its Allan levels, then its Theo1 levels, which may overlap)
    for i, part in enumerate(np.split(np.arange(x.taus.size), np.flatnonzero(np.diff(x.taus) < 0) + 1)):
        ax.plot(x.taus[part], x.deviation[part], color=colour, marker=marker, linewidth=1.3,
                label=label if i == 0 else None, zorder=3)
    drawn = [x.deviation]
    if error_bars:
        valid = np.isfinite(x.lci) & np.isfinite(x.uci) & (x.lci > 0)
        if valid.any():
            below = x.deviation[valid] - x.lci[valid]
            above = x.uci[valid] - x.deviation[valid]
            ax.errorbar(x.taus[valid], x.deviation[valid], yerr=np.vstack([below, above]), fmt="none",
                        ecolor=colour, elinewidth=1.0, capsize=3, zorder=2,
                        label=f"{format_confidence(x.confidence)} confidence (chi-squared)")
            drawn += [x.lci[valid], x.uci[valid]]
    if mask is not None:
        from avar.plotting.masks import draw_mask, mask_line
        from avar.stability.time_error.masks import find_mask

        found = find_mask(mask, x.estimator)
        top = max(float(np.max(x.taus)), 10 * found.pieces[-1].low)
        draw_mask(ax, found, top)
        line = mask_line(found, top)
        drawn.append(line.limits[(line.taus >= np.min(x.taus)) & (line.taus <= np.max(x.taus))])
    if ylab is None:
        ylab = f"{x.name} $\\sigma_x(\\tau)$ (s)" if x.estimator in ("tdev", "ttotdev") else f"{x.name} $\\sigma_y(\\tau)$"
    xlab = r"Averaging time $\tau$ (s)" if xlab is None else xlab
    title = f"{x.long_name.capitalize()} ({x.data_type} data)" if main is None else main
    finish(ax, xlab, ylab, title, legend, log_limits(*drawn))
    return fig
