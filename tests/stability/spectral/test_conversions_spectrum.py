"""Conversions, drift removal, power-law noise, PSD and PSD-to-deviation: closed forms, peers, simulation."""

from __future__ import annotations

import allantools
import numpy as np
import pytest

import avar
from avar.models.noise import discrete_psd, filter_coefficients
from avar.stability.uncertainty.edf import chi2_bounds, estimator_edf


def test_conversions_round_trip_and_match_allantools():
    rng = np.random.default_rng(0)
    y = 1e-11 * rng.standard_normal(500) + 3e-9
    x = avar.frequency_to_phase(y, rate=4.0)
    assert x.size == 501 and x[0] == 0.0
    np.testing.assert_allclose(avar.phase_to_frequency(x, rate=4.0), y, rtol=1e-6)
    np.testing.assert_allclose(avar.frequency_to_phase(y, rate=4.0, remove_mean=True),
                               allantools.frequency2phase(y, 4.0), rtol=1e-12, atol=1e-24)
    np.testing.assert_allclose(avar.phase_to_frequency(x, 4.0), allantools.phase2frequency(x, 4.0), rtol=1e-15)
    with pytest.raises(ValueError, match="phase has 1 NaN"):
        avar.phase_to_frequency([0.0, np.nan, 1.0])
    with pytest.raises(ValueError, match="rate"):
        avar.frequency_to_phase([1.0, 2.0], rate=0.0)


@pytest.mark.parametrize("model", ["quadratic", "avg2diff", "3point"])
def test_phase_drift_models_recover_a_parabola(model):
    t = np.arange(1001) / 2.0
    x = 1e-6 + 3e-9 * t + 0.5 * 4e-12 * t**2
    res = avar.remove_drift(x, model, data_type="phase", rate=2.0)
    assert res.drift == pytest.approx(4e-12, rel=1e-7)
    assert res.coefficients["b"] == pytest.approx(3e-9, rel=1e-7)
    assert np.abs(res.residual).max() < 1e-12 * np.abs(x).max()
    noise = 1e-9 * np.random.default_rng(1).standard_normal(x.size)
    if model == "avg2diff":  # the mean second difference telescopes: it suits white FM, not white PM
        noise = 1e-12 * np.cumsum(noise)
    noisy = x + noise
    assert avar.remove_drift(noisy, model, data_type="phase", rate=2.0).drift == pytest.approx(4e-12, rel=0.05)


def test_three_point_goes_through_its_points_and_linear_has_no_curvature():
    x = np.random.default_rng(2).standard_normal(101)
    res = avar.remove_drift(x, "3point", data_type="phase")
    np.testing.assert_allclose(res.residual[[0, 50, 100]], 0.0, atol=1e-12)
    lin = avar.remove_drift(x, "linear", data_type="phase")
    assert lin.drift == 0.0 and abs(lin.residual.sum()) < 1e-9


@pytest.mark.parametrize("model", ["linear", "bisection"])
def test_frequency_linear_drift(model):
    t = np.arange(2000.0)
    y = 1e-12 + 5e-16 * t
    res = avar.remove_drift(y, model)
    assert res.drift == pytest.approx(5e-16, rel=1e-6)
    assert np.abs(res.residual).max() < 1e-20


def test_log_and_diffusion_models_recover_their_coefficients():
    t = np.arange(0, 3000.0, 3.0)  # rate 1/3 Hz
    rng = np.random.default_rng(4)
    y = 2e-10 * np.log1p(0.01 * t) + 1e-9 + 1e-13 * rng.standard_normal(t.size)
    res = avar.remove_drift(y, "log", rate=1 / 3)
    assert res.coefficients["a"] == pytest.approx(2e-10, rel=0.02)
    assert res.coefficients["b"] == pytest.approx(0.01, rel=0.05)
    assert res.residual.std() < 2e-13
    y = 1e-9 + 3e-11 * np.sqrt(t + 50.0) + 1e-14 * rng.standard_normal(t.size)
    res = avar.remove_drift(y, "diffusion", rate=1 / 3)
    assert res.coefficients["b"] == pytest.approx(3e-11, rel=0.05)
    assert res.coefficients["c"] == pytest.approx(50.0, rel=0.2)
    assert res.residual.std() < 2e-14


def test_drift_validation():
    with pytest.raises(ValueError, match="model must be one of .*'quadratic'"):
        avar.remove_drift([1.0, 2.0, 3.0], "log", data_type="phase")
    with pytest.raises(ValueError, match="data_type"):
        avar.remove_drift([1.0, 2.0, 3.0], "linear", data_type="time")


def test_filter_is_kasdin_walter():
    # the fractional-difference recursion equals the binomial series of (1 - z)**(alpha / 2)
    from scipy.special import binom

    for alpha in (-1.0, 1.0, -0.5):
        k = np.arange(8)
        np.testing.assert_allclose(filter_coefficients(alpha, 8), binom(alpha / 2, k) * (-1.0) ** k, rtol=1e-12)
    rw = avar.noise.power_law(-2, 1000, seed=3)
    assert np.allclose(np.diff(rw).std() ** 2, 1 / (2 * (2 * np.pi) ** -2), rtol=0.1)


def test_power_law_deviations_match_theory_within_their_bands():
    f = np.geomspace(1e-9, 0.5, 200001)
    taus = np.array([1.0, 2, 4, 8, 16, 32, 64, 128])
    inside = total = 0
    for alpha in (-2, -1, 0, 1, 2):
        theory = avar.psd_to_deviation(f, discrete_psd(f, alpha), taus, rate=1.0)
        edf = estimator_edf("oadev", np.full(taus.size, alpha), taus.astype(np.int64), 2049)
        for seed in range(20):
            y = avar.noise.power_law(alpha, 2048, seed=seed)
            res = avar.oadev(y, taus=taus)
            lci, uci = chi2_bounds(res.deviation, edf, 0.95)
            inside += int(np.sum((lci <= theory) & (theory <= uci)))
            total += taus.size
    assert inside / total >= 0.90


def test_power_law_options():
    x = avar.noise.power_law(0, 100, rate=10.0, data_type="phase", seed=1)
    y = avar.noise.power_law(0, 100, rate=10.0, seed=1)
    np.testing.assert_allclose(avar.phase_to_frequency(x, 10.0), y, rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(y, avar.noise.power_law(0, 100, rate=10.0, seed=1))
    with pytest.raises(ValueError, match="alpha must be in -4 .. 2"):
        avar.noise.power_law(3, 10)
    with pytest.raises(ValueError, match="h must be positive"):
        avar.noise.power_law(0, 10, h=0.0)


def test_psd_of_power_law_noise_marks_the_slope():
    for alpha in (-2, 0, 2):
        y = avar.noise.power_law(alpha, 2**15, h=1.0, seed=alpha + 10)
        res = avar.psd(y, rate=1.0)
        assert res.alpha == alpha
        band = (res.frequencies > 1e-3) & (res.frequencies < 0.1)
        ratio = np.median(res.psd[band] / discrete_psd(res.frequencies[band], alpha))
        assert ratio == pytest.approx(1.0, rel=0.15)
        assert set(res.slopes.columns) == {"f_low", "f_high", "slope", "alpha"}
    x = avar.noise.power_law(0, 2**14, seed=5, data_type="phase")
    assert avar.psd(x, data_type="phase", method="periodogram").alpha == 0


def test_psd_to_deviation_closed_forms():
    f = np.linspace(1e-7, 0.5, 400001)
    tau = np.array([4.0, 32.0])
    # random-walk FM, S_y = h f**-2: AVAR = (2 pi)**2 h tau / 6 (continuous form, f << 1 / tau0)
    fl = np.geomspace(1e-9, 50.0, 400001)
    got = avar.psd_to_deviation(fl, 1e-3 * fl**-2.0, tau)
    np.testing.assert_allclose(got, np.sqrt((2 * np.pi) ** 2 * 1e-3 * tau / 6), rtol=1e-3)
    # white PM of sampled data: x white of variance s2 gives AVAR = 3 s2 / tau**2 exactly
    s2 = 2.0
    s_y = discrete_psd(f, 2, h=2 * s2 * (2 * np.pi) ** 2)  # S_x = 2 s2 tau0, S_y = (2 sin(pi f))**2 S_x
    np.testing.assert_allclose(avar.psd_to_deviation(f, s_y, tau, rate=1.0), np.sqrt(3 * s2 / tau**2), rtol=1e-3)
    # MDEV of white FM: Mod sigma**2 = h0 / (4 tau) for m >> 1
    np.testing.assert_allclose(avar.psd_to_deviation(f, np.full(f.size, 2.0), [64.0], kind="mdev", rate=1.0),
                               np.sqrt(2.0 / (4 * 64.0)), rtol=0.02)
    with pytest.raises(ValueError, match="rate is needed"):
        avar.psd_to_deviation(f, f, [1.0], kind="mdev")
