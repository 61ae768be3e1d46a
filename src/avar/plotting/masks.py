"""The figure of an ITU-T mask check (``MaskCheck.plot()``): the measured MTIE or TDEV and the mask.

Drawn on the ``ax`` given or on a new headless figure, as every figure of :mod:`avar.plotting`.
The mask's name goes into the legend as plain text (no mathtext). :func:`draw_mask` draws a
mask's line on any axes (also ``Deviation.plot(mask=...)``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from avar.plotting.base import AD_COLOUR, new_axes, setup_log_axes
from avar.stability.time_error.masks import Mask, MaskCheck

#: Points of a piece whose limit is a sum of power laws (a curve on log-log axes).
CURVE_POINTS = 60


class MaskLine(NamedTuple):
    """The points of a mask's line: averaging or observation times ``taus`` (s) and the ``limits``
    there (s for MTIE and TDEV, dimensionless for a frequency deviation)."""

    taus: np.ndarray
    limits: np.ndarray


def mask_line(mask: Mask, top: float) -> MaskLine:
    """The (tau, limit) points of ``mask``'s line (s, s): each piece from its low end to its high end
    (``top`` for an open end). A piece of one power law is straight on log-log axes: its two ends;
    a sum of power laws: :data:`CURVE_POINTS` points. A piece's ends are the mask's breakpoints."""
    taus: list[np.ndarray] = []
    limits: list[np.ndarray] = []
    for piece in mask.pieces:
        high = top if np.isinf(piece.high) else piece.high
        if high <= piece.low:
            continue
        grid = (np.array([piece.low, high]) if len(piece.powers) == 1
                else np.geomspace(piece.low, high, CURVE_POINTS))
        taus.append(grid)
        limits.append(piece.limit(grid))
    return MaskLine(np.concatenate(taus), np.concatenate(limits))


def draw_mask(ax: Axes, mask: Mask, top: float, colour="0.3") -> None:
    """The mask's limit as a dashed line on ``ax``, labelled with its name (plain text)."""
    line = mask_line(mask, top)
    ax.plot(line.taus, line.limits, color=colour, linestyle="--", label=mask.name.replace("$", r"\$"), zorder=1)


def plot_mask_check(check: MaskCheck, ax: Axes | None = None) -> Figure:
    """Log-log plot of the measured curve (points failing the mask in red) under the mask's limit."""
    fig, ax = new_axes(ax)
    setup_log_axes(ax)
    draw_mask(ax, check.mask, max(float(check.taus.max()), 10 * check.mask.pieces[-1].low))
    ax.plot(check.taus, check.measured, "o-", color=AD_COLOUR, markersize=4, label="measured")
    failing = ~check.passes
    if failing.any():
        ax.plot(check.taus[failing], check.measured[failing], "o", color="tab:red", markersize=6, label="above the mask")
    ax.set_xlabel("observation interval tau (s)")
    ax.set_ylabel(f"{check.mask.statistic.upper()} (s)")
    ax.set_title(f"{check.mask.statistic.upper()}: {'passes' if check.passed else 'fails'}")
    ax.legend(loc="best", fontsize="small")
    return fig
