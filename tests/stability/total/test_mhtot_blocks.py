"""MHTOTDEV's blocked O(N) expansion and its NumPy twin against the direct O(N m) loop and exact rationals."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import avar
from avar._kernels.runtime import paths, tasks
from avar._kernels.runtime.paths import forced
from avar._kernels.total import mhtot as kernel
from avar._kernels.total.blocks import block_size
from avar._kernels.total.mhtot_blocks import level_sum, level_tables, segments
from avar.stability.total import mhtot as statistic
from avar.stability.total import small_mhtot
from tests._support.powerlaw import powerlaw_phase

NO_GAPS = np.zeros(0, dtype=np.int64)


def direct(x: np.ndarray, m: int) -> float:
    """The direct loop's level sum (:func:`avar._kernels.total.mhtot.level_sum`)."""
    return kernel.level_sum(x, m, NO_GAPS, 0).total


def exact_level(x: list, m: int) -> Fraction:
    """sum over the windows of sum_j A_j^2 (half-means detrending, reflected extension), exactly."""
    span, half = 3 * m + 1, (3 * m + 1) // 2
    total = Fraction(0)
    for n in range(len(x) - 4 * m + 1):
        w = x[n : n + span]
        slope = (sum(w[half:]) / (span - half) - sum(w[:half]) / half) / Fraction(span, 2)
        d = [w[k] - slope * k for k in range(span)]
        e = d[::-1] + d + d[::-1]
        third = [e[i] - 3 * e[i + m] + 3 * e[i + 2 * m] - e[i + 3 * m] for i in range(len(e) - 3 * m)]
        total += sum(sum(third[j : j + m]) ** 2 for j in range(len(third) - m + 1))
    return total


#: Phase of white PM, flicker PM, white FM, flicker FM and random-walk FM (FFT-filtered white noise).
N = 3000
SERIES = {alpha: powerlaw_phase(N, alpha, seed=60 + alpha) for alpha in (2, 1, 0, -1, -2)}


@pytest.mark.parametrize("alpha", [2, 1, 0, -1, -2])
def test_equals_the_direct_loop(alpha):
    """Every segment layout (m = 1, 2, 3 and up; odd and even L = 3m + 1) up to m = N / 4, on the
    phase and on its running sum (the phase of the same series read as frequency: one integration
    more, the hardest conditioning); the last block is short unless the windows fill it (at m =
    749 it holds 5 windows, fewer than m: the partner sums' general case)."""
    for x in (SERIES[alpha], np.concatenate(([0.0], np.cumsum(SERIES[alpha])))):
        for m in (1, 2, 3, 4, 5, 8, 33, 120, 333, 749):
            expected = direct(x, m)
            assert level_sum(x, m) == pytest.approx(expected, rel=1e-11), m
            assert small_mhtot.level_sum(x, m).total == pytest.approx(expected, rel=1e-11), m  # and the twin


def test_long_series_several_blocks_per_level():
    x = np.cumsum(powerlaw_phase(20000, -2, seed=3))
    for m in (6, 64, 700):
        assert (x.size - 4 * m + 1) > 4 * block_size(m)
        assert level_sum(x, m) == pytest.approx(direct(x, m), rel=1e-11)


def test_equals_exact_rationals():
    """A random walk, and a smooth record far from 0 (thrice integrated white noise plus 1e6): both
    the expansion and the direct loop (which reads each window less its first point) to 1e-12."""
    walk = np.cumsum(np.random.default_rng(5).standard_normal(40))
    smooth = np.cumsum(np.cumsum(walk)) + 1e6
    for x in (walk, smooth):
        exact = [Fraction(float(v)) for v in x]
        for m in (1, 2, 3, 4):
            expected = float(exact_level(exact, m))
            assert level_sum(x, m) == pytest.approx(expected, rel=1e-12)
            assert direct(x, m) == pytest.approx(expected, rel=1e-12)


def test_segments_and_tables():
    """The nine segments cover j = 0 .. 5m + 3; the tables are exact halves and quarters of integers."""
    for m in (1, 2, 3, 7, 1 << 17):
        cuts = segments(m)
        assert cuts[0].first == 0 and sum(segment.length for segment in cuts) == 5 * m + 4
        assert all(a.first + a.length == b.first for a, b in zip(cuts[:-1], cuts[1:]))
        tables = level_tables(m)
        for table in (tables.moment_weights, tables.point_weights, tables.square):
            assert np.all(table * 4 == np.round(table * 4))
    assert [segment.length for segment in segments(10)] == [1, 10, 10, 1, 9, 1, 10, 10, 2]


def test_blind_to_a_line_and_to_the_thread_count(monkeypatch):
    x = SERIES[-1]
    assert level_sum(x + 3.0 - 0.01 * np.arange(N), 40) == pytest.approx(level_sum(x, 40), rel=1e-10)
    sums = []
    for count in (1, 3):
        monkeypatch.setattr(tasks, "threads", lambda count=count: count)
        sums.append(level_sum(x, 9))
    assert sums[0] == sums[1]  # each block's sum has its own slot, added in order


def prefix_count(missing: np.ndarray) -> np.ndarray:
    return np.concatenate(([0], np.cumsum(missing))).astype(np.int64)


@pytest.mark.parametrize("shift", [0, 1])
def test_gaps_run_the_blocks_over_the_clean_stretches(monkeypatch, shift):
    """Windows touching a gap are skipped: the expansion over each run of clean windows equals
    the direct loop's skipping loop, and so does the twin's. A missing phase point is NaN, a
    missing frequency sample a jump of the phase: reading either would show."""
    x = SERIES[-1].copy()
    missing = np.zeros(N - shift, dtype=bool)  # phase points (shift 0) or frequency samples (shift 1)
    missing[[5, 6, 700, 1800, 1810, 2500]] = True
    bad = prefix_count(missing)
    for k in np.flatnonzero(missing):
        if shift:
            x[k + 1 :] += 1e6
        else:
            x[k] = np.nan
    factors = np.array([1, 2, 6, 16, 33, 150, 250])  # 3m + 1 = 751 fits between the gaps at 700 and 1800
    fast = kernel.level_sums(x, factors, bad, shift)
    paths_taken = [kernel.blocked(m, used) for m, used in zip(factors.tolist(), fast.n_terms.tolist())]
    assert any(paths_taken) and not all(paths_taken)
    monkeypatch.setattr(kernel, "FAST_WORK", 1 << 62)
    slow = kernel.level_sums(x, factors, bad, shift)
    assert fast.n_terms.tolist() == slow.n_terms.tolist() and slow.n_terms[-1] > 0 and np.isfinite(slow.sums).all()
    np.testing.assert_allclose(fast.sums, slow.sums, rtol=1e-11)
    twin = small_mhtot.level_sums(x, factors, bad, shift)
    assert twin.n_terms.tolist() == slow.n_terms.tolist()
    np.testing.assert_allclose(twin.sums, slow.sums, rtol=1e-11)


def test_levels_choose_their_path(monkeypatch):
    """Levels with enough windows take the expansion, small ones the direct loop."""
    calls = []
    monkeypatch.setattr(kernel, "blocked_level_sum", lambda x, m, clean=None: calls.append(m) or 0.0)
    x = SERIES[0]
    assert (N - 3) * (1 + 4) <= kernel.FAST_WORK < (N - 4 * 8 + 1) * (8 + 4)
    kernel.level_sums(x, np.array([1, 8, 64]), NO_GAPS, 0)
    kernel.level_sums(x[:200], np.array([8]), NO_GAPS, 0)  # 169 windows: too few to pay for the tables
    assert calls == [8, 64]
    assert kernel.level_kernels(N, np.array([1, 64]), False) == kernel.BLOCK_KERNELS + kernel.DIRECT_KERNELS


@pytest.mark.parametrize("data_type", ["phase", "freq"])
@pytest.mark.parametrize("alpha", [2, 1, 0, -1, -2])
def test_twin_equals_the_kernels(alpha, data_type):
    """The NumPy twin and the compiled path of :func:`avar.mhtotdev`, on every noise, at 1e-12."""
    data = SERIES[alpha] if data_type == "phase" else np.diff(SERIES[alpha])
    with forced("numpy"):
        cold = avar.mhtotdev(data, data_type=data_type, taus="octave")
    with forced("compiled"):
        warm = avar.mhtotdev(data, data_type=data_type, taus="octave")
    assert cold.n.tolist() == warm.n.tolist()
    np.testing.assert_allclose(cold.variance, warm.variance, rtol=1e-12)


def test_twin_with_gaps_and_its_certificate(monkeypatch):
    y = np.diff(SERIES[-2]) + 1e3  # a large frequency offset, on random-walk FM
    y[[10, 11, 1500]] = np.nan
    with forced("numpy"):
        cold = avar.mhtotdev(y, taus="octave", nan_policy="omit")
    with forced("compiled"):
        warm = avar.mhtotdev(y, taus="octave", nan_policy="omit")
    assert cold.n.tolist() == warm.n.tolist() and cold.n[0] == N - 4 + 1 - 4 - 3  # windows 8 .. 11, 1498 .. 1500
    np.testing.assert_allclose(cold.variance, warm.variance, rtol=1e-12)
    # a twin that cannot certify its rounding hands over to the kernels
    monkeypatch.setattr(small_mhtot, "TOL", 0.0)
    assert small_mhtot.level_sums(SERIES[0], np.array([4]), NO_GAPS, 0) is None
    calls = []
    monkeypatch.setattr(statistic, "level_sums", lambda *args: calls.append(1) or kernel.level_sums(*args))
    with forced("numpy"):
        np.testing.assert_allclose(avar.mhtotdev(y, taus="octave", nan_policy="omit").variance, warm.variance,
                                   rtol=1e-12)
    assert calls == [1]


def test_cold_kernels_take_the_twin(monkeypatch):
    """While the kernels are not compiled (and the record is small), the levels come from the twin."""
    calls = []
    real = small_mhtot.level_sums
    monkeypatch.setattr(small_mhtot, "level_sums", lambda *args: calls.append(1) or real(*args))
    monkeypatch.setattr(paths, "compiled", lambda kernels, argument=None: False)
    monkeypatch.setattr(paths, "_WARM_ROUTES", set())
    monkeypatch.setattr(paths, "_SPENT", {})
    with forced("auto"):
        statistic.mhtotdev(SERIES[1], data_type="phase")
        assert calls == [1]
        statistic.mhtotdev(np.zeros(1 << 21) + np.arange(1 << 21) % 7, data_type="phase", taus=[1.0, 2.0, 4.0])
    assert calls == [1]  # above the twin's limit: the kernels
