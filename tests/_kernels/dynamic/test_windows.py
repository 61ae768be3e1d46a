"""The dynamic deviations' window kernel against a plain loop over every window's terms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from avar._kernels.dynamic.windows import REACH, window_sums
from avar.stability.dynamic import small

ORDER = {0: (1, -2, 1), 1: (-1, 3, -3, 1), 2: (-1, 3, -3, 1), 4: (1, -4, 6, -4, 1)}


def twin_sums(hi, lo, code, m, stride, starts, count, mode, bad, sums, counts):
    """The NumPy twin (:mod:`avar.stability.dynamic.small`) with the kernel's signature."""
    sums[:], counts[:] = small.window_sums(hi, lo, code, m, stride, starts, count, mode, bad)


#: The compiled kernel and its NumPy twin: each is checked against the plain loops.
IMPLEMENTATIONS = pytest.mark.parametrize("implementation", [window_sums, twin_sums], ids=["kernel", "twin"])


def plain_window(p, code, m, stride, start, count, missing, mode):
    """A window's sum of squared terms and its terms used, term by term (math.fsum).

    ``missing``: the missing phase points (mode 1) or frequency values (mode 2)."""
    reach = REACH[code] * m
    squares, used = [], 0
    for k in range(count):
        b = start + k * stride
        if mode == 1:
            points = range(b, b + reach) if code >= 2 else range(b, b + reach + 1, m)
            ok = not any(missing[q] for q in points)
        elif mode == 2:
            last = b + reach if code < 2 else b + reach - 1
            ok = not missing[b:last].any()
        else:
            ok = True
        if ok:
            d = sum(c * p[b + j * m] for j, c in enumerate(ORDER[code]))
            squares.append(d * d)
            used += 1
    return math.fsum(squares), used


@IMPLEMENTATIONS
@pytest.mark.parametrize("code", [0, 1, 2, 4])
@pytest.mark.parametrize("mode", [0, 1, 2])
def test_window_sums_match_plain_loops(code, mode, implementation):
    rng = np.random.default_rng(code + 10 * mode)
    n = 600
    p = np.cumsum(rng.standard_normal(n)) + 1e3  # an offset far above the increments
    hi = p.copy()
    lo = np.zeros(n, dtype=np.float32)
    missing = np.zeros(n, dtype=bool)
    if mode:
        missing[rng.choice(n - 1, 8, replace=False)] = True
    bad = np.concatenate(([0], np.cumsum(missing))).astype(np.int64)
    window = 150
    starts = np.arange(0, n - window, 37, dtype=np.int64)
    for m in (1, 3, 10):
        for stride in (1, m):
            count_all = (window - REACH[code] * m - 1) // stride + 1
            sums = np.empty(starts.size)
            counts = np.empty(starts.size, dtype=np.int64)
            implementation(hi, lo, code, m, stride, starts, count_all, mode, bad, sums, counts)
            for w, start in enumerate(starts.tolist()):
                expected, used = plain_window(p, code, m, stride, start, count_all, missing, mode)
                assert counts[w] == used
                assert sums[w] == pytest.approx(expected, rel=1e-9, abs=1e-9 * expected + 1e-300)


@IMPLEMENTATIONS
def test_a_windows_sum_is_accurate_relative_to_the_window(implementation):
    """Early terms 1e16 times the window's (a burst of 1e6 in phase noise of 1e-2): a plain prefix sum
    would leave nothing of the window's sum; the compensated one keeps it to ~1e-12."""
    rng = np.random.default_rng(5)
    p = rng.standard_normal(3000) * 1e-2
    p[100:200] += rng.standard_normal(100) * 1e6
    lo = np.zeros(p.size, dtype=np.float32)
    starts = np.array([1000, 2000], dtype=np.int64)
    sums, counts = np.empty(2), np.empty(2, dtype=np.int64)
    implementation(p, lo, 0, 2, 1, starts, 500, 0, np.zeros(1, dtype=np.int64), sums, counts)
    for w, start in enumerate(starts.tolist()):
        expected, used = plain_window(p, 0, 2, 1, start, 500, None, 0)
        assert counts[w] == used == 500
        assert sums[w] == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("code", [0, 1, 2, 4])
def test_the_twin_equals_the_kernel_with_float32_low_parts(code):
    """Both paths on the same phase split into hi + lo (lo float32, as the classic core builds it):
    the terms are the kernel's bit for bit, the window sums agree to 1e-13."""
    rng = np.random.default_rng(20 + code)
    p = np.cumsum(np.cumsum(rng.standard_normal(4000))) * 1e-3 + 1e6
    hi = p.copy()
    lo = (rng.standard_normal(p.size) * 1e-11).astype(np.float32)
    missing = np.zeros(p.size, dtype=bool)
    missing[rng.choice(p.size - 1, 5, replace=False)] = True
    bad = np.concatenate(([0], np.cumsum(missing))).astype(np.int64)
    starts = np.arange(0, 3000, 250, dtype=np.int64)
    for mode in (0, 1, 2):
        for m in (1, 7, 64):
            for stride in (1, m):
                count = (1000 - REACH[code] * m - 1) // stride + 1
                sums, counts = np.empty(starts.size), np.empty(starts.size, dtype=np.int64)
                window_sums(hi, lo, code, m, stride, starts, count, mode, bad, sums, counts)
                twin = small.window_sums(hi, lo, code, m, stride, starts, count, mode, bad)
                np.testing.assert_array_equal(twin.counts, counts)
                np.testing.assert_allclose(twin.sums, sums, rtol=1e-13, atol=0)


def test_the_twin_refuses_uneven_starts_and_windows_past_the_record():
    hi, lo, bad = np.zeros(50), np.zeros(50, dtype=np.float32), np.zeros(1, dtype=np.int64)
    with pytest.raises(ValueError, match="starts must be evenly spaced"):
        small.window_sums(hi, lo, 0, 1, 1, np.array([0, 1, 5]), 10, 0, bad)
    with pytest.raises(ValueError, match="reach past the record's 48 terms"):
        small.window_sums(hi, lo, 0, 1, 1, np.array([0, 40]), 10, 0, bad)
