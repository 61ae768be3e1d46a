"""Theo1's expansion without a compiler (:mod:`avar._kernels.total.theo1_numpy`): the twins of its
kernels give the kernels' bits, and a cold Theo1 of a long record the warm one's sums."""

from __future__ import annotations

import numpy as np
import pytest

from avar._kernels.runtime.paths import forced
from avar._kernels.total import theo1_numpy
from avar._kernels.total.fft import _hankel_leaves, autocorrelation, phi_sums
from avar._kernels.total.theo1 import DIRECT_TERMS, _end_autocorrelation, _plain_parts, _weighted_lags, theo1_sums
from avar._kernels.total.windows import theo1_sum
from avar.stability.total import small

RNG = np.random.default_rng(43)
NO_GAPS = np.zeros(0, dtype=np.int64)


def records(n: int) -> dict[str, np.ndarray]:
    white = RNG.standard_normal(n)
    walk = np.cumsum(np.cumsum(RNG.standard_normal(n)))
    walk -= np.polyval(np.polyfit(np.arange(n), walk, 1), np.arange(n))
    return {"white PM": white, "random-walk FM": walk, "offset": white + 1e6}


@pytest.mark.parametrize("name", ["white PM", "random-walk FM", "offset"])
def test_plain_parts_and_weighted_lags_are_the_kernels_bit_for_bit(name):
    x = records(3000)[name]
    reverse = np.ascontiguousarray(x[::-1])
    squares = np.concatenate(([0.0], np.cumsum(x * x)))
    autocorr = autocorrelation(x)
    phi, phi_reverse = phi_sums(x, 1201), phi_sums(reverse, 1201)
    for m in (2, 4, 10, 64, 500, 2400):
        args = (x, reverse, squares, autocorr, phi, phi_reverse, m)
        assert theo1_numpy.plain_parts(*args) == _plain_parts(*args)
        ends = (_end_autocorrelation(x, reverse, m), _end_autocorrelation(x, reverse, m // 2), m)
        assert theo1_numpy.weighted_lags(*ends) == _weighted_lags(*ends)


@pytest.mark.parametrize("leaf", [64, 75, 128])
def test_hankel_leaves_are_the_kernels_bit_for_bit(leaf):
    y = RNG.standard_normal(40 * leaf)  # (several passes of LEAF_CHUNK products)
    kappa = 1.0 / (np.arange(3 * y.size) + 1.0)
    before = RNG.standard_normal(y.size)  # the leaves add into what ``out`` holds
    expected, twin = before.copy(), before.copy()
    _hankel_leaves(y, kappa, expected, leaf)
    theo1_numpy.hankel_leaves(y, kappa, twin, leaf)
    assert np.array_equal(twin, expected)
    for g in (1, leaf - 1, leaf + 5):  # out[g] += sum_{start <= i < g} y[i] kappa[g + i], start its leaf's
        start = leaf * (g // leaf)
        plain = sum(y[i] * kappa[g + i] for i in range(start, g))
        assert twin[g] - before[g] == pytest.approx(plain, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("name", ["white PM", "random-walk FM"])
def test_a_cold_theo1_of_long_levels_sums_as_the_warm_one(name):
    """Long levels (expansion) and short ones (direct), each path forced: the expanded levels to the
    bit, the direct ones (NumPy's dot products) to 1e-12, and both to the direct kernel."""
    x = records(8000)[name]
    factors = np.array([2, 64, 1024, 4096])
    assert (8000 - 4096) * 2048 > DIRECT_TERMS  # (the largest level takes the expansion)
    with forced("numpy"):
        cold = theo1_sums(x, factors, small.theo1_direct(NO_GAPS, 0))
    with forced("compiled"):
        warm = theo1_sums(x, factors, small.theo1_direct(NO_GAPS, 0))
    assert cold.n_expanded == warm.n_expanded >= 1
    expanded = (8000 - factors) * (factors // 2) > DIRECT_TERMS
    assert np.array_equal(cold.sums[expanded], warm.sums[expanded])
    np.testing.assert_allclose(cold.sums, warm.sums, rtol=1e-12, atol=0)
    direct = [theo1_sum(x, int(m), NO_GAPS, 0).total for m in factors]
    np.testing.assert_allclose(cold.sums, direct, rtol=1e-9, atol=0)
