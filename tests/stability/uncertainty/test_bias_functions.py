"""Barnes' dead-time bias functions B2 and B3: closed forms, a plain sum of covariances, and simulated dead-time data."""

from __future__ import annotations

import math

import numpy as np
import pytest

import avar


def structure(t: float, mu: float) -> float:
    t = abs(t)
    if mu == -2:
        return 0.0 if t == 0 else 1.0
    if mu == 0:
        return 0.0 if t == 0 else t * t * math.log(t)
    return t ** (mu + 2)


def two_sample_variance(n: int, period: float, length: float, mu: float) -> float:
    """sigma^2(2, n, T, tau) up to the noise's constant, by a plain double loop over the phase points:
    E[(sum a_k x(s_k))^2] = -1/2 sum_k sum_l a_k a_l D(s_k - s_l) for weights summing to zero."""
    points, weights = [], []
    for group, sign in ((0, -1.0), (1, 1.0)):
        for i in range(n):
            start = (group * n + i) * period
            points += [start + length, start]
            weights += [sign / (n * length), -sign / (n * length)]
    total = 0.0
    for sk, ak in zip(points, weights):
        for sl, al in zip(points, weights):
            total += ak * al * structure(sk - sl, mu)
    return -0.25 * total


ALPHAS = {2: -2.0, 0: -1.0, -1: 0.0, -2: 1.0, -0.5: -0.5, -2.5: 1.5}


@pytest.mark.parametrize("r", [0.5, 1.0, 1.5, 2.0, 3.0, 10.0])
def test_b2_closed_forms(r):
    assert avar.bias_b2(2, r) == pytest.approx(1.0 if r == 1 else 2 / 3, rel=1e-12)   # white PM
    assert avar.bias_b2(1, r) == avar.bias_b2(2, r)                                    # flicker PM: mu = -2
    assert avar.bias_b2(0, r) == pytest.approx(1.0 if r >= 1 else r, rel=1e-12)       # white FM
    if r >= 1:  # random-walk FM
        assert avar.bias_b2(-2, r) == pytest.approx((3 * r - 1) / 2, rel=1e-12)
    if r > 1:  # flicker FM: [2 r^2 ln r - (r+1)^2 ln(r+1) - (r-1)^2 ln(r-1)] / (-4 ln 2)
        expected = (2 * r * r * math.log(r) - (r + 1) ** 2 * math.log(r + 1) - (r - 1) ** 2 * math.log(r - 1)) \
            / (-4 * math.log(2))
        assert avar.bias_b2(-1, r) == pytest.approx(expected, rel=1e-12)
    for alpha in ALPHAS:
        assert avar.bias_b2(alpha, 1.0) == pytest.approx(1.0, rel=1e-12)   # no dead time: no bias


def test_b2_random_walk_fm_values():
    # Barnes (1969): B2(r, mu = 1) = (3 r - 1) / 2 for r >= 1
    assert [avar.bias_b2(-2, r) for r in (1.0, 2.0, 5.0, 11.0)] == pytest.approx([1.0, 2.5, 7.0, 16.0], rel=1e-12)


@pytest.mark.parametrize("alpha", list(ALPHAS))
@pytest.mark.parametrize("n", [1, 2, 3, 7])
@pytest.mark.parametrize("r", [0.5, 1.0, 1.5, 4.0])
def test_b2_and_b3_equal_the_plain_sum_of_covariances(alpha, n, r):
    mu = ALPHAS[alpha]
    b2 = two_sample_variance(1, r, 1.0, mu) / two_sample_variance(1, 1.0, 1.0, mu)
    assert avar.bias_b2(alpha, r) == pytest.approx(b2, rel=1e-9)
    b3 = two_sample_variance(n, r, 1.0, mu) / two_sample_variance(1, n * r, float(n), mu)
    assert avar.bias_b3(alpha, n, r) == pytest.approx(b3, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("alpha", list(ALPHAS))
def test_b3_is_one_without_averaging_or_dead_time(alpha):
    assert avar.bias_b3(alpha, 1, 3.0) == pytest.approx(1.0, rel=1e-12)
    assert avar.bias_b3(alpha, 6, 1.0) == pytest.approx(1.0, rel=1e-12)
    assert avar.bias_b3(0, 6, 2.5) == pytest.approx(1.0, rel=1e-12)   # white FM: independent measurements
    assert avar.bias_b3(2, 6, 2.5) == pytest.approx(6.0, rel=1e-12)   # white PM: n separate pairs of points


def simulate_rw_fm(times: np.ndarray, q2: float, rng) -> np.ndarray:
    """Phase x(t) of random-walk FM (dy = sqrt(q2) dW, dx = y dt) at ``times``, exactly (the two-state model)."""
    x, y = np.zeros(times.size), 0.0
    steps = np.diff(times)
    for i, h in enumerate(steps):
        cov = q2 * np.array([[h**3 / 3, h**2 / 2], [h**2 / 2, h]])
        dx, dy = np.linalg.cholesky(cov) @ rng.standard_normal(2)
        x[i + 1] = x[i] + y * h + dx
        y += dy
    return x


def test_dead_time_correction_recovers_simulated_random_walk_fm():
    rng = np.random.default_rng(20261128)
    q2, tau0, r, count = 1.0, 1.0, 3.0, 40_000
    starts = np.arange(count) * r * tau0
    times = np.sort(np.concatenate([starts, starts + tau0]))
    x = simulate_rw_fm(times, q2, rng)
    y = (x[1::2] - x[0::2]) / tau0                     # one measurement of tau0 every T0 = 3 tau0
    for n in (1, 4):
        averages = y[: y.size // n * n].reshape(-1, n).mean(axis=1)
        measured = math.sqrt(0.5 * np.mean(np.diff(averages) ** 2))
        expected = math.sqrt(avar.bias_b2(-2, r) * avar.bias_b3(-2, n, r) * q2 * n * tau0 / 3)  # AVAR = q2 tau / 3
        assert measured == pytest.approx(expected, rel=0.04)
        truth = math.sqrt(q2 * n * tau0 / 3)
        assert avar.dead_time_correction(measured, alpha=-2, r=r, n=n) == pytest.approx(truth, rel=0.04)
        assert abs(measured / truth - 1) > 0.3   # the bias is real: uncorrected, the deviation is far off


def test_dead_time_correction_of_simulated_white_pm():
    rng = np.random.default_rng(7)
    x = rng.standard_normal(600_000)                   # white PM, sigma_x = 1, at unit steps
    tau0, period = 2, 5                                 # r = 2.5
    starts = np.arange(0, x.size - tau0, period)
    y = (x[starts + tau0] - x[starts]) / tau0
    measured = math.sqrt(0.5 * np.mean(np.diff(y) ** 2))
    truth = math.sqrt(3.0) / tau0                       # AVAR of white PM at tau = tau0 samples: 3 sigma^2 / tau^2
    assert measured / truth == pytest.approx(math.sqrt(2 / 3), rel=0.01)
    assert avar.dead_time_correction(measured, alpha=2, r=2.5) == pytest.approx(truth, rel=0.01)
    np.testing.assert_allclose(avar.dead_time_correction(np.array([measured, 2 * measured]), 2, 2.5),
                               [truth, 2 * truth], rtol=0.01)


def test_arguments_are_checked():
    with pytest.raises(ValueError, match="r must be"):
        avar.bias_b2(0, 0.0)
    with pytest.raises(ValueError, match="alpha must be"):
        avar.bias_b2(3, 2.0)
    with pytest.raises(ValueError, match="n must be"):
        avar.bias_b3(0, 0, 2.0)
    with pytest.raises(TypeError, match="alpha must be"):
        avar.bias_b2("white", 2.0)
