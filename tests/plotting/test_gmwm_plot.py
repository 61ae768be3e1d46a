"""Tests of the GMWM figures: avar.plotting.gmwm."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure

from avar.fit.gmwm import gmwm
from avar.imu import IMU
from avar.models import AR1, RW, WN
from avar.plotting.gmwm import plot_gmwm, plot_imu_gmwm


@pytest.fixture(scope="module")
def fit():
    x = (WN(sigma2=1.0) + AR1(phi=0.99, sigma2=1e-2) + RW(gamma2=3e-5)).simulate(20_000, seed=3)
    return gmwm(x, "WN + AR1 + RW")


def test_lines_are_the_empirical_implied_and_process_deviations(fit):
    fig = fit.plot()
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    lines = {line.get_label(): line for line in ax.lines}
    assert list(lines) == ["Empirical AD", "Implied AD", "WN", "AR1", "RW"]
    np.testing.assert_allclose(lines["Empirical AD"].get_ydata(), np.sqrt(fit.av.allan))
    np.testing.assert_allclose(lines["Implied AD"].get_ydata(), np.sqrt(fit.implied_av))
    wn = fit.model.components[0]
    np.testing.assert_allclose(lines["WN"].get_ydata(), np.sqrt(wn.sigma2 / fit.av.averaging_factors))
    np.testing.assert_allclose(lines["AR1"].get_xdata(), fit.av.levels)
    assert len(ax.collections) == 1  # the band
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    assert ax.get_title().startswith("GMWM fit: WN(")


def test_options(fit):
    ax = plot_gmwm(fit, decomp=False, deviation=False, ci=False, main="").axes[0]
    assert [line.get_label() for line in ax.lines] == ["Empirical AV", "Implied AV"]
    np.testing.assert_allclose(ax.lines[1].get_ydata(), fit.implied_av)
    assert not ax.collections and ax.get_title() == ""


def test_bad_inputs(fit):
    with pytest.raises(TypeError, match="GmwmResult"):
        plot_gmwm(fit.av)
    with pytest.raises(TypeError, match="ImuGmwmResult"):
        plot_imu_gmwm(fit)
    with pytest.raises(TypeError, match="decomp"):
        fit.plot(decomp="yes")


def test_imu_grid():
    data = np.random.default_rng(0).standard_normal((8192, 4))
    imu = IMU(data, freq=100, gyro=[0, 1], accel=[2, 3])
    fig = gmwm(imu, model_gyro="WN", model_acc="WN").plot()
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert len(visible) == 4
    assert [ax.get_title() for ax in visible] == list(imu.channels)
