"""The figure of an ITU-T mask check (``MaskCheck.plot()``): the measured MTIE or TDEV and the mask.

Drawn on the ``ax`` given or on a new headless figure, as every figure of :mod:`avar.plotting`.
The mask's name goes into the legend as plain text (no mathtext).
"""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from avar.plotting.base import AD_COLOUR, new_axes, setup_log_axes
from avar.stability.time_error.masks import MaskCheck


def plot_mask_check(check: MaskCheck, ax: Axes | None = None) -> Figure:
    """Log-log plot of the measured curve (points failing the mask in red) under the mask's limit."""
    fig, ax = new_axes(ax)
    setup_log_axes(ax)
    low, high = check.mask.taus
    top = check.taus.max() if np.isinf(high) else high
    grid = np.geomspace(low * (1 + 1e-9), top, 400)
    ax.plot(grid, check.mask.limit(grid), color="0.3", linestyle="--", label=check.mask.name.replace("$", r"\$"))
    ax.plot(check.taus, check.measured, "o-", color=AD_COLOUR, markersize=4, label="measured")
    failing = ~check.passes
    if failing.any():
        ax.plot(check.taus[failing], check.measured[failing], "o", color="tab:red", markersize=6, label="above the mask")
    ax.set_xlabel("observation interval tau (s)")
    ax.set_ylabel(f"{check.mask.statistic.upper()} (s)")
    ax.set_title(f"{check.mask.statistic.upper()}: {'passes' if check.passed else 'fails'}")
    ax.legend(loc="best", fontsize="small")
    return fig
