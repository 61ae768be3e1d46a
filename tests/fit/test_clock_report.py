"""The clock report: h_alpha and Kalman q of simulated clocks with known truth."""

import math

import numpy as np
import pytest

import avar
from avar.fit.clock.coefficients import h_coefficient, kalman_q


def test_the_conversions_match_the_allan_variances_they_stand_for():
    """Each process's h, put into NIST SP 1065 Table 3's Allan variance, gives the process's own
    theoretical Allan variance at long taus (per-sample parameters at 10 Hz)."""
    rate = 10.0
    m = np.array([64.0, 256.0, 1024.0])
    tau = m / rate
    cases = [("WN", avar.WN(sigma2=3.0), 0), ("RW", avar.RW(gamma2=2e-4), -2), ("FN", avar.FN(b2=0.5), -1)]
    for name, process, alpha in cases:
        (value,) = process.parameters.values()
        got_alpha, h = h_coefficient(name, value, rate)
        assert got_alpha == alpha
        np.testing.assert_allclose(avar.power_law_adev(h, alpha, tau) ** 2, process.theoretical_av(m), rtol=2e-3)
    # white PM: QN's AV 3 q2 / m**2 against Table 3 with f_h = rate / 2
    _, h2 = h_coefficient("QN", 0.7, rate)
    np.testing.assert_allclose(avar.power_law_adev(h2, 2, tau, f_high=rate / 2) ** 2,
                               avar.QN(q2=0.7).theoretical_av(m), rtol=1e-12)
    q1, q2 = kalman_q(2e-22, 1e-30)
    assert q1 == 1e-22 and q2 == pytest.approx(2 * math.pi**2 * 1e-30, rel=1e-15)


@pytest.mark.parametrize("seed", [1, 2])
def test_white_fm_and_random_walk_fm_are_recovered(seed):
    """White FM (h_0 = 2e-22) plus random-walk FM (h_-2 = 1e-28 / (2 pi**2)) at 1 Hz, 1e5 values."""
    y = (avar.WN(sigma2=1e-22) + avar.RW(gamma2=1e-28)).simulate(100_000, seed=seed)
    report = avar.clock_report(y, rate=1.0, data_type="freq", B=30, seed=seed)
    rows = report.coefficients.set_index("alpha")
    assert rows.loc[0, "h"] == pytest.approx(2e-22, rel=0.1)
    assert rows.loc[-2, "h"] == pytest.approx(1e-28 / (2 * math.pi**2), rel=0.5)
    assert rows.loc[0, "Lower"] < rows.loc[0, "h"] < rows.loc[0, "Upper"]
    assert report.q["q1"] == pytest.approx(rows.loc[0, "h"] / 2, rel=1e-12)
    assert report.q["q2"] == pytest.approx(2 * math.pi**2 * rows.loc[-2, "h"], rel=1e-12)
    assert report.in_band >= 0.8
    assert "white FM" in str(report) and "q2 =" in str(report)


def test_phase_data_give_the_frequency_datas_report():
    y = (avar.WN(sigma2=1e-22) + avar.RW(gamma2=1e-28)).simulate(20_000, seed=3)
    x = np.concatenate(([0.0], np.cumsum(y))) / 10.0  # time error at 10 Hz
    a = avar.clock_report(y, rate=10.0, data_type="freq", B=10, seed=0)
    b = avar.clock_report(x, rate=10.0, data_type="phase", B=10, seed=0)
    np.testing.assert_allclose(b.coefficients["h"], a.coefficients["h"], rtol=1e-6)


def test_errors_name_the_argument():
    y = np.random.default_rng(0).standard_normal(1000)
    with pytest.raises(ValueError, match="data_type"):
        avar.clock_report(y, data_type="time")
    with pytest.raises(ValueError, match="B must"):
        avar.clock_report(y, B=5)
    with pytest.raises(ValueError, match="processes"):
        avar.clock_report(y, processes=["AR1"])
    with pytest.raises(ValueError, match="confidence"):
        avar.clock_report(y, confidence=95)
