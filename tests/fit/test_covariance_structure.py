"""The covariance of the Allan variance estimates of a fitted sensor model, against brute force.

The reference is the quadratic-form identity written out with dense matrices:
nu_hat(m) = d' Q_m d / M with d the first differences of the series and Q_m
the Allan filter's Gram matrix, so for Gaussian d of covariance G and mean mu
Cov(nu_hat_j, nu_hat_k) = [2 tr(Q_j G Q_k G) + 4 mu' Q_j G Q_k mu] / (M_j M_k).
The increments' autocovariance of every term is written here from its
definition, independently of the package.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import toeplitz

from avar.fit.covariance.exact import exact_covariance
from avar.fit.covariance.structure import MAX_EXACT_LEVELS, _phi, _second_sums, structure_covariance, structure_function
from avar.fit.terms import Component, basis
from avar.models import AR1, RW, WN


def increment_autocovariance(component: Component, lags: int) -> np.ndarray:
    """gamma_d(0..lags) of the first differences of one term (per-sample parameters)."""
    h = np.arange(lags + 2, dtype=np.float64)
    c = component.scale
    out = np.zeros(lags + 1)
    if component.kind == "WN":  # d_t = e_t - e_{t-1}
        out[:2] = [2 * c, -c]
    elif component.kind == "QN":  # d_t = sqrt(q2) (e_t - 2 e_{t-1} + e_{t-2})
        out[:3] = [6 * c, -4 * c, c]
    elif component.kind == "RW":
        out[0] = c
    elif component.kind == "DR":  # a ramp: the increments' mean, no variance
        pass
    elif component.kind == "FN":  # Hosking's d = -1/2 fractional difference
        out[:] = (4 * c / math.pi) / (1 - 4 * h[:-1] ** 2)
    else:  # AR1, stationary y of autocovariance r: gamma_d(h) = 2 r(h) - r(h - 1) - r(h + 1)
        r = c * component.shape ** np.abs(np.arange(-1, lags + 2)) / (1 - component.shape**2)
        out[:] = 2 * r[1:-1] - r[:-2] - r[2:]
    return out


def brute_force(components: list[Component], n: int, factors: np.ndarray, omega: float = 0.0) -> np.ndarray:
    size = n - 1  # increments d_1..d_{n-1}
    gamma = sum(increment_autocovariance(c, size - 1) for c in components)
    big_g = toeplitz(gamma)
    grams, counts = [], []
    for m in factors:
        count = n - 2 * m + 1
        filt = np.zeros((count, size))
        ell = np.arange(1, 2 * m)
        for s in range(count):
            filt[s, s + ell - 1] = np.minimum(ell, 2 * m - ell) / (m * math.sqrt(2.0))
        grams.append(filt.T @ filt)
        counts.append(count)
    mean = np.full(size, omega)
    out = np.empty((factors.size, factors.size))
    for j, qj in enumerate(grams):
        for k, qk in enumerate(grams):
            left, right = qj @ big_g, qk @ big_g
            out[j, k] = (2 * np.trace(left @ right) + 4 * mean @ qj @ big_g @ qk @ mean) / (counts[j] * counts[k])
    return out


@pytest.mark.parametrize("kind, shape", [("QN", None), ("WN", None), ("FN", None), ("RW", None), ("AR1", 0.97)])
def test_the_structure_function_gives_each_terms_allan_variance(kind, shape):
    component = Component(kind, 0.7, shape)
    s2 = _second_sums(structure_function([component], 4000))
    for m in (1, 2, 5, 16, 100):
        at = np.array([0])
        gamma0 = (_phi(s2, at + m, m, m) + _phi(s2, at - m, m, m) - 2 * _phi(s2, at, m, m))[0] / (4 * m * m)
        assert gamma0 == pytest.approx(0.7 * basis(kind, shape, np.array([m]))[0], rel=1e-9)


@pytest.mark.parametrize("components, omega", [
    ([Component("WN", 1.0)], 0.0),
    ([Component("FN", 1.0)], 0.0),
    ([Component("RW", 0.01)], 0.0),
    ([Component("QN", 0.5), Component("WN", 1.0), Component("FN", 0.3), Component("RW", 1e-3)], 0.0),
    ([Component("WN", 1.0), Component("AR1", 0.2, 0.9)], 0.0),
    ([Component("WN", 1.0), Component("RW", 1e-3), Component("DR", 0.05**2)], 0.05),
])
def test_level_covariance_equals_the_dense_quadratic_forms(components, omega):
    n, factors = 300, np.array([1, 2, 4, 8, 16, 32, 64, 100, 149])  # the last level has M = 2 terms
    exact = brute_force(components, n, factors, omega)
    fast = structure_covariance(components, n, factors)
    spread = np.sqrt(np.diag(exact))
    # the trapezoid between the summand's kinks errs by < 1e-3 of the levels' spread
    np.testing.assert_allclose(fast / np.outer(spread, spread), exact / np.outer(spread, spread), atol=1e-3)
    np.testing.assert_allclose(np.diag(fast), np.diag(exact), rtol=1e-3)


def test_long_series_match_the_fft_covariance_and_cost_little():
    """At N = 2^14 and levels to 2^12 the lags are summed sparsely; the FFT formula sums them all."""
    n, factors = 2**14, 2 ** np.arange(13)
    for model, components in [(WN(sigma2=1.0) + RW(gamma2=1e-3), [Component("WN", 1.0), Component("RW", 1e-3)]),
                              (AR1(phi=0.99, sigma2=0.5), [Component("AR1", 0.5, 0.99)])]:
        exact = exact_covariance(model, n, factors)
        spread = np.sqrt(np.diag(exact))
        fast = structure_covariance(components, n, factors)
        np.testing.assert_allclose(fast / np.outer(spread, spread), exact / np.outer(spread, spread), atol=1e-3)


def test_terms_that_mix_are_not_one_power_law():
    """Where white noise and a random walk cross, the levels' correlation lies between the pure laws'."""
    n, factors = 2**16, 2 ** np.arange(14)
    cross = structure_covariance([Component("WN", 1.0), Component("RW", 1e-5)], n, factors)
    white = structure_covariance([Component("WN", 1.0)], n, factors)
    walk = structure_covariance([Component("RW", 1e-5)], n, factors)

    def adjacent(c):
        spread = np.sqrt(np.diag(c))
        return np.diag(c / np.outer(spread, spread), 1)

    # the AVs cross near m = sqrt(3 / 1e-5) ~ 550: levels 8..10
    mixed, low, high = adjacent(cross)[9], adjacent(white)[9], adjacent(walk)[9]
    assert low + 0.05 < mixed < high - 0.05


def test_a_sinusoid_adds_to_the_levels_not_to_their_covariance():
    """Fixed amplitude, random phase: its share of each estimate is all but constant between records."""
    n, factors = 300, 2 ** np.arange(7)
    noise = [Component("WN", 1.0), Component("AR1", 0.2, 0.9)]
    np.testing.assert_array_equal(structure_covariance(noise + [Component("SIN", 0.3, 0.07)], n, factors),
                                  structure_covariance(noise, n, factors))


def test_a_dense_grid_is_interpolated_from_log_spaced_levels():
    n = 20_000
    components = [Component("WN", 1.0), Component("FN", 0.01), Component("RW", 1e-5)]
    dense = np.unique(np.geomspace(1, 5000, 90).round().astype(np.int64))
    assert dense.size > MAX_EXACT_LEVELS
    interpolated = structure_covariance(components, n, dense)
    subset = dense[::3]
    exact = structure_covariance(components, n, subset)
    spread = np.sqrt(np.diag(exact))
    np.testing.assert_allclose(interpolated[::3, ::3] / np.outer(spread, spread), exact / np.outer(spread, spread),
                               atol=0.03)


def test_non_overlapping_estimates_get_wider_intervals_for_the_random_walk():
    import avar

    rng = np.random.default_rng(4)
    x = rng.standard_normal(2**18) + np.cumsum(1e-3 * rng.standard_normal(2**18))
    widths = {}
    for type in ("mo", "to"):
        table = avar.noise_report(x, gyro_units="rad/s", rate=100.0, type=type).table
        row = table[table["Process"] == "RW"].iloc[0]
        widths[type] = float(row["Upper"]) - float(row["Lower"])
    assert widths["to"] > 1.2 * widths["mo"]
