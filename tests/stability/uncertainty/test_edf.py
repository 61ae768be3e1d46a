"""EDF and chi-squared bounds against allantools, Stable32 output and exact white-noise values."""

from __future__ import annotations

import contextlib
import io
from math import comb

import allantools
import numpy as np
import pytest
from scipy.stats import chi2

from avar.stability.uncertainty.edf import ESTIMATORS, chi2_bounds, estimator_edf, greenhall_edf, totdev_edf

FACTORS = [1, 2, 3, 5, 8, 16, 33, 34, 50, 64, 100, 128, 300, 1000, 4096, 20000]
LENGTHS = [10, 33, 100, 1001, 4097, 100_000]


def allantools_edf(alpha, d, m, n, overlapping, modified):
    """allantools.edf_greenhall, or None where it has no answer (white PM with K <= d, d = 3 alpha = -4)."""
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            return allantools.edf_greenhall(alpha, d, m, n, overlapping=overlapping, modified=modified)
    except (NotImplementedError, AssertionError):
        return None


@pytest.mark.parametrize("estimator", sorted(ESTIMATORS))
def test_estimator_edf_matches_allantools(estimator):
    d, overlapping, modified = ESTIMATORS[estimator]
    compared = 0
    for n in LENGTHS:
        factors = np.array([m for m in FACTORS if (m * (d + 1) if modified else m * d + 1) <= n])
        for alpha in range(-2, 3):
            ours = estimator_edf(estimator, np.full(factors.size, alpha), factors, n)
            for m, value in zip(factors.tolist(), ours):
                reference = allantools_edf(alpha, d, m, n, overlapping, modified)
                if reference is not None:
                    assert value == pytest.approx(reference, rel=1e-6), (n, m, alpha)
                    compared += 1
    assert compared > 150


@pytest.mark.parametrize("alpha", [-4, -3])
def test_hadamard_steep_noises_match_allantools(alpha):
    for overlapping in (False, True):
        for m in (1, 5, 33, 100):
            reference = allantools_edf(alpha, 3, m, 4097, overlapping, False)
            if reference is not None:
                assert greenhall_edf(alpha, 3, m, 4097, overlapping, False) == pytest.approx(reference, rel=1e-6)


def test_totdev_edf_is_howes_and_stable32s():
    n = 1001
    factors = np.array([1, 2, 4, 16, 100, 333, 499])
    for alpha in range(-2, 3):
        ours = totdev_edf(n, factors, alpha)
        with contextlib.redirect_stdout(io.StringIO()):
            reference = np.array([allantools.edf_totdev(n, int(m), alpha) for m in factors], dtype=float)
        usable = np.isfinite(reference) & (reference >= 1) & (ours > 1)
        if alpha == 0:  # the same b = 1.5
            np.testing.assert_allclose(ours[usable], reference[usable], rtol=1e-14)
        elif alpha < 0:  # allantools takes NIST SP 1065 Table 7's two decimals: within 0.6 %
            np.testing.assert_allclose(ours[usable], reference[usable], rtol=6e-3)
            assert not np.allclose(ours[usable], reference[usable], rtol=1e-3)
        else:  # Table 5 there, plus 2 as Stable32
            np.testing.assert_allclose(ours[usable], reference[usable] + 2, rtol=1e-12)
        assert (ours >= 1).all()
    # Stable32's coefficients by hand: flicker FM b = 1.168, c = 0.22; random-walk FM b = 0.927, c = 0.358
    assert totdev_edf(1001, 10, -1) == pytest.approx(1.168 * 100.1 - 0.22, rel=1e-14)
    assert totdev_edf(1001, 10, -2) == pytest.approx(0.927 * 100.1 - 0.358, rel=1e-14)


# Stable32 1.60, TOTDEV of the 1253-point clock record (allantoolkit's tests/assets/Sr87/phase/decade/totdev.txt)
# and of a GPS receiver's 241,218 phase points (allantools' tests/gps/stable32_TOTDEV_octave.txt), one
# sigma: (m, alpha, min sigma, sigma, max sigma), the sigma bias-removed as Stable32 prints it.
STABLE32_TOTDEV = {
    1253: [(1, -1, 8.8689e-17, 9.0304e-17, 9.2011e-17), (2, -2, 8.6445e-17, 8.8930e-17, 9.1644e-17),
           (4, -1, 1.0156e-16, 1.0523e-16, 1.0932e-16), (10, 0, 9.2942e-17, 9.7582e-17, 1.0300e-16),
           (20, 0, 7.9975e-17, 8.5590e-17, 9.2581e-17), (40, 0, 5.9788e-17, 6.5627e-17, 7.3597e-17),
           (100, 1, 4.2698e-17, 4.5724e-17, 4.9499e-17), (200, -1, 2.0582e-17, 2.5261e-17, 3.5911e-17),
           (400, -1, 1.5759e-17, 2.0492e-17, 3.6551e-17)],
    241218: [(4096, 1, 3.5895e-12, 3.6305e-12, 3.6730e-12), (8192, 0, 1.7566e-12, 1.9332e-12, 2.1767e-12),
             (16384, 0, 1.0191e-12, 1.1604e-12, 1.3834e-12), (32768, 1, 7.2339e-13, 7.5714e-13, 7.9613e-13),
             (65536, 1, 3.7976e-13, 4.1817e-13, 4.7121e-13)],
}


@pytest.mark.parametrize("n_phase", sorted(STABLE32_TOTDEV))
def test_totdev_bounds_match_stable32_at_every_noise(n_phase):
    rows = np.array(STABLE32_TOTDEV[n_phase])
    factors, alpha = rows[:, 0].astype(int), rows[:, 1].astype(int)
    edf = totdev_edf(n_phase, factors, alpha)
    lci, uci = chi2_bounds(rows[:, 3], edf, quantiles="stable32")  # one sigma
    np.testing.assert_allclose(lci, rows[:, 2], rtol=1e-4)  # 5 printed digits
    np.testing.assert_allclose(uci, rows[:, 4], rtol=1e-4)
    # Table 7's two decimals, or Table 5 without the 2, miss rows by 3e-4 to 4e-3
    with contextlib.redirect_stdout(io.StringIO()):
        theirs = np.array([allantools.edf_totdev(n_phase, int(m), int(a)) for m, a in zip(factors, alpha)])
    assert np.max(np.abs(chi2_bounds(rows[:, 3], theirs, quantiles="stable32")[1] / rows[:, 4] - 1)) > 3e-4


def white_pm_exact_edf(n, m, d, overlapping):
    """(tr A)**2 / tr(A A) of the quadratic form of the unmodified estimator: exact for white phase."""
    step = 1 if overlapping else m
    starts = np.arange(0, n - d * m, step)
    weights = np.array([(-1) ** k * comb(d, k) for k in range(d + 1)], dtype=float)
    rows = np.zeros((starts.size, n))
    for k, w in enumerate(weights):
        rows[np.arange(starts.size), starts + k * m] = w
    a = rows.T @ rows
    return np.trace(a) ** 2 / np.sum(a * a)


@pytest.mark.parametrize("d", [2, 3])
@pytest.mark.parametrize("overlapping", [False, True])
def test_white_pm_is_exact_including_few_terms(d, overlapping):
    # Includes K = ceil(M / S) <= d, where allantools raises NotImplementedError.
    for n, m in [(10, 3), (13, 4), (20, 2), (40, 6), (64, 5), (64, 21), (33, 16)]:
        if m * d + 1 > n:
            continue
        expected = white_pm_exact_edf(n, m, d, overlapping)
        assert greenhall_edf(2, d, m, n, overlapping, False) == pytest.approx(expected, rel=1e-12), (n, m)


def test_white_fm_unoverlapped_is_exact():
    # m > 33: F = infinity, independent frequency averages; the M differences of order d
    # are correlated only between neighbours.
    n = 1001
    for m in (34, 50, 100, 250):
        terms = (n - 1) // m - 1
        assert greenhall_edf(0, 2, m, n, False, False) == pytest.approx(2 * terms**2 / (3 * terms - 1), rel=1e-12)
        terms -= 1
        correlation = terms + 2 * (terms - 1) * (4 / 6) ** 2 + 2 * (terms - 2) * (1 / 6) ** 2
        assert greenhall_edf(0, 3, m, n, False, False) == pytest.approx(terms**2 / correlation, rel=1e-12)


# Stable32 1.60 on its PHASE.DAT (N = 1001 phase points), alpha = 0, confidence printed 0.683
# (one sigma, 0.682689..., is what it computes with: tests/stability/test_chi2.py):
# (m, min sigma, sigma, max sigma), as published with allantools' tests.
STABLE32 = {
    "adev": [(1, 2.8515e-01, 2.9223e-01, 2.9987e-01), (8, 1.0254e-01, 1.1013e-01, 1.1971e-01),
             (64, 2.7109e-02, 3.2550e-02, 4.3537e-02), (128, 2.6481e-02, 3.3855e-02, 5.5744e-02)],
    "oadev": [(2, 1.9520e-01, 2.0102e-01, 2.0738e-01), (16, 5.7696e-02, 6.1915e-02, 6.7217e-02),
              (128, 2.3045e-02, 2.7674e-02, 3.7027e-02)],
    "mdev": [(2, 1.5336e-01, 1.5821e-01, 1.6355e-01), (32, 3.0466e-02, 3.4255e-02, 3.9933e-02),
             (128, 1.4874e-02, 1.8669e-02, 2.8584e-02)],
    "tdev": [(4, 2.3838e-01, 2.4895e-01, 2.6106e-01), (128, 1.0992e+00, 1.3797e+00, 2.1124e+00)],
    "hdev": [(2, 1.9887e-01, 2.0716e-01, 2.1659e-01), (32, 4.6987e-02, 5.4697e-02, 6.8092e-02),
             (128, 2.8841e-02, 3.8060e-02, 7.3807e-02)],
    "ohdev": [(1, 2.8635e-01, 2.9439e-01, 3.0315e-01), (16, 5.6173e-02, 6.0638e-02, 6.6369e-02),
              (128, 2.3761e-02, 2.9147e-02, 4.1367e-02)],
    "totdev": [(1, 2.8707e-01, 2.9223e-01, 2.9768e-01), (32, 4.4255e-02, 4.8580e-02, 5.4484e-02),
               (256, 1.0734e-02, 1.3369e-02, 1.9924e-02)],
}


@pytest.mark.parametrize("estimator", sorted(STABLE32))
def test_bounds_match_stable32(estimator):
    rows = np.array(STABLE32[estimator])
    factors, low, sigma, high = rows[:, 0].astype(int), rows[:, 1], rows[:, 2], rows[:, 3]
    edf = estimator_edf(estimator, np.zeros(factors.size, dtype=int), factors, 1001)
    lci, uci = chi2_bounds(sigma, edf, quantiles="stable32")  # one sigma
    # Stable32 prints 5 significant digits and its own chi-squared quantiles: agreement to
    # 1.6e-4 (HDEV's upper bound at 4 EDF; allantools checks the same table to 1e-3)
    np.testing.assert_allclose(lci, low, rtol=1.7e-4)
    np.testing.assert_allclose(uci, high, rtol=1.7e-4)
    # an EDF off by 20% would not pass
    assert not np.allclose(chi2_bounds(sigma, 0.8 * edf)[0], low, rtol=1e-3)


def test_chi2_bounds_match_allantools():
    for edf in (1.0, 1.7, 4.2, 30.0, 999.0, 1e6):
        for confidence in (0.5, 0.683, allantools.ci.ONE_SIGMA_CI, 0.9, 0.95, 0.999):
            lci, uci = chi2_bounds(0.37, edf, confidence)
            low, high = allantools.confidence_interval(0.37, edf, confidence)
            assert lci == pytest.approx(low, rel=1e-9) and uci == pytest.approx(high, rel=1e-9)
            assert 0 < lci <= 0.37 <= uci


def test_chi2_bounds_vectorized_and_extreme_confidence():
    deviation = np.array([0.0, 1.0, 2.0])
    lci, uci = chi2_bounds(deviation, np.array([3.0, 3.0, 3.0]))
    assert lci[0] == uci[0] == 0.0 and lci[2] == pytest.approx(2 * lci[1], rel=1e-15)
    # 1 - 1e-13: ppf(1 - q) would lose the tail; the bounds still hold their probability
    confidence = 1 - 1e-13
    tail = (1 - confidence) / 2  # exact (Sterbenz): 5.0016e-14, the float nearest 1 - 1e-13 is not 1 - 1e-13
    lci, uci = chi2_bounds(1.0, 10.0, confidence=confidence)
    assert chi2.sf(10.0 / lci**2, 10.0) == pytest.approx(tail, rel=1e-9)
    assert chi2.cdf(10.0 / uci**2, 10.0) == pytest.approx(tail, rel=1e-9)
    assert 0 < lci < 1 < uci < np.inf
    assert np.isnan(chi2_bounds(1.0, np.nan)[0])


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda: estimator_edf("avar", [0], [1], 100), ValueError, "estimator must be one of"),
        (lambda: estimator_edf("adev", [3], [1], 100), ValueError, "alpha must"),
        (lambda: estimator_edf("adev", [0.5], [1], 100), TypeError, "alpha must be an integer"),
        (lambda: estimator_edf("adev", [0], [0], 100), ValueError, "averaging factors >= 1"),
        (lambda: estimator_edf("adev", [0], [50], 100), ValueError, "too large for n_phase = 100"),
        (lambda: estimator_edf("adev", [0, 0], [1, 2, 3], 100), ValueError, "must broadcast"),
        (lambda: greenhall_edf(-1, 1, 2, 100, False, False), ValueError, r"alpha \+ 2 d > 1"),
        (lambda: greenhall_edf(0, 4, 2, 100, False, False), ValueError, "d must be 1, 2 or 3"),
        (lambda: greenhall_edf(0, 2, 2, 100, 1, False), TypeError, "overlapping must be True or False"),
        (lambda: totdev_edf(100, 101, 0), ValueError, "m must be <= n_phase"),
        (lambda: totdev_edf(1.5, 1, 0), ValueError, "n_phase must be an integer"),
        (lambda: chi2_bounds(1.0, 0.0), ValueError, "edf must be positive"),
        (lambda: chi2_bounds(-1.0, 3.0), ValueError, "deviation must be finite and >= 0"),
        (lambda: chi2_bounds(1.0, 3.0, confidence=1.0), ValueError, "confidence must be a number in"),
        (lambda: chi2_bounds("a", 3.0), TypeError, "deviation must be a real"),
    ],
)
def test_validation_names_the_argument(call, error, message):
    with pytest.raises(error, match=message):
        call()


# Stable32 on a Keysight 53230A time-interval record (N = 55,688 phase points; white and flicker PM,
# white FM at TOTDEV's longest taus), kept in allantools' tests: (m, alpha, min sigma, sigma,
# max sigma). The bounds need only N, m, alpha and the printed sigma; N this large takes
# Greenhall's algorithm through its long-sum branches.
STABLE32_LONG = {
    "oadev": [(1, 2, 1.7629e-11, 1.7702e-11, 1.7776e-11), (64, 2, 2.7844e-13, 2.7960e-13, 2.8077e-13), (1024, 2, 1.7589e-14, 1.7663e-14, 1.7738e-14), (2048, 1, 8.5857e-15, 8.8933e-15, 9.2367e-15), (8192, 1, 2.1277e-15, 2.2694e-15, 2.4439e-15)],
    "mdev": [(1, 2, 1.7629e-11, 1.7702e-11, 1.7776e-11), (64, 2, 3.9878e-14, 4.0708e-14, 4.1593e-14), (1024, 2, 1.3270e-15, 1.4367e-15, 1.5789e-15), (2048, 1, 8.3873e-16, 9.4879e-16, 1.1179e-15), (8192, 1, 2.7966e-16, 3.5547e-16, 5.7122e-16)],
    "tdev": [(1, 2, 1.0178e-11, 1.0220e-11, 1.0263e-11), (64, 2, 1.4735e-12, 1.5042e-12, 1.5369e-12), (1024, 2, 7.8454e-13, 8.4936e-13, 9.3347e-13), (2048, 1, 9.9173e-13, 1.1219e-12, 1.3218e-12), (8192, 1, 1.3227e-12, 1.6812e-12, 2.7017e-12)],
    "hdev": [(1, 2, 1.8570e-11, 1.8654e-11, 1.8739e-11), (64, 2, 2.8073e-13, 2.9072e-13, 3.0187e-13), (1024, 2, 1.5635e-14, 1.7772e-14, 2.1119e-14), (2048, 1, 8.7188e-15, 1.0348e-14, 1.3452e-14), (8192, 1, 9.4771e-16, 1.2817e-15, 2.9912e-15)],
    "ohdev": [(1, 2, 1.8570e-11, 1.8654e-11, 1.8739e-11), (64, 2, 2.9326e-13, 2.9459e-13, 2.9593e-13), (1024, 2, 1.8542e-14, 1.8627e-14, 1.8714e-14), (2048, 1, 9.0364e-15, 9.3893e-15, 9.7873e-15), (8192, 1, 2.1814e-15, 2.3474e-15, 2.5583e-15)],
    "totdev": [(1, 2, 1.7628e-11, 1.7702e-11, 1.7777e-11), (64, 2, 2.7862e-13, 2.7980e-13, 2.8098e-13), (1024, 2, 1.7644e-14, 1.7719e-14, 1.7795e-14), (2048, 1, 8.7523e-15, 8.9523e-15, 9.1668e-15), (8192, 0, 1.9371e-15, 2.3153e-15, 3.0614e-15), (16384, 0, 1.0189e-15, 1.2833e-15, 1.9897e-15)],
}


@pytest.mark.parametrize("estimator", sorted(STABLE32_LONG))
def test_bounds_of_a_long_record_match_stable32(estimator):
    rows = np.array(STABLE32_LONG[estimator])
    factors, alpha = rows[:, 0].astype(int), rows[:, 1].astype(int)
    edf = estimator_edf(estimator, alpha, factors, 55688)
    lci, uci = chi2_bounds(rows[:, 3], edf, quantiles="stable32")  # one sigma
    # 5 printed digits on intervals down to +-0.4 %: agreement to 1.8e-4 (HDEV at m = 8192, 4 terms)
    np.testing.assert_allclose(lci, rows[:, 2], rtol=2e-4)
    np.testing.assert_allclose(uci, rows[:, 4], rtol=2e-4)
    assert not np.allclose(chi2_bounds(rows[:, 3], 0.9 * edf)[1], rows[:, 4], rtol=2e-4, atol=0)
