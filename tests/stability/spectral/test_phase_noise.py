"""Phase noise L(f), S_phi(f) from time error, and the power-law conversions, against theory."""

import numpy as np
import pytest

import avar

CARRIER = 10e6


def band(result, theory, mask=slice(None)):
    """Mean of the Welch estimate over bins, relative to theory: each bin has about 2 * segments
    degrees of freedom; the mean of K roughly independent bins is within a few 1 / sqrt(K segments)."""
    return float(np.mean(result[mask] / theory[mask]))


def test_white_pm_reads_its_theory_level():
    sigma, rate = 2e-12, 10.0
    x = np.random.default_rng(1).standard_normal(2**16) * sigma
    pn = avar.phase_noise(x, rate=rate, carrier=CARRIER)
    s_x = np.full(pn.frequencies.size, 2 * sigma**2 / rate)
    assert band(pn.S_x, s_x) == pytest.approx(1.0, abs=0.03)
    assert band(pn.S_phi, (2 * np.pi * CARRIER) ** 2 * s_x) == pytest.approx(1.0, abs=0.03)
    np.testing.assert_allclose(pn.L, 10 * np.log10(pn.S_phi / 2), rtol=1e-13)
    # the median of the log estimate sits near its theory (chi-squared of ~16 dof: within 1 dB)
    assert np.median(pn.L) == pytest.approx(10 * np.log10((2 * np.pi * CARRIER) ** 2 * s_x[0] / 2), abs=1.0)


def test_white_fm_from_frequency_data_and_its_allan_deviation():
    sigma, rate = 1e-11, 1.0
    y = np.random.default_rng(2).standard_normal(2**16) * sigma
    pn = avar.phase_noise(y, rate=rate, carrier=CARRIER, data_type="freq")
    h0 = 2 * sigma**2 / rate
    assert band(pn.S_y, np.full(pn.frequencies.size, h0)) == pytest.approx(1.0, abs=0.03)
    # S_phi of white FM falls as f**-2: (nu0 / f)**2 h0 at f << rate
    low = pn.frequencies < 0.05
    assert band(pn.S_phi, CARRIER**2 * h0 / pn.frequencies**2, low) == pytest.approx(1.0, abs=0.06)
    taus = [1.0, 10.0, 100.0]
    expected = avar.power_law_adev(h0, 0, taus)
    np.testing.assert_allclose(expected, [1e-11, 1e-11 / np.sqrt(10), 1e-12], rtol=1e-14)
    np.testing.assert_allclose(pn.deviation(taus), expected, rtol=0.05)
    np.testing.assert_allclose(avar.oadev(y, taus=taus).deviation, expected, rtol=0.08)


def test_white_pm_allan_deviation_from_the_spectrum_and_the_formula():
    sigma = 1e-12
    x = np.random.default_rng(3).standard_normal(2**16) * sigma
    pn = avar.phase_noise(x, rate=1.0, carrier=CARRIER)
    taus = [1.0, 10.0, 100.0]
    h2 = (2 * np.pi) ** 2 * 2 * sigma**2  # S_y = (2 pi f)**2 S_x = h2 f**2
    formula = avar.power_law_adev(h2, 2, taus, f_high=0.5)
    np.testing.assert_allclose(formula, np.sqrt(3) * sigma / np.array(taus), rtol=1e-12)  # NIST SP 1065 Table 3
    np.testing.assert_allclose(pn.deviation(taus), formula, rtol=0.03)
    np.testing.assert_allclose(avar.oadev(x, data_type="phase", taus=taus).deviation, formula, rtol=0.03)


def test_flicker_fm_and_random_walk_fm_formulas_against_simulation():
    rng_seeds = range(4)
    n = 2**15
    for alpha, tau, h in ((-1, 16.0, 1.0), (-2, 16.0, 1.0)):
        ratios = []
        for seed in rng_seeds:
            y = avar.noise.power_law(alpha, n, h=h, seed=seed)
            ratios.append(avar.oadev(y, taus=[tau]).deviation[0] / avar.power_law_adev(h, alpha, [tau])[0])
        assert np.mean(ratios) == pytest.approx(1.0, abs=0.15), (alpha, ratios)


def test_conversions():
    np.testing.assert_allclose(avar.ssb_to_phase_psd([-120.0, -90.0]), [2e-12, 2e-9], rtol=1e-14)
    np.testing.assert_allclose(avar.phase_psd_to_ssb(avar.ssb_to_phase_psd([-133.5])), [-133.5], rtol=1e-14)
    np.testing.assert_allclose(avar.phase_psd_to_frequency_psd([1.0, 100.0], [1e-10, 1e-10], carrier=5e6),
                               [1e-10 / 25e12, 1e-10 * 1e4 / 25e12], rtol=1e-14)


def test_errors_name_the_argument():
    x = np.zeros(100)
    with pytest.raises(ValueError, match="carrier"):
        avar.phase_noise(x, carrier=0.0)
    with pytest.raises(ValueError, match="data_type"):
        avar.phase_noise(x, data_type="time")
    with pytest.raises(ValueError, match="segments"):
        avar.phase_noise(x, segments=0)
    with pytest.raises(ValueError, match="too few"):
        avar.phase_noise(np.zeros(20), segments=8)
    with pytest.raises(ValueError, match="f_high"):
        avar.power_law_adev(1.0, 2, [1.0])
    with pytest.raises(ValueError, match="alpha"):
        avar.power_law_adev(1.0, 3, [1.0])
