"""The small octave "mo" levels by moving sums by pairs (:mod:`avar._kernels.allan.pyramid`).

Against its plain twin (the compensated sliding window, ``run_sweep(window=True)``), exact
rational arithmetic, and its own error bound; the marked (block, level) pairs redone by the
window; every dtype; thread-count independence.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numba
import numpy as np
import pytest

from avar._kernels.allan import columns, pyramid
from avar._kernels.allan.blocks import read_only

TINY = dict(block=64, near=256, chunk=3, fine=16)  # pyramid blocks of 64, levels 1 .. 128


def octave(n):
    return 2 ** np.arange(0, (n // 2).bit_length(), dtype=np.int64)


def sweep(x, factors, **kw):
    data = np.asarray(x)[:, None]
    return columns.run_sweep(data, factors, data.shape[0] - 2 * factors + 1, **kw)[0]


def exact_mo(x, m):
    """Maximal-overlap AV of integer-valued samples: every ``D`` an exact integer, the
    squares added exactly (``math.fsum``)."""
    s = np.concatenate(([0], np.cumsum(np.asarray(x, dtype=np.int64))))
    d = (s[2 * m :] - 2 * s[m:-m] + s[: -2 * m]).astype(np.float64)
    return math.fsum(d * d) / (2.0 * m * m * d.shape[0])


def series(name, n, rng):
    t = np.arange(n)
    return {
        "white": rng.integers(-1000, 1000, n),
        "offset": rng.integers(-1000, 1000, n) + 10**9,
        "random walk": np.cumsum(rng.integers(-50, 51, n)),
        "drift": 7 * t + rng.integers(-3, 4, n),
        "white PM": np.diff(rng.integers(-1000, 1000, n + 1)),  # D stays small at large m: marked
    }[name]


@pytest.mark.parametrize("name", ["white", "offset", "random walk", "drift", "white PM"])
@pytest.mark.parametrize("n", [257, 640, 3001])
def test_pyramid_matches_its_window_twin_and_exact_sums(name, n):
    x = series(name, n, np.random.default_rng(n)).astype(np.float64)
    factors = octave(n)
    want = [exact_mo(x, int(m)) for m in factors]
    got = sweep(x, factors, **TINY)
    twin = sweep(x, factors, **TINY, window=True)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
    np.testing.assert_allclose(got, twin, rtol=1e-12, atol=0)


def test_default_blocks_match_the_window_on_a_long_series():
    """The default block (2**15) and levels (below 2**13) against the default window path."""
    n = 200_003
    x = np.random.default_rng(3).standard_normal(n) + 5.0
    factors = octave(n)
    got = sweep(x, factors)
    np.testing.assert_allclose(got, sweep(x, factors, window=True), rtol=1e-13, atol=0)
    picks = [1, 2, 1024, 4096]
    exact = []
    v = [Fraction(float(a)) for a in x[:40_000]]
    s = [Fraction(0)]
    for a in v:
        s.append(s[-1] + a)
    for m in picks:  # the exact AV of the first 40 000 samples, against the pyramid on them
        total = sum((s[b + 2 * m] - 2 * s[b + m] + s[b]) ** 2 for b in range(0, 40_000 - 2 * m + 1))
        exact.append(float(total / (2 * m * m * (40_000 - 2 * m + 1))))
    head = sweep(x[:40_000], np.array(picks, dtype=np.int64))
    np.testing.assert_allclose(head, exact, rtol=1e-12, atol=0)


def test_marked_blocks_are_redone_by_the_window(monkeypatch):
    """tol = 0 marks every (block, level): all of them go to the window, and the result is
    still exact; the runs of blocks handed to the window cover exactly the marked pairs and
    are cut at task boundaries (3 blocks here)."""
    n = 3001
    x = series("white", n, np.random.default_rng(8)).astype(np.float64)
    factors = octave(n)
    want = [exact_mo(x, int(m)) for m in factors]
    seen = []
    original = pyramid.marked_sums

    def spy(*args):
        seen.append(args[-1].copy())
        return original(*args)

    monkeypatch.setattr(pyramid, "marked_sums", spy)
    got = sweep(x, factors, **TINY, tol=0.0)
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=0)
    assert seen and seen[-1].shape[2] == np.count_nonzero(factors < TINY["near"])
    assert seen[-1][0].any(axis=0).all()  # every small level went to the window
    runs = pyramid.marked_runs(seen[-1], 3)
    assert all(stop - first <= 3 and first // 3 == (stop - 1) // 3 for _, first, stop, _ in runs)
    covered = np.zeros_like(seen[-1])
    for c, first, stop, levels in runs:
        covered[c, first:stop][:, levels] = True
    np.testing.assert_array_equal(covered, seen[-1])


@pytest.mark.parametrize("dtype", [np.float32, np.int16, np.int64, np.uint8])
def test_pyramid_reads_every_dtype_exactly(dtype):
    n = 1500
    rng = np.random.default_rng(11)
    x = rng.integers(0, 200, n).astype(dtype)
    factors = octave(n)
    want = [exact_mo(x.astype(np.int64), int(m)) for m in factors]
    np.testing.assert_allclose(sweep(x, factors, **TINY), want, rtol=1e-12, atol=0)


def test_each_difference_within_the_certified_bound():
    """The moving sums by pairs of one block, against Fractions: every ``D`` of every level
    within :func:`pyramid.pair_error_bound` (a large offset and a ramp: values far from 0)."""
    rng = np.random.default_rng(5)
    n = 200
    x = 1e7 + 3e-3 * np.arange(n) + rng.standard_normal(n)
    rows = read_only(x[None, :])
    a = np.empty(n)
    big = pyramid.centred_block(rows, 0, 0, n, 1.0, a)
    v = [Fraction(float(t)) for t in x]
    m, depth, valid = 1, 0, n
    b = np.empty(n)
    while 4 * m <= 32:
        count = valid - 3 * m
        for level, size in ((0, m), (1, 2 * m)):  # D of m and 2m, as the pass forms them
            exact = [sum(v[i + size : i + 2 * size]) - sum(v[i : i + size]) for i in range(count)]
            if level == 0:
                got = a[size : size + count] - a[:count]
            else:
                got = (a[2 * m : 2 * m + count] + a[3 * m : 3 * m + count]) - (a[:count] + a[m : m + count])
            bound = pyramid.pair_error_bound(depth + level, size, big)
            worst = max(abs(Fraction(float(g)) - e) for g, e in zip(got, exact))
            assert worst <= bound, (size, float(worst), bound)
        s1, s2 = pyramid.two_levels(a, m, count, count, count, b)
        np.testing.assert_allclose(s1, np.sum((a[m : m + count] - a[:count]) ** 2), rtol=1e-13)
        a, b = b, a
        valid -= 3 * m
        m *= 4
        depth += 2


def test_pyramid_bits_do_not_depend_on_thread_count():
    x = np.random.default_rng(2).standard_normal(5000)
    factors = octave(5000)
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = sweep(x, factors, **TINY)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = sweep(x, factors, **TINY)
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(one, many)
