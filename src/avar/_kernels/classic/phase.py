"""The detrended phase of the deviation family as a double-double (numba).

See :mod:`avar._kernels.classic.levels` for how the kernels use it: the phase is
rebuilt from its increments (the fractional frequency, or the first
differences of phase data, each an exact pair by Knuth's TwoSum) minus a line
``centre + slope i`` (removed exactly: ``slope i`` is exact by construction),
by a compensated running sum ``hi + lo``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from avar._kernels.classic.sums import CUMSUM_BLOCK
from avar._kernels.dd import two_sum
from avar._kernels.runtime.paths import numpy_path
from avar._kernels.runtime.tasks import run_tasks


class Scanned(NamedTuple):
    """One pass over the data (:func:`scan`)."""

    n_missing: int
    total: float
    low: float
    high: float
    moment: float


@njit(cache=True)
def _scan_block(data, start, stop):
    """NaN count, sum, min and max of ``data[start:stop]`` (the sum over the non-NaN values)."""
    count = 0
    total = 0.0
    low = np.inf
    high = -np.inf
    for i in range(start, stop):
        v = data[i]
        if np.isnan(v):
            count += 1
        else:
            total += v
            low = min(low, v)
            high = max(high, v)
    return count, total, low, high


@njit(cache=True, fastmath={"reassoc"})
def _scan_block_fast(data, start, stop, weigh):
    """:func:`_scan_block` without branches, four values at a time (independent chains), exact
    when the block has no NaN: a comparison with NaN is false, so NaN never becomes the
    min or max, but it poisons the sum; the caller rescans such a block. With ``weigh``,
    also ``sum_i i data[start + i]`` (the block's index-weighted sum; 0.0 otherwise)."""
    count = 0
    total = 0.0
    weighted = 0.0
    l0 = l1 = l2 = l3 = np.inf
    h0 = h1 = h2 = h3 = -np.inf
    values = data[start:stop]  # indices from 0: no negative-index checks in the loop
    n4 = values.shape[0] // 4 * 4
    for i in range(0, n4, 4):
        a, b, c, d = values[i], values[i + 1], values[i + 2], values[i + 3]
        total += (a + b) + (c + d)
        if weigh:  # i a + (i + 1) b + (i + 2) c + (i + 3) d
            weighted += np.float64(i) * ((a + b) + (c + d)) + ((b + d) + 2.0 * (c + d))
        count += (a != a) + (b != b) + (c != c) + (d != d)
        l0, l1, l2, l3 = a if a < l0 else l0, b if b < l1 else l1, c if c < l2 else l2, d if d < l3 else l3
        h0, h1, h2, h3 = a if a > h0 else h0, b if b > h1 else h1, c if c > h2 else h2, d if d > h3 else h3
    for i in range(n4, values.shape[0]):
        v = values[i]
        total += v
        if weigh:
            weighted += np.float64(i) * v
        count += v != v
        l0 = v if v < l0 else l0
        h0 = v if v > h0 else h0
    return count, total, min(min(l0, l1), min(l2, l3)), max(max(h0, h1), max(h2, h3)), weighted


@njit(cache=True, nogil=True)
def _scan_task(data, b, block, weigh, half, nans, sums, lows, highs, moments):
    """Block ``b`` of :func:`scan`, into its own slots."""
    start, stop = b * block, min(data.shape[0], (b + 1) * block)
    nans[b], sums[b], lows[b], highs[b], weighted = _scan_block_fast(data, start, stop, weigh)
    moments[b] = weighted + (start - half) * sums[b]
    if nans[b] > 0:
        nans[b], sums[b], lows[b], highs[b] = _scan_block(data, start, stop)


#: Records of at most this many values are scanned by NumPy while the scan's kernels are not
#: compiled yet (:func:`avar._kernels.runtime.paths.numpy_path`): a few passes, still far shorter
#: than the compilation.
NUMPY_SCAN = 1 << 20


def _numpy_scan(data, weigh):
    """:func:`scan` by NumPy (a pairwise sum: as exact as the blocked one)."""
    missing = np.isnan(data)
    count = int(np.count_nonzero(missing))
    values = data[~missing] if count else data
    if values.shape[0] == 0:
        return Scanned(count, 0.0, np.inf, -np.inf, np.nan)
    moment = np.nan
    if weigh and count == 0:
        moment = float(np.einsum("i,i", np.arange(data.shape[0], dtype=np.float64) - (data.shape[0] - 1) / 2.0, data))
    return Scanned(count, float(np.sum(values)), float(np.min(values)), float(np.max(values)), moment)


def scan(data, block=CUMSUM_BLOCK, weigh=False):
    """Number of NaN, and sum, minimum and maximum of the other values (a :class:`Scanned`), in one pass on the threads;
    with ``weigh`` and no NaN, also the centred moment ``sum_i (i - (N - 1) / 2) data_i``
    (the numerator of the least-squares slope; NaN otherwise). Short records by NumPy while
    the kernels are cold (:data:`NUMPY_SCAN`)."""
    n = data.shape[0]
    if numpy_path(n, NUMPY_SCAN, (_scan_task,)):
        return _numpy_scan(data, weigh)
    n_blocks = -(-n // block)
    nans = np.zeros(n_blocks, dtype=np.int64)
    sums, lows, highs, moments = np.zeros(n_blocks), np.full(n_blocks, np.inf), np.full(n_blocks, -np.inf), \
        np.zeros(n_blocks)
    half = (n - 1) / 2.0
    run_tasks(n_blocks, lambda b: _scan_task(data, b, block, bool(weigh), half, nans, sums, lows, highs, moments))
    total = 0.0
    moment = 0.0
    for b in range(n_blocks):  # in order: the result does not depend on the thread count
        total += float(sums[b])
        moment += float(moments[b])
    count = int(nans.sum())
    low = float(lows.min()) if n_blocks else np.inf
    high = float(highs.max()) if n_blocks else -np.inf
    return Scanned(count, total, low, high, moment if count == 0 and weigh else np.nan)


class Increment(NamedTuple):
    """One increment of the phase as an exact pair ``hi + lo`` (:func:`phase_increment`)."""

    hi: float
    lo: float


@njit(cache=True, inline="always")
def phase_increment(data, data_lo, i, kind, centre, slope, scale):
    """Increment ``i`` minus ``centre + slope i``, times ``scale``, as an exact pair (an :class:`Increment`)."""
    if kind == 1:
        h, l = two_sum(data[i + 1], -data[i])
    elif kind == 2:
        h = data[i]
        l = np.float64(data_lo[i])
    else:
        h = data[i]
        l = 0.0
    # centre first: an increment near the mean frequency loses nothing to it (Sterbenz), and the
    # drift then comes off a small number, whose rounding error is small too. The other order
    # leaves the rounding error of a large increment (up to half its ulp) in the low part,
    # which the phase accumulates in float32.
    h, e2 = two_sum(h, -centre)
    l += e2
    if slope != 0.0:
        h, e1 = two_sum(h, -(slope * i))
        l += e1
    return Increment(h * scale, l * scale)


@njit(cache=True, nogil=True)
def _phase_block(data, data_lo, kind, centre, slope, scale, b, block, start_hi, start_lo, hi, lo, write):
    """Compensated sum of the increments of block ``b`` from ``start_hi + start_lo``; with
    ``write``, the running sums are written to ``hi, lo`` (``kind`` 2: as a renormalized pair,
    ``lo`` within half an ulp of ``hi``)."""
    n = hi.shape[0] - 1
    total = start_hi
    comp = start_lo
    for i in range(b * block, min(n, (b + 1) * block)):
        h, l = phase_increment(data, data_lo, i, kind, centre, slope, scale)
        total, err = two_sum(total, h)
        comp += err + l
        if write:
            if kind == 2:  # renormalized: the increments' low parts (the phase's) add up in ``comp``,
                # a constant one linearly, and float32 ``lo`` would keep 24 bits of that, not of the sum
                hi[i + 1], lo[i + 1] = two_sum(total, comp)
            else:
                hi[i + 1] = total
                lo[i + 1] = comp
    return total, comp


def detrended_phase(data, data_lo, kind, centre, slope, scale, hi, lo, block=CUMSUM_BLOCK):
    """Fill ``hi`` (float64), ``lo`` (float32; length M + 1) with the compensated running sum of the increments.

    ``kind`` 0: ``data`` is the frequency (M values, the increments
    themselves); 1: the phase (M + 1 values, increments ``data[i + 1] -
    data[i]``); 2: the increments are the pairs ``data[i] + data_lo[i]`` (the
    running sum of the phase, for MDEV). ``data_lo`` is unused (any float32
    array) for kinds 0 and 1. Increment ``i``
    enters as ``(increment - centre - slope i) scale``; ``slope i`` must be
    exact and ``scale`` a power of two. ``hi[0] = lo[0] = 0``. Two passes over
    blocks on the threads with an exact scan of the block sums between them: the
    block size, not the thread count, fixes the arithmetic.
    """
    n = hi.shape[0] - 1
    n_blocks = -(-n // block)
    centre, slope, scale = float(centre), float(slope), float(scale)
    sums = np.zeros((n_blocks, 2))

    def first(b):
        sums[b] = _phase_block(data, data_lo, kind, centre, slope, scale, b, block, 0.0, 0.0, hi, lo, False)

    run_tasks(n_blocks, first)
    offsets = np.zeros_like(sums)
    total, comp = 0.0, 0.0
    for b in range(n_blocks):  # the blocks' offsets, in order (double-double)
        offsets[b] = total, comp
        s = total + sums[b, 0]
        bv = s - total
        comp += ((total - (s - bv)) + (sums[b, 0] - bv)) + sums[b, 1]
        total = s
    hi[0] = 0.0
    lo[0] = 0.0
    run_tasks(n_blocks, lambda b: _phase_block(data, data_lo, kind, centre, slope, scale, b, block, offsets[b, 0],
                                               offsets[b, 1], hi, lo, True))


@njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _centred_moment_block(data, kind, start, stop, half):
    """sum over the increments ``start <= i < stop`` of (i - half) increment_i."""
    values = data[start : stop + kind]  # indices from 0: no negative-index checks in the loop
    origin = start - half
    total = 0.0
    for i in range(stop - start):
        v = values[i + 1] - values[i] if kind == 1 else values[i]
        total += (origin + i) * v
    return total


def centred_moment(data, kind, block=CUMSUM_BLOCK):
    """sum_i (i - (M - 1) / 2) increment_i over the M increments (``kind`` 0: ``data`` itself; 1: its differences).

    Blocks on the threads, added in order: the bits do not depend on the thread count. Short
    records by NumPy while the kernel is cold (:data:`NUMPY_SCAN`).
    """
    count = data.shape[0] - kind
    half = (count - 1) / 2.0
    if numpy_path(count, NUMPY_SCAN, (_centred_moment_block,)):
        increments = data[1:] - data[:-1] if kind == 1 else data
        return float(np.einsum("i,i", np.arange(count, dtype=np.float64) - half, increments))
    n_blocks = -(-count // block)
    parts = np.zeros(max(n_blocks, 1))

    def task(b):
        parts[b] = _centred_moment_block(data, kind, b * block, min(count, (b + 1) * block), half)

    run_tasks(n_blocks, task)
    total = 0.0
    for b in range(n_blocks):
        total += float(parts[b])
    return total


#: The compiled loop of :func:`detrended_phase` (whether it is compiled yet: :func:`avar._kernels.runtime.paths.compiled`).
PHASE_KERNELS = (_phase_block,)
