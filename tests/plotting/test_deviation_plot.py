"""The figure of a Deviation: log axes, the points plotted and the chi-squared error bars."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure

import avar
from avar.plotting import plot_deviation


def test_plot_draws_points_and_error_bars():
    res = avar.oadev(np.random.default_rng(0).standard_normal(4096), rate=10.0)
    fig = res.plot()
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    np.testing.assert_array_equal(ax.lines[0].get_xdata(), res.taus)
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), res.deviation)
    assert "OADEV" in ax.get_ylabel()
    bars = ax.collections[0].get_segments()
    assert len(bars) == len(res)
    for segment, tau, low, high in zip(bars, res.taus, res.lci, res.uci):
        np.testing.assert_allclose(segment[:, 0], [tau, tau])
        np.testing.assert_allclose(sorted(segment[:, 1]), [low, high], rtol=1e-12)


def test_tdev_label_and_options():
    res = avar.tdev(np.random.default_rng(1).standard_normal(500))
    ax = plot_deviation(res, error_bars=False, legend_position=None, main="T").axes[0]
    assert "TDEV" in ax.get_ylabel() and "(s)" in ax.get_ylabel()
    assert len(ax.collections) == 0 and ax.get_legend() is None and ax.get_title() == "T"
    with pytest.raises(TypeError, match="x must be a Deviation"):
        plot_deviation("nope")
    with pytest.raises(ValueError, match="colour"):
        plot_deviation(res, colour="notacolour")
    with pytest.raises(TypeError, match="error_bars"):
        plot_deviation(res, error_bars=1)


def test_theoh_draws_its_allan_and_theo1_levels_as_two_lines():
    x = np.cumsum(np.random.default_rng(4).standard_normal(1253))
    res = avar.theoh(x, data_type="phase")  # OADEV to m = 256 (tau 256 s), Theo1 from tau 192 s
    fig = res.plot(error_bars=False)
    lines = [line for line in fig.axes[0].lines if len(line.get_xdata())]
    assert [len(line.get_xdata()) for line in lines] == [9, 3]
    np.testing.assert_array_equal(lines[1].get_xdata(), res.taus[9:])
    assert lines[0].get_label().endswith(f"N = {res.n_samples}") and lines[1].get_label().startswith("_")  # one legend entry
