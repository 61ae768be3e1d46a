"""Tests of the noise-report figure: deviation axis, labelled term lines, BI marker, implied curve."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.figure import Figure

import avar
from avar.models import FN, RW, WN

FREQ = 50.0


@pytest.fixture(scope="module")
def report():
    model = WN.from_continuous(3e-3, FREQ) + FN.from_continuous(2e-3, FREQ) + RW.from_continuous(3e-4, FREQ)
    data = np.column_stack([model.simulate(180_000, seed=k) for k in range(2)])
    imu = avar.IMU(data, freq=FREQ, gyro=[0], accel=[1], name="bench unit")
    return avar.noise_report(imu, gyro_units="deg/s", accel_units="g")


def coefficient(report, channel, kind):
    """The IEEE coefficient of a fitted term in data units: N = sqrt(c / f), B = sqrt(c), K = sqrt(c f)."""
    c = [x.scale for x in report.fits[channel].components if x.kind == kind][0]
    f = report.freq
    return {"WN": math.sqrt(c / f), "FN": math.sqrt(c), "RW": math.sqrt(c * f)}[kind]


def _closed_form(kind, c, shape, factors):
    """Per-sample Allan variances written out: WN c / m, RW c (2 m^2 + 1) / (6 m), the others by their class."""
    m = factors.astype(float)
    if kind == "WN":
        return c / m
    if kind == "RW":
        return c * (2 * m**2 + 1) / (6 * m)
    if kind == "FN":
        return avar.FN(b2=c).theoretical_av(factors)
    if kind == "AR1":
        return avar.AR1(phi=shape, sigma2=c).theoretical_av(factors)
    return avar.SIN(a2=c, f=shape).theoretical_av(factors)


def line(ax, label):
    found = [ln for ln in ax.lines if ln.get_label() == label]
    assert len(found) == 1, [ln.get_label() for ln in ax.lines]
    return found[0]


def test_deviation_axes_units_and_titles(report):
    fig = report.plot()
    fig.canvas.draw()  # renders headless
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    gyro_ax, accel_ax = fig.axes
    assert gyro_ax.get_xscale() == gyro_ax.get_yscale() == "log"
    assert gyro_ax.get_ylabel() == "Allan deviation [deg/s]"
    assert accel_ax.get_ylabel() == "Allan deviation [g]"
    assert "[s]" in gyro_ax.get_xlabel()
    assert gyro_ax.get_title() == "Gyro. X (gyroscope)"
    assert fig._suptitle.get_text() == "Noise report: bench unit"
    av = report.avs["Gyro. X"]
    np.testing.assert_array_equal(line(gyro_ax, "Empirical AD").get_ydata(), av.adev)


def test_each_term_line_is_labelled_with_value_and_unit(report):
    ax = report.plot().axes[0]
    table = report.table.set_index(["Channel", "Process"])
    fit, av = report.fits["Gyro. X"], report.avs["Gyro. X"]
    n = table.loc[("Gyro. X", "WN"), "Customary"]
    b = table.loc[("Gyro. X", "FN"), "Customary"]
    k = table.loc[("Gyro. X", "RW"), "Customary"]
    wn = line(ax, f"N = {n:.3g} deg/sqrt(h)")
    bi = line(ax, f"B = {b:.3g} deg/h (IEEE 952: AD = 0.664 B)")
    rw = line(ax, f"K = {k:.3g} deg/h/sqrt(h)")
    # each line is the term's own Allan deviation: N / sqrt(tau) and K sqrt(tau / 3) in data units (the
    # continuous-time forms, to the sampling's 1 / (6 m^2)), flicker's exact discrete curve tending to 0.664 B
    tau = av.levels
    np.testing.assert_allclose(wn.get_ydata(), coefficient(report, "Gyro. X", "WN") / np.sqrt(tau), rtol=1e-12)
    np.testing.assert_allclose(bi.get_ydata()[-1], math.sqrt(2 * math.log(2) / math.pi)
                               * coefficient(report, "Gyro. X", "FN"), rtol=1e-6)
    np.testing.assert_allclose(rw.get_ydata(), coefficient(report, "Gyro. X", "RW") * np.sqrt(tau / 3) * np.sqrt(
        1 + 1 / (2 * av.averaging_factors.astype(float) ** 2)), rtol=1e-12)  # (2 m^2 + 1) / (6 m) exactly
    np.testing.assert_allclose(rw.get_ydata()[-6:], coefficient(report, "Gyro. X", "RW") * np.sqrt(tau[-6:] / 3),
                               rtol=1e-6)
    assert fit.components and av.n == 180_000


def test_the_allan_deviation_minimum_is_marked(report):
    ax = report.plot().axes[0]
    row = report.table.set_index(["Channel", "Process"]).loc[("Gyro. X", "MIN")]
    av = report.avs["Gyro. X"]
    marker = line(ax, f"AD minimum {row['Customary']:.3g} deg/h at {row['Tau (s)']:.3g} s")
    assert marker.get_marker() == "*" and marker.get_linestyle() == "None"
    assert marker.get_xdata()[0] == av.levels[np.argmin(av.adev)] == row["Tau (s)"]
    assert marker.get_ydata()[0] == np.min(av.adev)
    assert row["Customary"] == pytest.approx(np.min(av.adev) * 3600, rel=1e-12)  # deg/s -> deg/h


def test_implied_curve_is_the_sum_of_the_processes_variances(report):
    fig = report.plot()
    for ax, channel in zip(fig.axes, report.channels):
        fit, av = report.fits[channel], report.avs[channel]
        total = np.sum([_closed_form(c.kind, c.scale, c.shape, av.averaging_factors) for c in fit.components], axis=0)
        implied = line(ax, "Implied AD (sum of variances)")
        np.testing.assert_allclose(implied.get_ydata() ** 2, total, rtol=1e-12)
    r_ax = report.plot(implied="r").axes[0]
    r_curve = line(r_ax, "Implied AD (R: square of summed deviations)").get_ydata()
    fit, av = report.fits["Gyro. X"], report.avs["Gyro. X"]
    deviations = sum(np.sqrt(c.av(av.averaging_factors)) for c in fit.components)
    np.testing.assert_allclose(r_curve, deviations, rtol=1e-12)
    assert np.all(r_curve > line(report.plot().axes[0], "Implied AD (sum of variances)").get_ydata())


def test_variance_option_channels_and_validation(report):
    fig = report.plot(deviation=False, channels="Accel. X")
    assert len(fig.axes) == 1 and fig.axes[0].get_ylabel() == "Allan variance [(g)^2]"
    np.testing.assert_array_equal(line(fig.axes[0], "Empirical AV").get_ydata(), report.avs["Accel. X"].allan)
    with pytest.raises(ValueError, match="implied"):
        report.plot(implied="product")
    with pytest.raises(ValueError, match="not channels"):
        report.plot(channels=["Gyro. Q"])
    with pytest.raises(TypeError, match="deviation"):
        report.plot(deviation="yes")
