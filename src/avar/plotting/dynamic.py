"""The figure of a dynamic deviation (``DynamicDeviation.plot()``): a heat map or Stable32's 3-D view,
drawn and returned as every figure of :mod:`avar.plotting`."""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from avar.plotting.base import SINGLE_FIGSIZE, new_axes, root_figure
from avar.stability.dynamic.results import DynamicDeviation

KINDS = ("heatmap", "surface")


def _edges(centres: np.ndarray, log: bool) -> np.ndarray:
    """Cell edges around increasing centres (halfway between neighbours, in log space if ``log``)."""
    values = np.log(centres) if log else np.asarray(centres, dtype=np.float64)
    if values.size == 1:
        half = 0.5 if not log else np.log(2.0) / 2
        edges = np.array([values[0] - half, values[0] + half])
    else:
        middle = (values[1:] + values[:-1]) / 2
        edges = np.concatenate(([2 * values[0] - middle[0]], middle, [2 * values[-1] - middle[-1]]))
    return np.exp(edges) if log else edges


def plot_dynamic(x: DynamicDeviation, kind: str = "heatmap", main: str | None = None, cmap: str = "viridis",
                 ax: Axes | None = None) -> Figure:
    """The deviation of every window against its centre time and tau.

    ``kind="heatmap"``: one cell per window and tau, coloured on a log scale (the deviation's
    colour bar), tau on a log axis. ``kind="surface"``: Stable32's 3-D view, log10 of the
    deviation over time and log10 tau (``ax``, if given, must be a 3-D axes). Cells without a
    value (gaps) are left blank.

    Parameters
    ----------
    x : DynamicDeviation
        From :func:`avar.dynamic`, :func:`avar.dadev` or :func:`avar.dhdev`.
    kind : {"heatmap", "surface"}
    main : str, optional
        Title; by default the statistic's long name and the window.
    cmap : str
        A matplotlib colour map.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; by default a new Figure.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> res = avar.dadev(np.random.default_rng(0).standard_normal(2000), window=400, step=100)
    >>> ax = plot_dynamic(res).axes[0]
    >>> ax.get_yscale(), ax.get_xlabel()
    ('log', 'Time (s)')
    """
    if not isinstance(x, DynamicDeviation):
        raise TypeError(f"x must be a DynamicDeviation (from avar.dynamic, avar.dadev, avar.dhdev), "
                        f"got {type(x).__name__}")
    if not isinstance(kind, str) or kind not in KINDS:
        raise ValueError(f"kind must be 'heatmap' or 'surface', got {kind!r}")
    if main is not None and not isinstance(main, str):
        raise TypeError(f"main must be a string or None, got {main!r}")
    unit = " (s)" if x.estimator in ("tdev", "htdev") else ""
    title = (f"{x.long_name.capitalize()}, windows of {x.window} samples" if main is None else main)
    values = np.where(x.deviation > 0, x.deviation, np.nan)
    if kind == "surface":
        if ax is None:
            fig = Figure(figsize=SINGLE_FIGSIZE, layout="constrained")
            ax = fig.add_subplot(projection="3d")
        elif getattr(ax, "name", "") != "3d":
            raise ValueError("kind='surface' draws on a 3-D axes (projection='3d'); pass one or none")
        else:
            fig = root_figure(ax)
        time, tau = np.meshgrid(x.times, np.log10(x.taus), indexing="ij")
        ax.plot_surface(time, tau, np.log10(values), cmap=cmap, linewidth=0, antialiased=True)
        ax.set_xlabel("Time (s)")
        ax.set_ylabel(r"log$_{10}$ $\tau$ (s)")
        ax.set_zlabel(f"log$_{{10}}$ {x.name}{unit}")
        ax.set_title(title)
        return fig
    fig, ax = new_axes(ax)
    finite = values[np.isfinite(values)]
    norm = LogNorm(vmin=finite.min(), vmax=finite.max()) if finite.size else None
    mesh = ax.pcolormesh(_edges(x.times, log=False), _edges(x.taus, log=True), np.ma.masked_invalid(values).T,
                         norm=norm, cmap=cmap, shading="flat")
    ax.set_yscale("log")
    ax.set_xlabel("Time (s)")
    ax.set_ylabel(r"Averaging time $\tau$ (s)")
    ax.set_title(title)
    fig.colorbar(mesh, ax=ax, label=f"{x.name}{unit}")
    return fig
