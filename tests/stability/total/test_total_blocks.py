"""The blocked O(N) expansion of MTOTDEV and HTOTDEV against the direct O(N m) kernel and the exact formula."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import avar
from avar._kernels.runtime import tasks
from avar._kernels.runtime.paths import forced
from avar._kernels.total import windows as total
from avar._kernels.total.blocks import block_size, level_sum, level_tables
from tests._support.powerlaw import powerlaw_phase

NO_GAPS = np.zeros(0, dtype=np.int64)


def direct(values: np.ndarray, m: int) -> float:
    """The direct kernel's level sum (kind 0 and 1 differ only in how gaps are read)."""
    return total._level_serial(0, values, m, NO_GAPS, 0, values.shape[0] - 3 * m + 1)[0]


def exact_level(values: list, m: int) -> Fraction:
    """sum_n (1 / 6m^3) sum_j (A_j - 2 B_j + C_j)^2 over the detrended, reflected windows, exactly."""
    span, half = 3 * m, 3 * m // 2
    total_sum = Fraction(0)
    for n in range(len(values) - span + 1):
        w = values[n : n + span]
        slope = (sum(w[span - half :]) - sum(w[:half])) / half / (span - half)
        w = [w[k] - slope * k for k in range(span)]
        star = w[::-1] + w + w[::-1]
        for j in range(6 * m):
            total_sum += (sum(star[j : j + m]) - 2 * sum(star[j + m : j + 2 * m]) + sum(star[j + 2 * m : j + 3 * m])) ** 2
    return total_sum / (6 * m**3)


#: Phase of white PM, flicker PM, flicker FM and random-walk FM (FFT-filtered white noise), and
#: their frequencies (HTOTDEV's values).
N = 3000
SERIES = {alpha: powerlaw_phase(N, alpha, seed=40 + alpha) for alpha in (2, 1, -1, -2)}


@pytest.mark.parametrize("m", [1, 2, 3, 4, 7, 8, 33, 120, 333, 999, 1000])
@pytest.mark.parametrize("alpha", [2, 1, -1, -2])
def test_equals_the_direct_kernel(m, alpha):
    """MTOTDEV (phase) and HTOTDEV (frequency) levels, odd and even 3m, up to m = N / 3; the last
    block is short unless the number of windows is a multiple of the block size."""
    for values in (SERIES[alpha], np.diff(SERIES[alpha])):
        if 3 * m > values.size:
            continue
        assert level_sum(values, m) == pytest.approx(direct(values, m), rel=1e-11)


def test_long_series_several_blocks_per_level():
    x = powerlaw_phase(20000, -2, seed=3)
    for m in (5, 64, 700):
        assert (x.size - 3 * m + 1) > 4 * block_size(m)
        assert level_sum(x, m) == pytest.approx(direct(x, m), rel=1e-11)


def test_equals_the_exact_formula():
    x = np.cumsum(np.random.default_rng(5).standard_normal(50))
    for m in (1, 2, 5):
        assert level_sum(x, m) == pytest.approx(float(exact_level([Fraction(float(v)) for v in x], m)), rel=1e-12)


def test_blind_to_a_line_and_to_the_thread_count(monkeypatch):
    x = SERIES[-1]
    shifted = x + 3.0 - 0.01 * np.arange(N)
    assert level_sum(shifted, 40) == pytest.approx(level_sum(x, 40), rel=1e-10)
    sums = []
    for count in (1, 3):
        monkeypatch.setattr(tasks, "threads", lambda count=count: count)
        sums.append(level_sum(x, 7))
    assert sums[0] == sums[1]  # each block's sum has its own slot, added in order


def test_tables_are_exact_integers():
    for m in (1, 4, 33, 1 << 18):
        same, pairs, cross, points, square = level_tables(m)
        assert same[:, 0].max() <= 2 and np.all(pairs == np.round(pairs))
        for table in (cross, points, square):
            assert np.all(table * 4 == np.round(table * 4))  # halves and quarters of integers


def test_levels_choose_their_path(monkeypatch):
    """Levels with enough (clean) windows take the expansion, small ones the direct kernel."""
    calls = []
    monkeypatch.setattr(total, "level_sum", lambda values, m, clean=None: calls.append((m, clean is None)) or 0.0)
    x = SERIES[-1]
    assert (N - 2) * (1 + 10) > total.FAST_WORK  # m = 1 at N = 3000: just above the switch-over
    total.level_sums(0, x, np.array([1, 64]), NO_GAPS, 0)
    total.level_sums(1, x[:40], np.array([2]), NO_GAPS, 0)  # below it: too small to pay for the tables
    assert calls == [(1, True), (64, True)]
    holed = x.copy()
    holed[100] = np.nan
    with forced("compiled"):  # (a cold process would take the NumPy twin: avar.stability.total.small)
        res = avar.mtotdev(holed, data_type="phase", taus=[64.0], nan_policy="omit")
    assert calls[2:] == [(64, False)] and res.n[0] == N - 3 * 64 + 1 - 101  # windows 0 .. 100 touch it


def prefix_count(missing: np.ndarray) -> np.ndarray:
    return np.concatenate(([0], np.cumsum(missing))).astype(np.int64)


@pytest.mark.parametrize("shift", [0, 1])
@pytest.mark.parametrize("kind", [0, 1])
def test_gaps_run_the_blocks_over_the_clean_stretches(monkeypatch, kind, shift):
    """Windows touching a gap are skipped: the expansion over each run of clean windows (the gaps
    themselves NaN, so that reading one would show) equals the direct kernel's skipping loop."""
    rng = np.random.default_rng(kind + 2 * shift)
    x = SERIES[-2].copy()
    missing = np.zeros(N - shift, dtype=bool)  # phase points (shift 0) or frequency samples (shift 1)
    missing[[5, 6, 700, 1500, 1510]] = True
    missing[rng.integers(2000, N - shift, 3)] = True
    bad = prefix_count(missing)
    x[np.flatnonzero(missing) + shift] = np.nan
    factors = np.array([1, 2, 5, 16, 33, 150, 250])  # 3m = 750 fits between the gaps at 700 and 1500
    fast = total.level_sums(kind, x, factors, bad, shift)
    monkeypatch.setattr(total, "FAST_WORK", 1 << 62)
    slow = total.level_sums(kind, x, factors, bad, shift)
    assert fast[1].tolist() == slow[1].tolist() and slow[1][-1] > 0
    np.testing.assert_allclose(fast[0], slow[0], rtol=1e-11)


def test_block_lists_cover_the_clean_windows():
    from avar._kernels.total.blocks import blocks

    clean = np.array([1, 1, 1, 1, 1, 0, 0, 1, 0, 1, 1, 1, 1, 1, 1, 1], dtype=bool)
    starts, counts = blocks(clean.size, 3, clean)
    assert starts.tolist() == [0, 3, 7, 9, 12, 15] and counts.tolist() == [3, 2, 1, 3, 3, 1]
    starts, counts = blocks(7, 3)
    assert starts.tolist() == [0, 3, 6] and counts.tolist() == [3, 3, 1]
