"""Several Allan variances on one figure: :func:`plot_compare` (beyond R)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from matplotlib.axes import Axes
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

from avar._escape import figure_text
from avar.plotting.base import (
    axis_labels,
    check_colour,
    check_result,
    check_style,
    draw_empirical,
    finish,
    log_limits,
    new_axes,
    setup_log_axes,
)
from avar.stability.allan.results import AllanVariance


def compare_items(results: Any, labels: Any) -> list[tuple[str, AllanVariance]]:
    """(label, AllanVariance) pairs of :func:`plot_compare`'s arguments."""
    from avar.fit.results import AvlrResult

    if isinstance(results, Mapping):
        if labels is not None:
            raise ValueError("give the labels either as the keys of a mapping or as labels=, not both")
        labels, results = [figure_text(k) for k in results], list(results.values())  # names from data
    elif isinstance(results, str) or not isinstance(results, Sequence):
        hint = " (for an IMU pass its .channels)" if hasattr(results, "channels") else ""
        raise TypeError(
            "results must be a list (or a mapping label -> result) of AllanVariance or AvlrResult, "
            f"got {type(results).__name__}{hint}"
        )
    results = list(results)
    if not results:
        raise ValueError("plot_compare needs at least one result, got an empty collection")
    items = []
    for i, res in enumerate(results):
        if isinstance(res, AvlrResult):
            res = res.av
        check_result(res, f"results[{i}]")
        items.append(res)
    if labels is None:
        labels = [figure_text(res.name) if res.name else f"Series {i + 1}" for i, res in enumerate(items)]
    else:
        if isinstance(labels, str) or not isinstance(labels, Sequence):
            raise TypeError(f"labels must be a list of strings, got {labels!r}")
        if len(labels) != len(items):
            raise ValueError(f"got {len(labels)} labels for {len(items)} results; give one label per result")
        labels = [str(label) for label in labels]
    return list(zip(labels, items))


def plot_compare(
    results: Sequence[Any] | Mapping[str, Any],
    labels: Sequence[str] | None = None,
    units: str | None = None,
    xlab: str | None = None,
    ylab: str | None = None,
    main: str | None = None,
    colours: Sequence[Any] | None = None,
    ci: bool = False,
    deviation: bool = False,
    legend_position: str | None = "lower left",
    marker: str = "o",
    markersize: float = 4.0,
    ax: Axes | None = None,
) -> Figure:
    """Overlay the Allan variances of several sensors or runs on one plot.

    Parameters
    ----------
    results : list of AllanVariance or AvlrResult, or mapping label -> result
        The curves, drawn in order. An :class:`AvlrResult` contributes its
        empirical Allan variance ``.av``. A mapping such as
        ``imu_res.channels`` gives the labels as its keys.
    labels : list of str, optional
        One legend label per result; default: each result's ``name``, else
        ``"Series 1"``, ``"Series 2"``, ...
    units, xlab, ylab : str, optional
        As in :func:`plot_avar`.
    main : str, optional
        Title; default ``"Allan Variance Comparison"`` (``""`` for none).
    colours : list of matplotlib colours, optional
        One per result; default the matplotlib cycle ``"C0"``, ``"C1"``, ...
    ci : bool
        Also shade each curve's confidence band in its colour (off by default,
        overlapping bands hide each other).
    deviation, legend_position, marker, markersize, ax
        As in :func:`plot_avar`.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> rng = np.random.default_rng(1)
    >>> a = avar.avar(rng.standard_normal(4096), freq=10.0)
    >>> b = avar.avar(2 * rng.standard_normal(8192), freq=10.0)
    >>> fig = plot_compare([a, b], labels=["unit A", "unit B"], deviation=True)
    >>> [line.get_label() for line in fig.axes[0].lines]
    ['unit A', 'unit B']
    >>> plot_compare([])
    Traceback (most recent call last):
    ...
    ValueError: plot_compare needs at least one result, got an empty collection
    """
    items = compare_items(results, labels)
    deviation, ci, legend, markersize = check_style(
        deviation, ci, legend_position, markersize, {}, {"units": units, "xlab": xlab, "ylab": ylab, "main": main})
    if colours is None:
        colours = [f"C{i % 10}" for i in range(len(items))]
    else:
        if isinstance(colours, str) or not isinstance(colours, Sequence) or len(colours) != len(items):
            raise ValueError(f"colours must be a list of {len(items)} colours, one per result, got {colours!r}")
        for i, colour in enumerate(colours):
            check_colour(colour, f"colours[{i}]")
    fig, ax = new_axes(ax)
    setup_log_axes(ax)
    drawn = []
    for (label, av), colour in zip(items, colours):
        drawn += draw_empirical(ax, av, deviation=deviation, colour=colour, band_colour=to_rgba(colour, 0.15),
                                ci=ci, marker=marker, markersize=markersize, label=label, band_label=None)
    xlab, ylab = axis_labels(units, deviation, xlab, ylab)
    finish(ax, xlab, ylab, "Allan Variance Comparison" if main is None else main, legend, log_limits(*drawn))
    return fig
