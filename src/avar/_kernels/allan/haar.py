"""Tau-overlap Allan variance of power-of-two cluster sizes: the Haar pyramid (numba).

The sums of the clusters of size ``2**(k+1)`` are the sums of consecutive
pairs of those of size ``2**k``, so every octave level comes from one read
of the input and N/2 + N/4 + ... additions. The input is read in blocks of
``2**P`` samples (:data:`PYRAMID_EXP`); inside a block the pyramid lives in
a small in-cache buffer, and each level carries only its last cluster sum
from one block to the next. Whole blocks' sums feed the levels above ``P``
(one value per block, kept in a table of N / 2**P entries).

Exactness: every cluster sum is a double-double ``hi + lo`` (TwoSum of the
pairs; 64-bit integers enter as two exact halves), so sums are exact to
O(eps**2) of the cluster magnitude without centring (the differences of
consecutive clusters do not depend on the centre); the difference of two
clusters is formed with TwoSum as well. Samples exact in one float64 (all
but 64-bit integers) skip the pairs at level 0: the difference of two
samples, rounded once, is as exact as the pairs' (:func:`_first_level`), and the
block's magnitude is the maximum of the samples' bit patterns. Blocks are
read from the transposed input, so a single column's block is contiguous
(vectorized loads). Work is split into tasks of
``CHUNK_BLOCKS`` blocks whose partial sums, and the differences across task
boundaries, are added in a fixed order: the bits do not depend on the number
of threads.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, types
from numba.extending import overload

from avar._kernels.dd import fast_sum, two_sum
from avar._kernels.runtime.tasks import run_tasks

#: log2 of the samples per block.
PYRAMID_EXP = 12

#: Blocks per parallel task (fixes the summation order).
CHUNK_BLOCKS = 64


def exact_pair(x, sc):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(exact_pair, inline="always")
def _pair_overload(x, sc):
    """``x * sc`` as an exact pair ``(hi, lo)`` (64-bit integers split in two halves)."""
    if isinstance(x, types.Integer) and x.bitwidth == 64:
        shift = np.uint64(32) if not x.signed else np.int64(32)
        mask = np.uint64(0xFFFFFFFF) if not x.signed else np.int64(0xFFFFFFFF)

        def impl(x, sc):
            return two_sum(np.float64(x >> shift) * 4294967296.0, np.float64(x & mask))

        return impl

    def impl(x, sc):
        return np.float64(x) * sc, 0.0

    return impl


@njit(cache=True, inline="always")
def _dd_add(ah, al, bh, bl):
    s, e = two_sum(ah, bh)
    return s, e + (al + bl)


@njit(cache=True, inline="always")
def _dd_diff(ah, al, bh, bl):
    """``(ah + al) - (bh + bl)`` rounded once to float64 (compensated)."""
    s, e = two_sum(ah, -bh)
    return s + (e + (al - bl))


#: Bits of a float64's magnitude; a magnitude's bits at or above :data:`INFINITY_BITS` are inf or NaN.
MAGNITUDE_MASK = np.int64(0x7FFFFFFFFFFFFFFF)
INFINITY_BITS = np.int64(0x7FF0000000000000)


@njit(cache=True)
def largest_magnitude(values):
    """Largest ``|v|`` of float64 ``values`` (0 if none), inf if one is not finite: the maximum
    of the magnitudes' bit patterns, which are ordered as the magnitudes (integer maxima vectorize)."""
    bits = values.view(np.int64)
    top = np.int64(0)
    for i in range(bits.shape[0]):
        top = max(top, bits[i] & MAGNITUDE_MASK)
    if top >= INFINITY_BITS:
        return np.inf
    return np.array([top]).view(np.float64)[0]


@njit(cache=True)
def _magnitude(x):
    """Largest ``|x|`` of float64 values, NaN if one is not finite (a finite maximum is never inf)."""
    top = largest_magnitude(x)
    return np.nan if top == np.inf else top


def _scaled_magnitude(x, sc):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_scaled_magnitude)
def _scaled_magnitude_overload(x, sc):
    """Largest ``|x sc|`` (``sc`` a power of two), NaN if a sample is not finite."""
    if x.dtype == types.float64:
        return lambda x, sc: _magnitude(x) * sc

    def impl(x, sc):  # narrower types: exact in float64
        top = 0.0
        probe = 0.0
        for i in range(x.shape[0]):
            a = abs(np.float64(x[i]))
            top = a if a > top else top
            probe += 0.0 * a
        return top * sc + probe

    return impl


def _is_wide(x):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_is_wide, inline="always")
def _is_wide_overload(x):
    """Whether samples of this type are not exact in one float64 (64-bit integers)."""
    wide = isinstance(x, types.Integer) and x.bitwidth == 64
    return lambda x: wide


@njit(cache=True, inline="always")
def block_magnitude(x, sc):
    """Largest ``|x sc|`` of a block of samples (not 64-bit integers), NaN if one is not finite."""
    return _scaled_magnitude(x, sc)


@njit(cache=True, inline="always")
def _first_level(x, sc, h, l, buffer):
    """Level 0 of a block of float64-exact samples ``x``: returns the sum of the squared
    differences of consecutive samples (each one rounding: exact up to it) and leaves the
    exact pair sums (level 1) in ``h, l[: count // 2]``."""
    count = x.shape[0]
    for j in range(count - 1):
        d = (np.float64(x[j + 1]) - np.float64(x[j])) * sc
        buffer[j] = d * d
    for j in range(count // 2):
        h[j], l[j] = two_sum(np.float64(x[2 * j]) * sc, np.float64(x[2 * j + 1]) * sc)
    return fast_sum(buffer, count - 1)


@njit(cache=True, inline="always")
def _block(rows, col, start, count, sc, h, l, buffer, levels, first_h, first_l, last_h, last_l, have, sums):
    """Pyramid of one block of ``count`` samples; updates the carried state of levels 0..P.

    ``rows``: the input transposed (C, N), so that a single-column input's block is a
    contiguous row (vectorized loads). Returns the largest magnitude of the block (to
    detect extreme scales; nan if a sample is not finite).
    """
    x = rows[col, start : start + count]
    width = count
    k0 = 0
    if _is_wide(x[0]):  # 64-bit integers: level 0 from exact pairs like the others
        for i in range(count):
            h[i], l[i] = exact_pair(x[i], sc)
        magnitude = _magnitude(h[:count])
    else:
        magnitude = block_magnitude(x, sc)
        if levels > 0:
            total = _first_level(x, sc, h, l, buffer)
            if have[0]:
                d = np.float64(x[0]) * sc - last_h[0]
                total += d * d
            else:
                first_h[0] = np.float64(x[0]) * sc
                first_l[0] = 0.0
                have[0] = True
            sums[0] += total
            last_h[0] = np.float64(x[count - 1]) * sc
            last_l[0] = 0.0
            width = count // 2
            k0 = 1
    for k in range(k0, levels):
        if width == 0:
            break
        for j in range(width - 1):
            buffer[j] = _dd_diff(h[j + 1], l[j + 1], h[j], l[j])
            buffer[j] *= buffer[j]
        total = fast_sum(buffer, width - 1)
        if have[k]:
            d = _dd_diff(h[0], l[0], last_h[k], last_l[k])
            total += d * d
        else:
            first_h[k] = h[0]
            first_l[k] = l[0]
            have[k] = True
        sums[k] += total
        last_h[k] = h[width - 1]
        last_l[k] = l[width - 1]
        half = width // 2
        for j in range(half):
            h[j], l[j] = _dd_add(h[2 * j], l[2 * j], h[2 * j + 1], l[2 * j + 1])
        width = half
    return magnitude


@njit(cache=True, nogil=True)
def _task(rows, col, kb0, kb1, sc, levels, block, sums, first_h, first_l, last_h, last_l, have, bh, bl):
    n = rows.shape[1]
    h = np.empty(block)
    l = np.empty(block)
    buffer = np.empty(block)
    big = 0.0
    finite = True
    for kb in range(kb0, kb1):
        start = kb * block
        count = min(block, n - start)
        r = _block(rows, col, start, count, sc, h, l, buffer, levels, first_h, first_l, last_h, last_l, have, sums)
        finite = finite and np.isfinite(r)
        big = max(big, r)
        if count == block:  # a whole block: its sum feeds the upper levels
            bh[kb] = h[0]
            bl[kb] = l[0]
    return big if finite else np.nan


@njit(cache=True)
def _combine(sums, fh, fl, lh, ll, have, bh, bl, n_full, levels, n_levels):
    """Per-column sums of D**2 of levels 0 .. n_levels - 1, shape (C, n_levels)."""
    channels, n_tasks, _ = sums.shape
    out = np.zeros((channels, n_levels))
    for c in range(channels):
        for k in range(levels):
            total = 0.0
            for j in range(n_tasks):
                total += sums[c, j, k]
                if j > 0 and have[c, j, k] and have[c, j - 1, k]:
                    d = _dd_diff(fh[c, j, k], fl[c, j, k], lh[c, j - 1, k], ll[c, j - 1, k])
                    total += d * d
            out[c, k] = total
        # upper levels: a pyramid over the whole blocks' sums
        h = bh[c, :n_full].copy()
        l = bl[c, :n_full].copy()
        width = n_full
        for k in range(levels, n_levels):
            half = width // 2
            for j in range(half):
                h[j], l[j] = _dd_add(h[2 * j], l[2 * j], h[2 * j + 1], l[2 * j + 1])
            width = half
            total = 0.0
            for j in range(width - 1):
                d = _dd_diff(h[j + 1], l[j + 1], h[j], l[j])
                total += d * d
            out[c, k] = total
    return out


class HaarSums(NamedTuple):
    """:func:`haar_sums`: ``sums`` (C, levels) of squared differences of consecutive cluster sums,
    and ``big`` (C,) the largest magnitude of ``data * scale`` per column (nan when a sample is
    not finite)."""

    sums: np.ndarray
    big: np.ndarray


def haar_sums(data, scale, n_levels, exp=PYRAMID_EXP, chunk=CHUNK_BLOCKS):
    """Sums of squared differences of consecutive cluster sums at m = 2**k, k < ``n_levels``.

    Returns :class:`HaarSums` ``(sums, big)``: shape (C, n_levels), and the largest magnitude of
    ``data * scale`` per column (to rescale extreme data and run again; nan
    when a sample is not finite).
    """
    n, channels = data.shape
    block = 1 << exp
    levels = min(exp + 1, n_levels)
    n_blocks = -(-n // block)
    n_tasks = max(1, -(-n_blocks // chunk))
    shape = (channels, n_tasks, levels)
    sums = np.zeros(shape)
    fh, fl, lh, ll = np.zeros(shape), np.zeros(shape), np.zeros(shape), np.zeros(shape)
    have = np.zeros(shape, dtype=np.bool_)
    bh, bl = np.zeros((channels, n_blocks)), np.zeros((channels, n_blocks))
    big = np.zeros((channels, n_tasks))
    rows = data.T

    def task(t):
        c, j = divmod(t, n_tasks)
        big[c, j] = _task(rows, c, j * chunk, min(n_blocks, (j + 1) * chunk), scale[c], levels, block, sums[c, j],
                          fh[c, j], fl[c, j], lh[c, j], ll[c, j], have[c, j], bh[c], bl[c])

    run_tasks(channels * n_tasks, task)
    out = _combine(sums, fh, fl, lh, ll, have, bh, bl, n // block, levels, n_levels)
    return HaarSums(out, big.max(axis=1))


#: The compiled loop of :func:`haar_sums`, which reads the data's rows (``data.T``): whether it is
#: compiled yet, :func:`avar._kernels.runtime.paths.compiled`.
HAAR_KERNEL = _task
