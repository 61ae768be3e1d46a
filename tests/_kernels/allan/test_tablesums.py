"""The table pass's float32 block sums: plain only where provably exact, against exact rationals."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from avar._kernels.allan.blocks import block_table
from avar._kernels.allan.tablesums import block_sum, float32_block_sum


def run(x):
    """:func:`float32_block_sum` of a float32 vector, read as the table pass reads it (a row of the
    transposed (N, 1) input and its bit patterns)."""
    rows = np.ascontiguousarray(x, dtype=np.float32)[None, :]
    return float32_block_sum(rows[0], rows.view(np.int32)[0])


def exact_sum(x):
    return sum((Fraction(float(v)) for v in np.asarray(x, dtype=np.float32)), Fraction(0))


def blocks_of(rng):
    """Float32 blocks of 1024 samples: white noise, offsets, a wide range of exponents, zeros,
    subnormals and a negative zero."""
    white = rng.standard_normal(1024).astype(np.float32)
    offset = (1e4 + rng.standard_normal(1024)).astype(np.float32)
    wide = (rng.standard_normal(1024) * 2.0 ** rng.integers(-40, 40, 1024)).astype(np.float32)
    sparse = np.zeros(1024, np.float32)
    sparse[::97] = rng.standard_normal(sparse[::97].shape[0])
    subnormal = (rng.integers(-2000, 2000, 1024) * 2.0**-149).astype(np.float32)
    signed_zero = np.full(1024, -0.0, np.float32)
    tiny_one = white.copy()
    tiny_one[500] = np.float32(3e-30)  # one sample far below the others: not exact in a plain sum
    return {"white": white, "offset": offset, "wide": wide, "sparse": sparse, "subnormal": subnormal,
            "signed zero": signed_zero, "tiny one": tiny_one}


@pytest.mark.parametrize("name", ["white", "offset", "wide", "sparse", "subnormal", "signed zero", "tiny one"])
def test_exact_flag_is_never_wrong_and_extremes_are_the_samples(name):
    x = blocks_of(np.random.default_rng(7))[name]
    total, least, largest, exact = run(x)
    truth = exact_sum(x)
    if exact:
        assert Fraction(total) == truth
        assert least == float(x.min()) and largest == float(x.max())
    # The condition, evaluated independently: count * max|x| <= 2**53 * ulp32(smallest non-zero |x|).
    nonzero = np.abs(x[x != 0]).astype(np.float64)
    if nonzero.size == 0:
        expected = True
    else:
        grain = max(float(np.spacing(np.float32(nonzero.min()))), 2.0**-149)
        expected = x.shape[0] * nonzero.max() <= 2.0**53 * grain
    assert exact == expected
    assert exact == (name not in ("wide", "tiny one"))  # the two blocks built to fail do


def test_not_finite_samples_are_never_exact():
    x = np.ones(64, np.float32)
    for bad in (np.inf, -np.inf, np.nan):
        x[10] = bad
        assert not run(x)[3]


def test_float32_table_matches_the_compensated_table_and_exact_sums():
    rng = np.random.default_rng(11)
    parts = list(blocks_of(rng).values())
    x = np.concatenate(parts + [rng.standard_normal(1500).astype(np.float32)])[:, None]
    x.flags.writeable = False
    fast = block_table(x, np.ones(1), False, 1024)
    wide = x.astype(np.float64)  # the same values: the compensated path of every block
    slow = block_table(wide, np.ones(1), False, 1024)
    np.testing.assert_array_equal(fast.centre, slow.centre)
    np.testing.assert_array_equal(fast.maxabs, slow.maxabs)
    np.testing.assert_array_equal(fast.spread, slow.spread)
    s = Fraction(0)
    centre = Fraction(float(fast.centre[0]))
    for k in range(fast.table_hi.shape[1]):
        if k:
            s += exact_sum(x[(k - 1) * 1024 : k * 1024, 0])
        p = min(k * 1024, x.shape[0])
        want = s - p * centre
        got = Fraction(float(fast.table_hi[0, k])) + Fraction(float(fast.table_lo[0, k]))
        assert abs(float(got - want)) <= 2.0**-100 * float(abs(s) + p * abs(centre)) + 1e-300


def test_block_sum_is_compensated():
    x = np.array([1e16, 1.0, -1e16, 1.0, 3.0], dtype=np.float64)[:, None]
    total, comp, least, largest = block_sum(x, 0, 0, 5, 1.0)
    assert total + comp == 5.0 and (least, largest) == (-1e16, 1e16)
