"""The Allan variance kernels (numba): cumulative sums and second differences.

Nothing here validates input or builds objects: :mod:`avar.estimate` does that
once at the public boundary and calls these kernels on clean float64 arrays.
The tests check every kernel against a plain NumPy transcription of the
estimator formulas.

How the Allan variance is computed
----------------------------------
Both estimators need, for a cluster size ``m``, sums of squared second
differences of the cumulative sum ``S`` of the series::

    D_k = S[b + 2m] - 2 S[b + m] + S[b]        (b = k * stride)

``D_k / m`` is the difference of two adjacent cluster means; ``stride`` is 1
for the maximal-overlap estimator and ``m`` for the tau-overlap one. Each
``D_k`` costs O(1), so a level costs O(number of differences), never O(N m).

Cancellation is the numerical risk: ``S`` can be many orders of magnitude
larger than ``D`` (a drift or random walk, a large offset). Three steps keep
the result within a few ulps of exact arithmetic on the float64 input:

1. the series is centred on its mean, and the centred value is kept exactly
   as an unevaluated sum ``hi + lo`` (Knuth's TwoSum);
2. it is scaled by a power of two (exact) so that values are O(1);
3. the cumulative sum is compensated: ``S = hi + lo`` with ``hi`` the float64
   running sum and ``lo`` its accumulated rounding error, stored as float32
   (its own relative precision is irrelevant because it is ~1e-16 of ``hi``;
   float32 keeps the memory at 12 bytes per sample).

The differences ``S[a] - S[b]`` are then formed as ``(hi[a] - hi[b]) +
(lo[a] - lo[b])``, which is accurate relative to the window sums rather than
to ``S``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.dd import fast_sum, two_sum
from avar._kernels.runtime.tasks import run_ranges, run_tasks

#: Number of differences one parallel task sums (tasks are (channel, level,
#: chunk) triples; the chunk size fixes the summation order, so results do
#: not depend on the number of threads).
CHUNK = 1 << 15

#: Samples per block of the parallel cumulative sum.
CUMSUM_BLOCK = 1 << 16

#: Differences per time block when all "mo" levels are fused: the window
#: ends of the smaller levels stay in the caches across the block.
FUSED_BLOCK = 1 << 16

#: Grids with more levels than this (such as taus="all") go level by level:
#: their per-level work is large and the fused per-block table would be too.
FUSED_MAX_LEVELS = 128


@njit(cache=True, inline="always")
def _centred(xi, ctr, sc):
    """``(xi - ctr) * sc`` as an exact pair (``sc`` is a power of two)."""
    yh, yl = two_sum(xi, -ctr)
    return yh * sc, yl * sc


@njit(cache=True, nogil=True)
def _cumsum_block(data, c, b, block, centre, scale, start_hi, start_lo, hi, lo, write):
    """Compensated sum of block ``b`` of ``(data[:, c] - centre) * scale`` from
    ``start_hi + start_lo``; with ``write``, its running sums are written to ``hi, lo``."""
    n = data.shape[0]
    total = start_hi
    comp = start_lo
    for i in range(b * block, min(n, (b + 1) * block)):
        yh, yl = _centred(data[i, c], centre, scale)
        total, err = two_sum(total, yh)
        comp += err + yl
        if write:
            hi[c, i + 1] = total
            lo[c, i + 1] = comp
    return total, comp


def centred_cumsum(data, centre, scale, hi, lo, block=CUMSUM_BLOCK):
    """Fill ``hi``, ``lo`` with compensated cumulative sums of ``(data[:, c] - centre[c]) * scale[c]``.

    Two passes over blocks of ``block`` samples, both on the threads: the first
    sums every block, an exact (double-double) scan turns the block sums into
    offsets, the second writes the running sums of every block from its
    offset. The block size, not the thread count, fixes the arithmetic.

    Parameters
    ----------
    data : float64 array, shape (N, C)
    centre, scale : float64 arrays, shape (C,); ``scale`` must be powers of two.
    hi : float64 array, shape (C, N + 1), output
        Running float64 sums, ``hi[c, 0] = 0``.
    lo : float32 array, shape (C, N + 1), output
        Accumulated rounding errors: ``hi + lo`` is the exact cumulative sum
        up to O(eps**2).

    The outputs are allocated by the caller with NumPy, whose allocator asks
    the kernel for huge pages: first-touch page faults of fresh memory
    otherwise cost more than the arithmetic.
    """
    n, channels = data.shape
    n_blocks = -(-n // block)
    sums = np.empty((channels, n_blocks, 2))

    def first(t):
        c, b = divmod(t, n_blocks)
        sums[c, b] = _cumsum_block(data, c, b, block, centre[c], scale[c], 0.0, 0.0, hi, lo, False)

    run_tasks(channels * n_blocks, first)
    offsets = np.empty_like(sums)
    for c in range(channels):  # the blocks' offsets, in order (double-double)
        total, comp = 0.0, 0.0
        for b in range(n_blocks):
            offsets[c, b] = total, comp
            s = total + sums[c, b, 0]
            bv = s - total
            comp += ((total - (s - bv)) + (sums[c, b, 0] - bv)) + sums[c, b, 1]
            total = s
        hi[c, 0] = 0.0
        lo[c, 0] = 0.0

    def second(t):
        c, b = divmod(t, n_blocks)
        _cumsum_block(data, c, b, block, centre[c], scale[c], offsets[c, b, 0], offsets[c, b, 1], hi, lo, True)

    run_tasks(channels * n_blocks, second)


#: Length of the per-task scratch buffer: the squared differences of a block
#: are written there by a vectorizable loop, then summed by a reduction that
#: may reassociate. The compensated differences themselves are never
#: reassociated (that would undo the compensation).
BLOCK = 512


@njit(cache=True)
def contiguous_squares(hi, lo, m, start, count, buffer):
    """Sum of ``D_k**2`` for ``k = start .. start + count - 1`` with stride 1.

    ``count`` must not exceed ``buffer.shape[0]``. The loop over contiguous
    windows is one that LLVM vectorizes.
    """
    h0 = hi[start : start + count]
    h1 = hi[start + m : start + m + count]
    h2 = hi[start + 2 * m : start + 2 * m + count]
    l0 = lo[start : start + count]
    l1 = lo[start + m : start + m + count]
    l2 = lo[start + 2 * m : start + 2 * m + count]
    for j in range(count):
        # lo's second difference in float32 (8 lanes, one conversion): its
        # rounding is ~6e-8 of a quantity already ~1e-16 of the cumulative sum.
        d = ((h2[j] - h1[j]) - (h1[j] - h0[j])) + np.float64((l2[j] - l1[j]) - (l1[j] - l0[j]))
        buffer[j] = d * d
    return fast_sum(buffer, count)


@njit(cache=True)
def contiguous_third_squares(hi, lo, m, start, count, buffer):
    """Sum of the squared third differences ``S[b + 3m] - 3 S[b + 2m] + 3 S[b + m] - S[b]`` at
    ``b = start .. start + count - 1`` (vectorized; OHDEV's terms, and MDEV's of the running sum),
    squared in the loop that forms them (``count`` at most ``buffer.shape[0]``)."""
    h0 = hi[start : start + count]
    h1 = hi[start + m : start + m + count]
    h2 = hi[start + 2 * m : start + 2 * m + count]
    h3 = hi[start + 3 * m : start + 3 * m + count]
    l0 = lo[start : start + count]
    l1 = lo[start + m : start + m + count]
    l2 = lo[start + 2 * m : start + 2 * m + count]
    l3 = lo[start + 3 * m : start + 3 * m + count]
    for j in range(count):
        a1 = h1[j] - h0[j]
        a2 = h2[j] - h1[j]
        a3 = h3[j] - h2[j]
        b1 = l1[j] - l0[j]
        b2 = l2[j] - l1[j]
        b3 = l3[j] - l2[j]
        d = ((a3 - a2) - (a2 - a1)) + np.float64((b3 - b2) - (b2 - b1))
        buffer[j] = d * d
    return fast_sum(buffer, count)


@njit(cache=True)
def _strided_squares(hi, lo, m, stride, start, count, buffer):
    """Sum of ``D_k**2`` for ``k = start .. start + count - 1``, windows ``stride`` apart."""
    for j in range(count):
        b = (start + j) * stride
        d = ((hi[b + 2 * m] - hi[b + m]) - (hi[b + m] - hi[b])) + np.float64(
            (lo[b + 2 * m] - lo[b + m]) - (lo[b + m] - lo[b])
        )
        buffer[j] = d * d
    return fast_sum(buffer, count)


@njit(cache=True, nogil=True)
def _fused_block(hi, lo, c, b, factors, n_differences, block, out):
    """The sums of every level over differences ``[b block, (b + 1) block)`` of channel ``c``."""
    buffer = np.empty(BLOCK)
    h = hi[c]
    l = lo[c]
    start = b * block
    for k in range(factors.shape[0]):
        stop = min(start + block, n_differences[k])
        if stop <= start:
            break
        total = 0.0
        for first in range(start, stop, BLOCK):
            total += contiguous_squares(h, l, factors[k], first, min(BLOCK, stop - first), buffer)
        out[c, b, k] = total


def fused_overlapping_sums(hi, lo, factors, n_differences, block=FUSED_BLOCK):
    """Maximal-overlap sums of all levels, one time block per task.

    Task ``(c, b)`` covers differences ``k`` in ``[b * block, (b + 1) * block)``
    of channel ``c`` at every level, so the cumulative sums around that block
    are read from memory once for all levels (for octave grids the window
    ends of level j are the window middles of level j + 1).

    ``factors`` must be increasing (so ``n_differences`` decreases).
    Returns the per-block sums, shape (C, n_blocks, L).
    """
    channels = hi.shape[0]
    n_blocks = -(-int(n_differences[0]) // block)
    out = np.zeros((channels, n_blocks, factors.shape[0]))
    run_tasks(channels * n_blocks, lambda t: _fused_block(hi, lo, *divmod(t, n_blocks), factors, n_differences, block,
                                                          out))
    return out


@njit(cache=True, nogil=True)
def _task_range(hi, lo, task_channel, task_factor, task_stride, task_first, task_last, first_task, stop_task, out):
    """Tasks ``first_task .. stop_task - 1`` of :func:`task_sums`, each into its own ``out[i]``."""
    buffer = np.empty(BLOCK)
    for i in range(first_task, stop_task):
        h = hi[task_channel[i]]
        l = lo[task_channel[i]]
        m = task_factor[i]
        stride = task_stride[i]
        total = 0.0
        for first in range(task_first[i], task_last[i], BLOCK):
            count = min(BLOCK, task_last[i] - first)
            if stride == 1:
                total += contiguous_squares(h, l, m, first, count, buffer)
            else:
                total += _strided_squares(h, l, m, stride, first, count, buffer)
        out[i] = total


def task_sums(hi, lo, task_channel, task_factor, task_stride, task_first, task_last):
    """Evaluate every task's sum of squared second differences, on the threads.

    Task ``i`` sums ``D_k**2`` of channel ``task_channel[i]`` at cluster size
    ``task_factor[i]`` and stride ``task_stride[i]`` for
    ``k in [task_first[i], task_last[i])``.
    """
    out = np.empty(task_channel.shape[0], dtype=np.float64)
    run_ranges(out.shape[0], lambda first, stop: _task_range(hi, lo, task_channel, task_factor, task_stride, task_first,
                                                             task_last, first, stop, out))
    return out


def _level_wise_sums(hi, lo, channels, factors, strides, n_differences, chunk):
    """Sums of (channel, level) pairs, each split into tasks of ``chunk`` differences."""
    per_pair = -(-n_differences // chunk)
    pair_of_task = np.repeat(np.arange(channels.shape[0]), per_pair)
    pair_start = np.concatenate(([0], np.cumsum(per_pair)[:-1]))
    first = (np.arange(pair_of_task.shape[0]) - pair_start[pair_of_task]) * chunk
    last = np.minimum(first + chunk, n_differences[pair_of_task])
    sums = task_sums(
        hi, lo, channels[pair_of_task], factors[pair_of_task], strides[pair_of_task], first, last
    )
    return np.bincount(pair_of_task, weights=sums, minlength=channels.shape[0])


def squared_difference_sums(hi, lo, factors, strides, n_differences, chunk=CHUNK):
    """Sum of squared second differences ``D_k**2`` for every channel and level.

    Parameters
    ----------
    hi, lo : arrays of shape (C, N + 1) from :func:`centred_cumsum`.
    factors, strides, n_differences : int64 arrays of shape (L,)
        Cluster size ``m`` (increasing), stride between differences (1 for
        "mo", ``m`` for "to") and number of differences of every level.
    chunk : int
        Differences per parallel task on the level-by-level path.

    Returns
    -------
    float64 array of shape (C, L)

    Notes
    -----
    Maximal-overlap grids of at most ``FUSED_MAX_LEVELS`` levels go through
    :func:`fused_overlapping_sums`; others (tau overlap, taus="all") through
    :func:`task_sums`. Either way the summation order depends only on the
    block sizes, never on the number of threads.
    """
    factors = np.asarray(factors, dtype=np.int64)
    strides = np.asarray(strides, dtype=np.int64)
    n_differences = np.asarray(n_differences, dtype=np.int64)
    n_channels = hi.shape[0]
    n_levels = factors.shape[0]
    if np.all(strides == 1) and n_levels <= FUSED_MAX_LEVELS:
        return fused_overlapping_sums(hi, lo, factors, n_differences).sum(axis=1)
    channel = np.repeat(np.arange(n_channels, dtype=np.int64), n_levels)
    level = np.tile(np.arange(n_levels), n_channels)
    sums = _level_wise_sums(hi, lo, channel, factors[level], strides[level], n_differences[level], chunk)
    return sums.reshape(n_channels, n_levels)


def difference_kernels(strides, n_levels):
    """The compiled loops :func:`squared_difference_sums` runs for ``n_levels`` levels of these
    strides (whether they are compiled yet: :func:`avar._kernels.runtime.paths.compiled`)."""
    if np.all(np.asarray(strides) == 1) and n_levels <= FUSED_MAX_LEVELS:
        return (_fused_block,)
    return (_task_range,)
