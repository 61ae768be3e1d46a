"""The deviation kernels against plain loops over the formulas; determinism across thread counts."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from avar._kernels.classic.levels import detrended_phase, level_sums, scan
from avar.stability.classic.core import deviation_levels, phase_parts
from avar.stability.shared.grids import deviation_factors
from avar.stability.shared.registry import CLASSIC as ESTIMATORS
from avar.stability.shared.registry import KERNEL_CODES
from avar.stability.shared.term_counts import term_ranges
from tests._support.deviation_reference import exact_variance

NO_LO = np.zeros(1, dtype=np.float32)


def test_detrended_phase_is_the_exact_running_sum():
    rng = np.random.default_rng(0)
    y = 1e8 + rng.standard_normal(200_001)  # several cumulative-sum blocks
    hi = np.empty(y.size + 1)
    lo = np.empty(y.size + 1, dtype=np.float32)
    detrended_phase(y, NO_LO, 0, 1e8, 0.0, 1.0, hi, lo, block=4096)
    centred = [float(v) - 1e8 for v in y[:5000]]  # exact: |v| < 2**27 apart from 1e8
    running = np.concatenate(([0.0], np.cumsum(centred)))
    np.testing.assert_allclose(hi[:5001] + lo[:5001], running, rtol=0, atol=1e-9)
    # phase input: increments x[i+1] - x[i] as exact pairs
    x = np.cumsum(y)
    detrended_phase(x, NO_LO, 1, 0.0, 0.0, 1.0, hi[:-1], lo[:-1])
    assert hi[0] == 0.0 and abs(hi[1] - (x[1] - x[0])) == 0.0


def test_scan():
    data = np.array([1.0, np.nan, -3.0, 5.0, np.nan])
    assert scan(data, block=2)[:4] == (2, 3.0, -3.0, 5.0)
    assert np.isnan(scan(data, block=2, weigh=True)[4])  # no moment with a NaN
    clean = np.array([1.0, 2.0, -3.0, 5.0, 7.0, 0.5, 4.0])
    assert np.isnan(scan(clean)[4])  # not asked for
    for block in (2, 5, 8192):  # the 4-wide loop, its tail, block seams
        moment = scan(clean, block=block, weigh=True)[4]
        assert moment == pytest.approx(sum((i - 3.0) * v for i, v in enumerate(clean)), rel=1e-15)


def plain_loop(code, hi, lo, m, stride, first, last):
    """Sum of squared terms by the definition, in float64 on P = hi + lo."""
    p = hi + lo.astype(np.float64)
    n = p.size - 1
    total = 0.0
    for k in range(first, last):
        b = k * stride
        if code == 0:
            d = p[b + 2 * m] - 2 * p[b + m] + p[b]
        elif code in (1, 2):
            d = p[b + 3 * m] - 3 * p[b + 2 * m] + 3 * p[b + m] - p[b]
        elif code == 4:
            d = p[b + 4 * m] - 4 * p[b + 3 * m] + 6 * p[b + 2 * m] - 4 * p[b + m] + p[b]
        else:
            def star(j):
                return 2 * p[0] - p[-j] if j < 0 else (2 * p[n] - p[2 * n - j] if j > n else p[j])
            d = star(k - m) - 2 * p[k] + star(k + m)
        total += d * d
    return total


@pytest.mark.parametrize("estimator", ["adev", "oadev", "hdev", "ohdev", "totdev", "mdev", "mhdev"])
def test_level_sums_match_plain_loops(estimator):
    rng = np.random.default_rng(1)
    hi = np.cumsum(rng.standard_normal(3001))
    lo = (rng.standard_normal(3001) * 1e-17).astype(np.float32)
    modified = estimator in ("mdev", "mhdev")  # hi is the running sum: one point more than the phase
    factors = deviation_factors(estimator, 3001 - modified, taus="all")[::37]
    strides, first, last = term_ranges(estimator, 3001 - modified, factors)
    sums, counts = level_sums(hi, lo, KERNEL_CODES[estimator], factors, strides, first, last, chunk=256)
    for i, m in enumerate(factors):
        expected = plain_loop(KERNEL_CODES[estimator], hi, lo, int(m), int(strides[i]), int(first[i]), int(last[i]))
        assert sums[i] == pytest.approx(expected, rel=1e-12)
        assert counts[i] == last[i] - first[i]


@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_adversarial_offsets_against_exact_arithmetic(estimator):
    """A frequency offset of 1e9 over 1e-6 noise, and a phase ramp of 1e5 s/sample."""
    rng = np.random.default_rng(2)
    y = 1e9 + 1e-6 * rng.standard_normal(40)
    x = 1e5 * np.arange(40.0) + 1e-7 * rng.standard_normal(40)
    for data, data_type in ((y, "freq"), (x, "phase")):
        factors = deviation_factors(estimator, 40 + (data_type == "freq"), taus="all")
        variance, n = deviation_levels(estimator, data, factors, data_type, 1.0)
        for m, v, count in zip(factors, variance, n):
            expected, terms = exact_variance(estimator, data, int(m), data_type)
            assert count == terms
            assert v == pytest.approx(expected, rel=1e-10)


@pytest.mark.parametrize("estimator", ESTIMATORS)
def test_a_long_offset_stays_exact(estimator):
    """1e9 + 1e-6 noise, 1500 values: the phase's low part (float32) accumulates what the
    increments lose to the offset and the removed drift, which must stay below its precision
    (the Hadamard pair removed the drift from the undetrended value: errors of 1e-8)."""
    y = 1e9 + 1e-6 * np.random.default_rng(4).standard_normal(1500)
    factors = np.array([1, 3, 16, 100])
    variance, _ = deviation_levels(estimator, y, factors, "freq", 1.0)
    for m, v in zip(factors, variance):
        assert v == pytest.approx(exact_variance(estimator, y, int(m), "freq")[0], rel=1e-12)


def test_results_do_not_depend_on_the_thread_count():
    y = np.random.default_rng(3).standard_normal(300_000)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = [deviation_levels(e, y, deviation_factors(e, y.size + 1), "freq")[0] for e in ESTIMATORS]
        numba.set_num_threads(max(2, threads))
        many = [deviation_levels(e, y, deviation_factors(e, y.size + 1), "freq")[0] for e in ESTIMATORS]
    finally:
        numba.set_num_threads(threads)
    for a, b in zip(one, many):
        np.testing.assert_array_equal(a, b)


def test_hadamard_removes_the_drift():
    """An exactly linear frequency drift (y = 1e3 + i / 2) leaves HDEV at rounding level (1e-32 of ADEV**2)."""
    y = 1e3 + 0.5 * np.arange(100_000.0)
    parts = phase_parts(y, "freq", "ohdev")
    hi, scale, mode, bad = parts.hi, parts.scale, parts.mode, parts.bad
    assert mode == 0 and bad is None and np.max(np.abs(hi)) / scale < 1e6  # the drift is gone from the phase
    for estimator in ("hdev", "ohdev"):
        variance, _ = deviation_levels(estimator, y, np.array([1, 10, 100]), "freq")
        assert np.all(variance < 1e-25), variance
    assert deviation_levels("oadev", y, np.array([1]), "freq")[0][0] == pytest.approx(0.125)


@pytest.mark.parametrize("n", [0, 1, 3, 4, 7, 65_536, 65_539, 200_001])
def test_scan_equals_numpy_with_gaps_and_infinities_anywhere(n):
    rng = np.random.default_rng(n)
    y = rng.standard_normal(n) * 1e3 + 5.0
    for positions in ([], [0], [n - 1], [n // 2, n - 2]):
        z = y.copy()
        z[[p for p in positions if 0 <= p < n]] = np.nan
        if n > 10:
            z[n - 3] = np.inf  # in a tail, past the last group of four
        finite = z[~np.isnan(z)]
        count, total, low, high, moment = scan(z)
        assert count == np.isnan(z).sum()
        assert low == (finite.min() if finite.size else np.inf)
        assert high == (finite.max() if finite.size else -np.inf)
        expected = math.fsum(finite) if np.all(np.isfinite(finite)) else np.sum(finite)
        assert total == pytest.approx(expected, rel=1e-12, abs=1e-9)
    if n:  # gap-free: the centred moment of the Hadamard family's drift (scale: n^2 / 2 * 1e3)
        moment = scan(y, weigh=True)[4]
        assert moment == pytest.approx(math.fsum((i - (n - 1) / 2) * v for i, v in enumerate(y)),
                                       rel=1e-12, abs=1e-12 * n * n * 1e3)


def test_centred_moment_equals_a_plain_loop_at_any_thread_count():
    from avar._kernels.classic.phase import centred_moment

    rng = np.random.default_rng(3)
    y = rng.standard_normal(150_001)
    for kind in (0, 1):
        count = y.size - kind
        increments = np.diff(y) if kind else y
        expected = math.fsum((i - (count - 1) / 2) * v for i, v in enumerate(increments))
        bits = []
        for threads in (1, 2):
            numba.set_num_threads(threads)
            bits.append(centred_moment(y, kind))
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        assert bits[0] == bits[1]
        assert bits[0] == pytest.approx(expected, rel=1e-10)


@pytest.mark.parametrize("estimator", ["oadev", "mdev", "mhdev", "ohdev", "totdev"])
def test_a_huge_phase_ramp_keeps_the_digits_of_the_noise(estimator):
    """x = 1e3 i + 1e-9 noise: the first increment's rounding (x[1] - x[0]) is a constant low part
    of every increment, which MDEV's running sum of the phase adds up linearly; its float32 low
    part kept 24 bits of that line rather than of the sum (MDEV off by 1.7e-10 relative)."""
    x = 1e3 * np.arange(2000.0) + 1e-9 * np.random.default_rng(0).standard_normal(2000)
    factors = np.array([1, 2, 4, 16, 64])
    from avar._kernels.runtime.paths import forced

    with forced("compiled"):
        variance, _ = deviation_levels(estimator, x, factors, "phase", 1.0)
    for m, v in zip(factors, variance):
        assert v == pytest.approx(exact_variance(estimator, x, int(m), "phase")[0], rel=1e-13), m


@pytest.mark.parametrize("estimator", ["hdev", "ohdev", "mhdev"])
def test_a_negligible_drift_is_kept_with_the_same_levels_and_noise(estimator):
    """White FM's fitted drift (~1e-22 here) is kept on the public path (one TwoSum per value
    less): the same variances (to rounding) and alphas as removing it; a drift that
    dominates the data is still removed."""
    from avar.stability.classic.core import deviation_levels_and_phase
    from avar.stability.classic.deviations import noise_of_levels

    y = np.random.default_rng(3).standard_normal(300_000) * 1e-11 + 2e-22 * np.arange(300_000)
    scanned = scan(y, weigh=True)
    assert phase_parts(y, "freq", estimator, scanned, True).drift == 0.0
    assert phase_parts(y, "freq", estimator, scanned).drift != 0.0
    factors = deviation_factors(estimator, y.size + 1)
    kept = deviation_levels_and_phase(estimator, y, factors, "freq", 1.0, scanned)
    hi, lo, scale, _, _, phase, drift, _ = phase_parts(y, "freq", estimator, scanned)
    strides, first, last = term_ranges(estimator, y.size + 1, factors)
    sums, _ = level_sums(hi, lo, KERNEL_CODES[estimator], factors, strides, first, last)
    m = factors.astype(float)
    modified = m * m if estimator == "mhdev" else 1.0
    removed = sums / (6 * m * m * modified * (last - first)) / scale**2  # the drift removed
    np.testing.assert_allclose(kept.variance, removed, rtol=1e-12)  # HDEV: by the pyramid
    alpha = noise_of_levels(estimator, kept.phase, kept.drift, factors, kept.line)
    np.testing.assert_array_equal(alpha, noise_of_levels(estimator, phase, drift, factors, None))
    steep = y + 1e-9 * np.arange(y.size)
    assert phase_parts(steep, "freq", estimator, scan(steep, weigh=True), True).drift != 0.0
