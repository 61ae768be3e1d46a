"""The octave "mo" schedule (issue 39): the far levels in groups of ``FAR_SPAN`` (32, a ring
that stays in L2) against the former single group (span 512) and a plain loop, on sizes that
cross the tiles (sweep blocks, far pieces, groups) by one sample either way."""

from __future__ import annotations

import math

import numpy as np
import pytest

from avar._kernels.allan import columns
from avar._kernels.allan.far import FAR_SPAN

OLD_SPAN = 1 << 9
TINY = dict(block=64, near=256, chunk=3, fine=16)  # tile = sweep block 64, far piece 16


def octave(n):
    return 2 ** np.arange(0, (n // 2).bit_length(), dtype=np.int64)


def sweep(x, factors, **kw):
    data = x[:, None]
    return columns.run_sweep(data, factors, x.shape[0] - 2 * factors + 1, **kw)[0]


def series(n, dtype, seed=0):
    """White noise on a random walk and an offset, in steps of 2**-10 (exact in float32 too)."""
    rng = np.random.default_rng(seed)
    k = rng.integers(-1 << 12, 1 << 12, n) + np.cumsum(rng.integers(-8, 9, n)) + 3 * 1024
    return (k / 1024.0).astype(dtype)


def exact_mo(x, m):
    """Maximal-overlap AV of samples that are multiples of 2**-10: every ``D`` an exact integer
    (int64 cumulative sums), each square rounded once and added exactly (``math.fsum``)."""
    k = np.rint(np.asarray(x, dtype=np.float64) * 1024.0).astype(np.int64)
    s = np.concatenate(([0], np.cumsum(k)))
    d = (s[2 * m :] - 2 * s[m:-m] + s[: -2 * m]).astype(np.float64)
    return math.fsum(d * d) / (1024.0 * 1024.0) / (2.0 * m * m * d.shape[0])


def test_default_span_keeps_the_ring_in_l2():
    assert FAR_SPAN == 32
    assert (2 * FAR_SPAN + 2) * 1024 * 8 <= 1 << 20  # pieces of 1024 float64


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("n", [63, 64, 65, 5 * 64 + 3, 1023, 1024, 1025, 4095, 4097, 8191])
def test_grouped_far_levels_match_the_single_group_and_the_loop(n, dtype, monkeypatch):
    x = series(n, dtype, seed=n)
    factors = octave(n)
    want = [exact_mo(x, int(m)) for m in factors]
    old = sweep(x, factors, **TINY, span=OLD_SPAN)
    for tail in (0, columns.FAR_TAIL):  # 0: no short last group merged
        monkeypatch.setattr(columns, "FAR_TAIL", tail)
        for span in (2, 4, FAR_SPAN):  # levels 256 .. n/2 in groups of 1, 2, 3 or all
            got = sweep(x, factors, **TINY, span=span)
            np.testing.assert_allclose(got, old, rtol=1e-13, atol=0, err_msg=f"span={span}, tail={tail}")
            np.testing.assert_allclose(got, want, rtol=1e-11, atol=0, err_msg=f"span={span}, tail={tail}")


def test_a_short_last_group_joins_the_one_before(monkeypatch):
    calls = []
    far_sums = columns.far_sums
    monkeypatch.setattr(columns, "far_sums", lambda *a, **k: calls.append(a[6].tolist()) or far_sums(*a, **k))
    cases = [  # (n, factors, span, groups)
        (17000, octave(17000), 4, [[256, 512, 1024], [2048, 4096, 8192]]),  # a last group of three: its own
        (9000, octave(9000), 4, [[256, 512, 1024, 2048, 4096]]),  # of two, 4096 <= 4 * 4 * 256: joins
        (9000, np.array([1, 2, 256, 512, 1024, 4096]), 2, [[256, 512], [1024, 4096]]),  # 4096 > 2 * 4 * 256
    ]
    for n, factors, span, groups in cases:
        calls.clear()
        x = series(n, np.float64)
        got = sweep(x, factors.astype(np.int64), **TINY, span=span)
        assert calls == groups
        np.testing.assert_allclose(got, [exact_mo(x, int(m)) for m in factors], rtol=1e-11, atol=0)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_levels_near_a_quarter_tile_and_odd_lengths(dtype):
    """Levels m = tile / 8 .. tile / 2 (block 64: m = 8 .. 32) and the first far levels, odd n."""
    for n in (641, 1001, 3333):
        x = series(n, dtype, seed=1)
        factors = np.array([8, 16, 32, 64, 256, 512], dtype=np.int64)
        factors = factors[2 * factors < n]
        got = sweep(x, factors, **TINY, span=2)
        np.testing.assert_allclose(got, [exact_mo(x, int(m)) for m in factors], rtol=1e-11, atol=0)
        np.testing.assert_allclose(got, sweep(x, factors, **TINY, span=OLD_SPAN), rtol=1e-13, atol=0)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_default_tiles_two_groups_against_one(dtype):
    """Default blocks (8192), near (32768) and pieces (1024), odd n = 2**18 + 1: the far levels
    32768 .. 131072 make one group at the default span; span 2 splits them in two."""
    n = (1 << 18) + 1
    x = series(n, dtype, seed=5)
    factors = octave(n)
    default = sweep(x, factors)
    np.testing.assert_allclose(default, sweep(x, factors, span=2), rtol=1e-13, atol=0)
    np.testing.assert_allclose(default, sweep(x, factors, span=OLD_SPAN), rtol=1e-13, atol=0)
    np.testing.assert_allclose(default, [exact_mo(x, int(m)) for m in factors], rtol=1e-11, atol=0)


@pytest.mark.parametrize("position", [0, 16 * 40 - 1, 16 * 40, 2999])
def test_a_nan_gives_the_same_non_finite_levels_in_any_grouping(position):
    x = series(3000, np.float64)
    x[position] = np.nan
    factors = octave(3000)
    old = np.isfinite(sweep(x, factors, **TINY, span=OLD_SPAN))
    for span in (2, FAR_SPAN):
        np.testing.assert_array_equal(np.isfinite(sweep(x, factors, **TINY, span=span)), old)
    assert not old.any()  # a NaN makes the centre, and so every level, non-finite
