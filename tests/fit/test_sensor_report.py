"""The noise report on sensors as they are: terms chosen by the data, checked fits, warnings.

Series are made here with NumPy and SciPy alone (FFT 1/f flicker, lfilter
Gauss-Markov, a sine), independent of the package's process classes.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import avar
from avar.fit.gmwm import octave_factors
from avar.fit.report.checks import data_warnings, fit_check, unit_warnings
from avar.fit.report.sensor_fit import fit_sensor_model, term_bound
from avar.fit.terms import basis
from avar.models import AR1, SIN, WN
from avar.models.flicker import av_fn, flicker_unit_av

FREQ = 200.0


def flicker(rng: np.random.Generator, n: int, b: float, freq: float) -> np.ndarray:
    """1/f noise of one-sided PSD B^2 / (pi f) by FFT on 2n samples (IEEE 952: AD plateau 0.664 B)."""
    f = np.fft.rfftfreq(2 * n, d=1.0 / freq)
    psd = np.zeros_like(f)
    psd[1:] = b * b / (math.pi * f[1:])
    spectrum = np.sqrt(psd * freq * 2 * n / 4.0) * (rng.standard_normal(f.size) + 1j * rng.standard_normal(f.size))
    spectrum[0] = 0.0
    return np.fft.irfft(spectrum, n=2 * n)[:n]


def gauss_markov(rng: np.random.Generator, n: int, sigma: float, time: float, freq: float) -> np.ndarray:
    from scipy.signal import lfilter

    phi = math.exp(-1.0 / (time * freq))
    return lfilter([1.0], [1.0, -phi], sigma * math.sqrt(1 - phi * phi) * rng.standard_normal(n))


def row(report, process: str, channel: str = "x") -> pd.Series:
    table = report.table
    return table[(table["Channel"] == channel) & (table["Process"] == process)].iloc[0]


@pytest.mark.parametrize("seed", [1, 2])
def test_white_flicker_and_random_walk_of_independent_code(seed):
    n, truth = int(1800 * FREQ), {"WN": 1.2e-4, "FN": 1e-4, "RW": 4e-5}
    rng = np.random.default_rng(seed)
    x = truth["WN"] * math.sqrt(FREQ) * rng.standard_normal(n) + flicker(rng, n, truth["FN"], FREQ)
    x += np.cumsum(truth["RW"] / math.sqrt(FREQ) * rng.standard_normal(n))
    report = avar.noise_report(x, gyro_units="rad/s", rate=FREQ)
    assert row(report, "WN")["Value"] == pytest.approx(truth["WN"], rel=0.01)
    assert row(report, "FN")["Value"] == pytest.approx(truth["FN"], rel=0.15)
    walk = row(report, "RW")
    assert walk["Status"] == "present" and float(walk["Lower"]) < truth["RW"] < float(walk["Upper"])
    assert report.curves["Fits"].mean() >= 0.9 and not report.warnings


def test_a_gauss_markov_term_gives_its_correlation_time():
    n = int(1800 * FREQ)
    rng = np.random.default_rng(4)
    x = 1e-3 * math.sqrt(FREQ) * rng.standard_normal(n) + gauss_markov(rng, n, 3e-3, 2.0, FREQ)
    report = avar.noise_report(x, gyro_units="rad/s", rate=FREQ)
    times = report.table[report.table["Process"].str.endswith(".T")]
    assert len(times) >= 1
    best = times.iloc[int(np.argmin(np.abs(np.log(times["Value"].astype(float) / 2.0))))]
    assert float(best["Value"]) == pytest.approx(2.0, rel=0.25)
    assert float(best["Lower"]) < float(best["Value"]) < float(best["Upper"])
    assert row(report, "WN")["Value"] == pytest.approx(1e-3, rel=0.02)


def test_a_sinusoid_gives_its_frequency_and_amplitude():
    n = int(600 * FREQ)
    rng = np.random.default_rng(5)
    t = np.arange(n) / FREQ
    x = 0.01 * rng.standard_normal(n) + 0.02 * np.sin(2 * np.pi * 1.7 * t + 0.3)
    report = avar.noise_report(x, accel_units="m/s^2", rate=FREQ)
    hertz = report.table[report.table["Process"].str.startswith("SIN") & report.table["Process"].str.endswith(".f")]
    amplitude = report.table[report.table["Term"].str.endswith("amplitude")]
    near = np.abs(hertz["Value"].astype(float) - 1.7) / 1.7
    assert near.min() < 0.05
    assert float(amplitude.iloc[int(np.argmin(near))]["Value"]) == pytest.approx(0.02, rel=0.15)


def test_exact_curves_are_recovered_and_a_bound_covers_an_unresolved_term():
    m = octave_factors(2**20)
    # each term dominates a range of the levels: AR1 bumps near 300 samples, flicker is flat beyond, the walk last
    truth = [("WN", 1.0, None), ("FN", 1e-3, None), ("RW", 1e-8, None), ("AR1", 0.05, math.exp(-1 / 30))]
    nu = sum(c * basis(k, s, m) for k, c, s in truth)
    edf = np.maximum((2**20 - 2 * m + 1) / m, 1.0)
    fit = fit_sensor_model(m, nu, edf, kinds=("QN", "WN", "FN", "RW", "AR1"), penalty=0.0)
    np.testing.assert_allclose(fit.implied(), nu, rtol=1e-8)
    main = {c.kind: c for c in fit.components if c.av(m).max() > 1e-6 * nu.max()}  # negligible extras aside
    assert sorted(main) == ["AR1", "FN", "RW", "WN"]
    for kind, scale, shape in truth:
        assert main[kind].scale == pytest.approx(scale, rel=1e-5)
        if shape is not None:
            assert main[kind].shape == pytest.approx(shape, rel=1e-7)
    without = fit_sensor_model(m, nu - 1e-8 * basis("RW", None, m) + 1e-14 * basis("RW", None, m), edf,
                               kinds=("WN", "FN", "AR1"))
    assert term_bound(without, "RW") > 1e-14


def test_the_flicker_expansion_and_the_sinusoid_theory():
    big = np.array([4097, 10**5, 2**19])
    np.testing.assert_allclose(flicker_unit_av(big), av_fn(1.0, big), rtol=1e-12)
    s = SIN(a2=0.5, f=0.01)
    x = s.simulate(400_000, seed=3)
    factors = np.array([1, 5, 20, 37, 80])
    empirical = avar.avar(x, taus=factors.astype(float)).allan
    np.testing.assert_allclose(empirical, s.theoretical_av(factors), rtol=2e-3, atol=1e-6)


def test_a_model_that_cannot_fit_is_flagged():
    tau = 2.0 ** np.arange(10)
    adev = np.where(np.arange(10) % 2 == 0, 1.0, 2.0)  # a zigzag no sum of processes follows
    fits, text = fit_check("gx", tau, adev, 0.95 * adev, 1.05 * adev, np.full(10, 1.5))
    assert not fits.any() and "gx" in text and "10 of 10 levels" in text


def test_data_problems_are_named():
    rng = np.random.default_rng(6)
    x = rng.standard_normal(100_000)
    assert data_warnings("gx", "Gyroscope", x, 100.0, 16) == []
    clipped = np.clip(x, -1.5, 1.5)
    assert any("clipped" in w for w in data_warnings("gx", "Gyroscope", clipped, 100.0, 16))
    stuck = np.repeat(x[:25_000], 4)
    assert any("repeat" in w for w in data_warnings("gx", "Gyroscope", stuck, 100.0, 16))
    spiky = x.copy()
    spiky[rng.choice(x.size, 3000, replace=False)] += 30.0
    assert any("--robust" in w for w in data_warnings("gx", "Gyroscope", spiky, 100.0, 16))
    assert any("too short" in w for w in data_warnings("gx", "Gyroscope", x[:50], 100.0, 5))
    tilted = x + 300.0 * np.sin(2 * np.pi * 0.01 * np.arange(x.size) / 100.0)  # turned slowly, 300 sigma
    assert any("at rest" in w for w in data_warnings("ax", "Accelerometer", tilted, 100.0, 16))
    random_walk = x + np.cumsum(0.01 * rng.standard_normal(x.size))  # a static sensor's random walk
    assert not any("at rest" in w for w in data_warnings("ax", "Accelerometer", random_walk, 100.0, 16))


def test_wrong_units_are_warned_with_the_flag():
    gravity = np.full(1000, -1.0)
    assert any("--accel-units g" in w for w in unit_warnings("az", "Accelerometer", "m/s^2", gravity, 1e-3, False))
    assert any("--accel-units m/s^2" in w for w in unit_warnings("az", "Accelerometer", "g", gravity * 9.8, 1e-3, False))
    # 2 deg/sqrt(h) read as rad/s: 115 deg/sqrt(h)
    assert any("--gyro-units deg/s" in w for w in unit_warnings("gx", "Gyroscope", "rad/s", np.zeros(10), 2 / 60, False))
    assert unit_warnings("gx", "Gyroscope", "deg/s", np.zeros(10), 2 / 60, False) == []
    assert any("ROS bags" in w for w in unit_warnings("gx", "Gyroscope", "deg/s", np.zeros(10), 2 / 60, True))


def test_a_short_log_never_fits_more_terms_than_its_levels_support():
    x = (WN(sigma2=1.0) + AR1(phi=0.9, sigma2=0.1)).simulate(50, seed=2)
    report = avar.noise_report(x, gyro_units="rad/s", rate=10.0)
    fit = report.fits["x"]
    parameters = sum(1 if c.shape is None else 2 for c in fit.components)
    assert parameters <= len(report.avs["x"]) - 2
    assert any("too short" in w for w in report.warnings)


def test_spikes_are_warned_about_and_the_robust_report_gives_the_clean_terms():
    n = int(1800 * FREQ)
    rng = np.random.default_rng(8)
    sigma = 1.2e-4 * math.sqrt(FREQ)
    clean = sigma * rng.standard_normal(n) + np.cumsum(5e-5 / math.sqrt(FREQ) * rng.standard_normal(n))
    spiked = clean.copy()
    where = rng.choice(n, n // 20, replace=False)  # 5 % of the samples
    spiked[where] += 20 * sigma * rng.choice([-1.0, 1.0], where.size)
    truth = avar.noise_report(clean, gyro_units="rad/s", rate=FREQ)
    plain = avar.noise_report(spiked, gyro_units="rad/s", rate=FREQ)
    robust = avar.noise_report(spiked, gyro_units="rad/s", rate=FREQ, robust=True)
    assert not truth.warnings
    assert any("outliers" in w and "--robust" in w for w in plain.warnings)
    assert plain.value("x", "WN") > 3 * truth.value("x", "WN")  # the spikes swamp the white noise
    for process in ("WN", "RW"):
        assert robust.value("x", process) == pytest.approx(truth.value("x", process), rel=0.10)
    assert any("sets them aside" in w for w in robust.warnings)


def test_a_time_indexed_series_gives_its_rate_to_the_plain_and_the_robust_report():
    x = WN(sigma2=1e-4).simulate(40_000, seed=3)
    series = pd.Series(x, index=pd.date_range("2026-01-01", periods=x.size, freq="10ms"))
    plain = avar.noise_report(x, gyro_units="rad/s", rate=100.0)
    for report in (avar.noise_report(series, gyro_units="rad/s"),
                   avar.noise_report(series, gyro_units="rad/s", robust=True)):
        assert report.freq == 100.0
        np.testing.assert_array_equal(report.avs["x"].levels, plain.avs["x"].levels)
        assert report.value("x", "WN") == pytest.approx(plain.value("x", "WN"), rel=1e-9)
