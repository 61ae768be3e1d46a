"""Power-law noise identification on exactly simulated noise, and against allantools."""

from __future__ import annotations

import allantools
import numpy as np
import pytest
from allantools import ci as atci

from avar.stability.uncertainty.noise_id import b1_alpha, b1_theory, identify_noise, rn_boundary
from tests._support.powerlaw import powerlaw_phase

ALPHAS = [2, 1, 0, -1, -2]
N = 2**13


@pytest.fixture(scope="module")
def series():
    return {(alpha, seed): powerlaw_phase(N, alpha, seed) for alpha in ALPHAS for seed in range(10)}


@pytest.mark.parametrize("estimator", ["oadev", "mdev", "hdev", "totdev"])
@pytest.mark.parametrize("alpha", ALPHAS)
def test_identifies_simulated_power_laws(series, estimator, alpha):
    factors = np.array([1, 2, 4])
    found = np.array([identify_noise(series[alpha, seed], factors, estimator) for seed in range(10)])
    hits = (found == alpha).sum(axis=0)
    assert (hits >= 9).all(), (alpha, hits, found)


def test_powerlaw_helper_has_the_allan_slopes():
    # sanity of the simulator: ADEV slopes tau**mu, mu = -1, -1, -1/2, 0, 1/2 (flicker PM: ~ -1)
    slopes = {}
    for alpha in ALPHAS:
        x = powerlaw_phase(2**16, alpha, 0)
        _, dev, _, _ = allantools.oadev(x, taus=[16, 256], data_type="phase")
        slopes[alpha] = np.log(dev[1] / dev[0]) / np.log(16)
    assert slopes[2] == pytest.approx(-1, abs=0.05)
    assert slopes[1] == pytest.approx(-1, abs=0.15)
    assert slopes[0] == pytest.approx(-0.5, abs=0.1)
    assert slopes[-1] == pytest.approx(0, abs=0.15)
    assert slopes[-2] == pytest.approx(0.5, abs=0.15)


def plain_stable32_lag1(x, m, dmax, from_frequency=False):
    """Stable32's lag-1 rule as a loop: decimate (phase integrated from frequency data: remove
    the least-squares line, their mean), then with n points
    r1 = (sum of lag-1 products / n) / (sum of squares / (n - 1)) of the points less their mean."""
    z = np.asarray(x[::m], dtype=float)
    if from_frequency:
        t = np.arange(z.size)
        z = z - np.polyval(np.polyfit(t, z, 1), t)
    for d in range(dmax + 1):
        c = z - z.mean()
        r1 = sum(c[i] * c[i + 1] for i in range(c.size - 1)) / c.size / (sum(c * c) / (c.size - 1))
        rho = r1 / (1 + r1)
        if rho < 0.25 or d == dmax:
            return int(np.clip(2 - np.round(2 * rho) - 2 * d, -2, 2))
        z = np.diff(z)


@pytest.mark.parametrize("estimator, dmax", [("adev", 2), ("ohdev", 3)])
def test_lag1_is_the_plain_rule_and_mostly_allantools(series, estimator, dmax):
    # Stable32 removes the mean of phase data (a line from frequency data; allantools a quadratic)
    # and divides the variance by n - 1 (allantools by n): the same decisions but near a boundary
    factors = [1, 2, 4, 16, 64, 256]  # N / m >= 30: the lag-1 method in both
    compared = same_as_allantools = 0
    for (alpha, seed), x in series.items():
        if seed >= 4:
            continue
        ours = identify_noise(x, factors, estimator)
        plain = [plain_stable32_lag1(x, m, dmax) for m in factors]
        np.testing.assert_array_equal(ours, plain, err_msg=f"alpha={alpha} seed={seed}")
        integrated = identify_noise(x, factors, estimator, from_frequency=True)
        np.testing.assert_array_equal(integrated, [plain_stable32_lag1(x, m, dmax, True) for m in factors])
        theirs = np.clip([atci.autocorr_noise_id(x, m, data_type="phase", dmax=dmax)[0] for m in factors], -2, 2)
        same_as_allantools += int((ours == theirs).sum())
        compared += len(factors)
    assert compared == 120 and same_as_allantools >= 110, same_as_allantools


def reference_b1_alpha(x, m):
    """allantools' B1 ratio and boundaries; R(n) from its full ADEV and MDEV."""
    b1 = atci.b1(x, m, 1.0)
    k = (len(x) - 1) // m
    for b_hi, alpha in ((-3, -2), (-2, -1), (-1, 0)):
        if b1 > atci.b1_boundary(b_hi, k):
            return alpha
    return 1 if atci.rn(x, m, 1.0) > atci.rn_boundary(m, 0) else 2


def test_b1_fallback_agrees_with_allantools_b1_and_rn():
    agree = total = 0
    for alpha in ALPHAS:
        for seed in range(8):
            x = powerlaw_phase(2049, alpha, 100 + seed)
            for m in (128, 256, 512):  # 16, 8 and 4 averages: fewer than 30 points
                cumsum = np.concatenate(([0.0], np.cumsum(x)))
                agree += b1_alpha(x, cumsum, m) == reference_b1_alpha(x, m)
                total += 1
    # the B1 decisions are the same statistic; R(n) here samples MVAR at 64 offsets per cluster
    assert agree >= 0.95 * total, (agree, total)


def test_b1_fallback_identifies_clear_cases():
    hits = {alpha: 0 for alpha in (2, -2)}
    overlapping_rw = []
    for alpha in hits:
        for seed in range(10):
            x = powerlaw_phase(2**14, alpha, 200 + seed)
            hits[alpha] += identify_noise(x, [29 * 16], "oadev")[0] == alpha  # 35 averages: lag-1
            hits[alpha] += identify_noise(x, [680], "adev")[0] == alpha  # 24 averages: B1
            if alpha == -2:
                overlapping_rw.append(identify_noise(x, [680], "oadev")[0])
    assert hits[2] >= 16 and hits[-2] >= 16, hits
    # Stable32's B1 for the overlapping estimators compares B1 of the K = 24 averages (about
    # K / 2 for random-walk FM) with its values for n + 1 ~ N samples: random-walk FM
    # (B1 ~ N / 2) is out of reach and reads as flicker FM, as in its tables
    assert overlapping_rw.count(-1) >= 8, overlapping_rw


def test_b1_theory_and_rn_boundary_values():
    # Barnes: B1(N, mu) = N (1 - N**mu) / (2 (N - 1) (1 - 2**mu)), limits at mu = 0, -1
    for k in (3, 10, 100):
        assert b1_theory(k, 1) == pytest.approx(k * (1 - k) / (2 * (k - 1) * (1 - 2)))
        assert b1_theory(k, -2) == pytest.approx(k * (1 - k**-2.0) / (2 * (k - 1) * (1 - 2**-2.0)))
        assert b1_theory(k, 0) == pytest.approx(k * np.log(k) / (2 * (k - 1) * np.log(2)))
        assert b1_theory(k, -1) == 1.0
    for m in (2, 100, 5000):
        assert rn_boundary(m) == pytest.approx(atci.rn_boundary(m, 0), rel=1e-12)


def test_levels_without_enough_data_take_the_previous_level():
    x = powerlaw_phase(200, -2, 3)
    factors = np.array([1, 2, 80, 99])  # 80, 99: 2 averages, no B1
    alpha = identify_noise(x, factors, "adev")
    assert alpha[2] == alpha[3] == alpha[1]
    # shuffled factors give the same per-factor answers
    np.testing.assert_array_equal(identify_noise(x, factors[::-1], "adev"), alpha[::-1])
    # nothing identifiable (constant phase): white FM by convention
    np.testing.assert_array_equal(identify_noise(np.zeros(10), [1, 2, 4], "adev"), [0, 0, 0])


def test_result_is_clipped_and_integer():
    x = np.cumsum(np.cumsum(powerlaw_phase(4096, -2, 0)))  # steeper than random-walk FM
    alpha = identify_noise(x, [1, 2, 4], "hdev")
    assert alpha.dtype == np.int64 and (alpha == -2).all()
    rng = np.random.default_rng(0)
    blue = np.diff(rng.standard_normal(4097))  # bluer than white PM
    assert (identify_noise(blue, [1], "adev") == 2).all()


@pytest.mark.parametrize(
    "args, error, message",
    [
        ((np.ones((3, 3)), [1], "adev"), TypeError, "phase must be a 1-D array"),
        ((np.ones(3), [1], "adev"), ValueError, "at least 4 points"),
        ((np.r_[1.0, np.nan, 1, 1, 1], [1], "adev"), ValueError, "finite and gap-free; first bad value at index 1"),
        ((np.ones(10), [0], "adev"), ValueError, r"factors must be in 1 .. 9"),
        ((np.ones(10), [1.5], "adev"), TypeError, "factors must be a 1-D array of integer"),
        ((np.ones(10), [1], "avar"), ValueError, "estimator must be one of"),
    ],
)
def test_validation(args, error, message):
    with pytest.raises(error, match=message):
        identify_noise(*args)
