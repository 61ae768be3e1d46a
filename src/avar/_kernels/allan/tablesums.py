"""The block sums of the table pass (numba): compensated, or plain where provably exact (float32).

:func:`avar._kernels.allan.blocks.block_table` sums every block of the series (and finds its
least and largest value). :func:`block_sum` does it for any dtype with four interleaved TwoSum
lanes (about 1.25 ns a sample). For float32 samples (scale 1) the table pass runs
:func:`float32_table_task` instead, which first tries :func:`float32_block_sum`: a plain float64
sum (vectorized) that is *exact* whenever the block's magnitudes are close enough, and its
extremes from the bit patterns (integer maxima vectorize); :func:`block_sum` otherwise.

Why exact: every float32 of magnitude at least ``s`` (the block's smallest non-zero magnitude)
is an integer multiple of ``g = ulp32(s)``, and so is every partial sum of the block's samples,
in any association. A partial sum of ``count`` samples is at most ``count r`` in magnitude (``r``
the largest); when ``count r <= 2**53 g`` every one is a float64, so no addition rounds. White
noise passes (its smallest magnitude in a block of 1024 is rarely below ``2**-18`` of its largest);
a block that fails, or holds a non-finite sample, takes the compensated path.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from avar._kernels.allan.haar import exact_pair
from avar._kernels.dd import fast_two_sum, two_sum


class BlockSum(NamedTuple):
    """A block's sum ``total + compensation`` and its ``least`` and ``largest`` value (built inside
    compiled kernels too: numba types a NamedTuple as a tuple)."""

    total: float
    compensation: float
    least: float
    largest: float


@njit(cache=True)
def block_sum(data, col, start, stop, scale):
    """Compensated sum of ``data[start:stop, col] * scale`` and its least and largest value
    (of the high parts, for 64-bit integers), in four interleaved lanes: independent TwoSum
    chains that the CPU overlaps (one chain waits for each addition; 1.9 against 1.25 ns a
    sample), combined by TwoSum at the end: a :class:`BlockSum`."""
    x = data[start:stop, col]
    count = stop - start
    t0 = t1 = t2 = t3 = c0 = c1 = c2 = c3 = 0.0
    lo0 = lo1 = lo2 = lo3 = np.inf
    hi0 = hi1 = hi2 = hi3 = -np.inf
    for j in range(count // 4):
        h0, l0 = exact_pair(x[4 * j], scale)
        h1, l1 = exact_pair(x[4 * j + 1], scale)
        h2, l2 = exact_pair(x[4 * j + 2], scale)
        h3, l3 = exact_pair(x[4 * j + 3], scale)
        t0, e0 = two_sum(t0, h0)
        t1, e1 = two_sum(t1, h1)
        t2, e2 = two_sum(t2, h2)
        t3, e3 = two_sum(t3, h3)
        c0 += e0 + l0
        c1 += e1 + l1
        c2 += e2 + l2
        c3 += e3 + l3
        lo0, lo1, lo2, lo3 = min(lo0, h0), min(lo1, h1), min(lo2, h2), min(lo3, h3)
        hi0, hi1, hi2, hi3 = max(hi0, h0), max(hi1, h1), max(hi2, h2), max(hi3, h3)
    for i in range(4 * (count // 4), count):
        h0, l0 = exact_pair(x[i], scale)
        t0, e0 = two_sum(t0, h0)
        c0 += e0 + l0
        lo0 = min(lo0, h0)
        hi0 = max(hi0, h0)
    a, ea = two_sum(t0, t1)
    b, eb = two_sum(t2, t3)
    total, e = two_sum(a, b)
    return BlockSum(total, ((c0 + c1) + (c2 + c3)) + ((ea + eb) + e), min(min(lo0, lo1), min(lo2, lo3)),
                    max(max(hi0, hi1), max(hi2, hi3)))


@njit(cache=True, fastmath={"reassoc", "contract"})
def _plain_sum(x):
    """Plain float64 sum of float32 ``x`` in any association (vectorized): exact under the
    condition of :func:`float32_block_sum`, which holds for every association."""
    total = 0.0
    for i in range(x.shape[0]):
        total += np.float64(x[i])
    return total


@njit(cache=True)
def _keys(bits):
    """Least and largest order key (``b ^ ((b >> 31) & 0x7FFFFFFF)``, ordered as the float32
    values) and least ``magnitude bits - 1`` that is not negative (of the smallest non-zero
    magnitude), of the float32 bit patterns ``bits``: integer selects, which vectorize."""
    mask = np.int32(0x7FFFFFFF)
    lo = mask
    hi = -mask
    small = mask
    for i in range(bits.shape[0]):
        v = bits[i]
        k = v ^ ((v >> np.int32(31)) & mask)
        lo = k if k < lo else lo
        hi = k if k > hi else hi
        a = (v & mask) - np.int32(1)
        a = a if a >= np.int32(0) else mask
        small = a if a < small else small
    return lo, hi, small


@njit(cache=True, inline="always")
def _magnitude(bits):
    """The float32 magnitude of the bit pattern ``bits`` (0 <= bits < 0x7F800000), as float64."""
    exponent = bits >> 23
    fraction = np.float64(bits & 0x7FFFFF)
    if exponent == 0:
        return math.ldexp(fraction, -149)
    return math.ldexp(fraction + 8388608.0, exponent - 150)


@njit(cache=True, inline="always")
def _value(key):
    """The float32 value of an order key of :func:`_keys`, as float64."""
    return -_magnitude((key ^ 0x7FFFFFFF) & 0x7FFFFFFF) if key < 0 else _magnitude(key)


@njit(cache=True)
def float32_block_sum(x, bits):
    """``(total, least, largest, exact)`` of float32 ``x`` (``bits``: the same samples viewed as
    int32): ``total`` the plain float64 sum, ``exact`` whether it is provably the exact sum (see
    the module: ``count r <= 2**53 ulp32(s)``); ``least, largest`` only when exact."""
    total = _plain_sum(x)
    if not np.isfinite(total):  # a finite total: every sample finite
        return total, 0.0, 0.0, False
    lo_key, hi_key, small = _keys(bits)
    lo = _value(lo_key)
    hi = _value(hi_key)
    if small == 0x7FFFFFFF:  # every sample zero
        return 0.0, lo, hi, True
    exponent = (small + 1) >> 23  # of the smallest non-zero magnitude: its ulp32 is 2**(exponent - 150)
    grain = math.ldexp(1.0, max(exponent, 1) - 150)
    return total, lo, hi, x.shape[0] * max(-lo, hi) <= 9007199254740992.0 * grain


@njit(cache=True, nogil=True)
def float32_table_task(data, rows, bits, col, b0, b1, block, ph, pl, low, high):
    """:func:`avar._kernels.allan.blocks.table_task` of float32 samples at scale 1 (``rows``:
    ``data.T``, ``bits``: ``rows`` viewed as int32; a column's block of them is contiguous, and
    the loops vectorize, 0.3 ns a sample): each block's plain sum where :func:`float32_block_sum`
    proves it exact (a zero compensation), else :func:`block_sum`."""
    n = data.shape[0]
    h = 0.0
    lo = 0.0
    for b in range(b0, b1):
        start, stop = b * block, min(n, (b + 1) * block)
        total, low[col, b], high[col, b], exact = float32_block_sum(rows[col, start:stop], bits[col, start:stop])
        comp = 0.0
        if not exact:
            total, comp, low[col, b], high[col, b] = block_sum(data, col, start, stop, 1.0)
        s, e = two_sum(h, total)
        e += lo + comp
        h, lo = fast_two_sum(s, e)
        ph[col, b] = h
        pl[col, b] = lo
