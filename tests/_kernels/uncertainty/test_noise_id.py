"""The compiled lag-1 noise identification against its plain NumPy twin."""

from __future__ import annotations

import numpy as np
import pytest

from avar._kernels.uncertainty.lag1 import lag1_alpha_decimated
from avar._kernels.uncertainty.noise_id import moments_with_drift
from avar.stability.uncertainty.noise_id import lag1_alpha


def plain_alpha(x: np.ndarray, m: int, dmax: int) -> float:
    """Decimate, remove the least-squares line (numpy.polynomial), then the NumPy lag-1 rule."""
    z = x[::m]
    u = np.linspace(-1.0, 1.0, z.size)
    trend = np.polynomial.polynomial.polyval(u, np.polynomial.polynomial.polyfit(u, z, 1))
    return lag1_alpha(z - trend, dmax)


def series(kind: str, n: int, seed: int) -> np.ndarray:
    w = np.random.default_rng(seed).standard_normal(n)
    drift = 1e3 + 0.5 * np.arange(n)  # a phase and a frequency offset: removed by both
    return {"white pm": w, "white fm": np.cumsum(w), "rw fm": np.cumsum(np.cumsum(w))}[kind] + drift


@pytest.mark.parametrize("kind", ["white pm", "white fm", "rw fm"])
@pytest.mark.parametrize("dmax", [2, 3])
def test_kernel_equals_the_numpy_twin(kind, dmax):
    hits = 0
    for seed in range(6):
        x = series(kind, 5000, seed)
        for m in (1, 2, 3, 7, 16, 64, 150):
            got, expected = lag1_alpha_decimated(x, m, dmax, np.nan), plain_alpha(x, m, dmax)
            assert got == expected, (kind, seed, m)
            hits += 1
    assert hits == 42


@pytest.mark.parametrize("kind", ["white pm", "white fm", "rw fm"])
@pytest.mark.parametrize("dmax", [2, 3])
def test_phase_data_keep_their_line(kind, dmax):
    # phase data: the kernel gets the line the caller removed back and takes only the mean off,
    # as the twin does with the decimated phase as given (no least-squares line)
    for seed in range(6):
        w = np.random.default_rng(seed).standard_normal(1200)
        given = {"white pm": w, "white fm": np.cumsum(w), "rw fm": np.cumsum(np.cumsum(w))}[kind]
        given = given + 0.02 * np.arange(1200) * given.std() / 1200  # a small frequency offset
        slope = (given[-1] - given[0]) / 1199
        detrended = given - slope * np.arange(1200)
        for m in (1, 2, 5, 16, 40):
            assert lag1_alpha_decimated(detrended, m, dmax, slope) == lag1_alpha(given[::m], dmax), (kind, seed, m)


def test_a_large_frequency_offset_of_phase_data_keeps_its_digits():
    # 1e12 times the noise: the offset sends order 0 to the differences, which the kernel forms
    # from the least-squares residuals; white PM and white FM are still told apart
    for seed in range(4):
        w = np.random.default_rng(seed).standard_normal(3000)
        for noise, alpha in ((w, 2.0), (np.cumsum(w), 0.0)):
            assert lag1_alpha_decimated(noise, 1, 2, 1e12) == alpha
            assert lag1_alpha_decimated(noise, 1, 2, 0.0) == alpha  # no offset: order 0 decides the same


def test_constant_series_gives_nan():
    assert np.isnan(lag1_alpha_decimated(np.full(100, 3.5), 1, 2, np.nan))
    assert np.isnan(lag1_alpha_decimated(np.full(100, 3.5), 1, 2, 0.0))


@pytest.mark.parametrize("factors", [[1, 2, 4, 8, 16, 32, 64, 128], [1, 3, 6, 7, 14, 100, 200], [5], [2, 4]])
def test_levels_serial_split_and_single_agree(factors):
    from avar._kernels.uncertainty.lag1 import lag1_levels, lag1_levels_split

    x = series("white fm", 20_000, 1)
    m = np.array(factors, dtype=np.int64)
    for line in (np.nan, 0.0, -0.5):  # frequency data; phase data as given and less a line
        serial, split = np.empty(m.size), np.empty(m.size)
        lag1_levels(x, m, 2, line, serial)
        lag1_levels_split(x, m, 2, line, split)
        single = [lag1_alpha_decimated(x, int(f), 2, line) for f in m]
        np.testing.assert_array_equal(serial, single)
        np.testing.assert_array_equal(split, single)


@pytest.mark.parametrize("kind", ["white pm", "white fm"])
def test_a_frequency_drift_stays_for_the_differences(kind):
    # only the line is removed (Stable32): a drift's parabola reaches the differencing, which
    # the twin reproduces, and second differences still read white PM / white FM
    for seed in range(4):
        x = series(kind, 3000, seed) + 1e-3 * np.arange(3000.0) ** 2
        got = lag1_alpha_decimated(x, 1, 2, np.nan)
        assert got == plain_alpha(x, 1, 2) == (2.0 if kind == "white pm" else 0.0)


def plain_moments(z: np.ndarray) -> np.ndarray:
    """The 16 moments of :data:`avar._kernels.classic.pyramid.MOMENTS` of points z_0 .. z_C, by NumPy."""
    c = z.size - 1
    t = np.arange(c + 1) - c / 2.0
    d1, d2, d3, d4 = (np.diff(z, k) for k in (1, 2, 3, 4))
    return np.array([c, z.sum(), (t * z).sum(), (t * t * z).sum(), (z * z).sum(), (d1 * d1).sum(), (d2 * d2).sum(),
                     (d3 * d3).sum(), (d4 * d4).sum(), z[-1], d1[0], d1[-1], d2[0], d2[-1], d3[0], d3[-1]])


@pytest.mark.parametrize("count, m, drift", [(5, 1, 0.3), (40, 7, 3e-3), (333, 64, -2e-7)])
def test_moments_with_drift_equal_the_moments_of_the_drifted_points(count, m, drift):
    z = np.concatenate(([0.0], np.cumsum(np.random.default_rng(count).standard_normal(count))))
    i = np.arange(count + 1.0) * m
    want = plain_moments(z + drift * i * (i - 1.0) / 2.0)
    got = moments_with_drift(plain_moments(z), drift, m)
    np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-11 * np.abs(want).max())


def exact_alpha(x: np.ndarray, m: int, dmax: int) -> float:
    """The lag-1 rule (line removed, Stable32's r1) on x[::m] in exact rational arithmetic."""
    from fractions import Fraction

    z = [Fraction(float(v)) for v in x[::m]]
    k = len(z)
    t = [Fraction(2 * j - (k - 1), 2) for j in range(k)]
    mean = sum(z) / k
    slope = sum(a * b for a, b in zip(t, z)) / Fraction(k * (k * k - 1), 12)
    w = [a - (mean + slope * b) for a, b in zip(z, t)]
    for d in range(dmax + 1):
        if d:
            w = [w[j + 1] - w[j] for j in range(len(w) - 1)]
        c = sum(w) / len(w)
        centred = [v - c for v in w]
        power = sum(v * v for v in centred)
        r1 = sum(a * b for a, b in zip(centred[:-1], centred[1:])) / power * Fraction(len(w) - 1, len(w))
        rho = r1 / (1 + r1)
        if rho < Fraction(1, 4) or d >= dmax:
            return float(2 - round(2 * rho) - 2 * d)
    return np.nan


def test_a_dominant_frequency_drift_keeps_the_noise_digits():
    # x = 1e-2 i^2 + 1e-6 random walk: the second differences are the drift's constant 0.02 m^2
    # (1e3 at m = 256) plus 1e-5 of noise; summing their squares before removing their mean
    # lost every digit (alpha -8 at m = 256, -2 at m = 512); now as exact arithmetic
    n = 20_000
    i = np.arange(n, dtype=np.float64)
    x = 1e-2 * i * i + 1e-6 * np.cumsum(np.random.default_rng(1).standard_normal(n))
    for m in (64, 128, 256, 512):
        expected = exact_alpha(x, m, 2)
        assert lag1_alpha_decimated(x, m, 2, np.nan) == expected, m
        assert plain_alpha(x, m, 2) == expected, m
    assert exact_alpha(x, 256, 2) == -1.0  # not a test that cannot fail: the levels differ
    assert exact_alpha(x, 512, 2) == 0.0


@pytest.mark.parametrize("estimator", ["adev", "hdev", "oadev"])
def test_a_dominant_drift_in_frequency_data_is_identified_as_exactly(estimator):
    # ADEV and HDEV of octave frequency data decide from the pyramid's one-pass moments: the
    # variance about a mean far above the noise lost every digit there (HDEV read white PM at
    # m = 256); such a level now goes to the two-pass kernel, which agrees with the NumPy twin
    # and, at m = 128 .. 512, with exact arithmetic on the phase
    import avar
    from avar._kernels.runtime.paths import forced

    n = 20_000
    i = np.arange(n, dtype=np.float64)
    x = 1e-2 * i * i + 1e-6 * np.cumsum(np.random.default_rng(1).standard_normal(n))
    found = {}
    for path in ("numpy", "compiled"):
        with forced(path):
            result = getattr(avar, estimator)(np.diff(x), data_type="freq")
        found[path] = result.alpha
    np.testing.assert_array_equal(found["compiled"], found["numpy"])
    levels = list(result.averaging_factors)
    for m in (128, 256, 512):
        assert found["compiled"][levels.index(m)] == exact_alpha(x, m, 3 if "h" in estimator else 2), m


@pytest.mark.parametrize("kind", ["white pm", "white fm", "rw fm"])
@pytest.mark.parametrize("k", [3, 4, 1025, 1026, 5000])
def test_contiguous_passes_equal_the_sums_they_stand_for(kind, k):
    """The vectorized passes of a contiguous series (m = 1) against math.fsum of the same values:
    the line's projections, then per order (0: r_i - r_0, 1: (r_i - r_{i-1}) - (r_1 - r_0)) the
    sum, the sum of squares, the lag-1 sum of products, the first and the last value."""
    import math

    from avar._kernels.uncertainty.lag1 import order_pass_contiguous, projections_contiguous

    x = series(kind, k, 7)
    half, c2 = (k - 1) / 2.0, (k * k - 1.0) / 12.0
    t = np.arange(k) - half
    s0, s1, s2 = projections_contiguous(x, k, half, c2)
    for got, terms in ((s0, x), (s1, t * x), (s2, (t * t - c2) * x)):
        assert abs(got - math.fsum(terms)) <= 1e-13 * math.fsum(np.abs(terms))
    a0, a1 = s0 / k, s1 / (k * (k * k - 1.0) / 12.0)
    stats = np.zeros((2, 5))
    order_pass_contiguous(x, k, half, c2, a0, a1, 0.0, stats)
    r = x - (a0 + a1 * t)
    a = r - r[0]
    b = np.diff(r) - (r[1] - r[0])
    for row, v in ((stats[0], a), (stats[1], b)):
        for got, terms in ((row[0], v), (row[1], v * v), (row[2], v[:-1] * v[1:])):
            assert abs(got - math.fsum(terms)) <= 1e-12 * math.fsum(np.abs(terms)) + 1e-300
        assert row[3] == 0.0 and abs(row[4] - v[-1]) <= 1e-12 * np.abs(v).max()
