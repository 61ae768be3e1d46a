"""Kernels of the time-and-frequency deviation family (numba): ADEV ... TOTDEV.

Nothing here validates input: :mod:`avar.stability.classic.deviations` does that once
and calls these kernels on clean arrays. The tests check every kernel against
a plain loop over the formula in exact arithmetic.

The phase as a double-double
----------------------------
Every estimator is a sum of squared differences of the phase ``x``. The
phase is rebuilt from its increments (the fractional frequency, or the first
differences of phase data, each an exact pair by Knuth's TwoSum) after
removing a line ``c + d i`` from them (the mean frequency and, for the
Hadamard family, a linear frequency drift; the statistics are invariant to
both). ``d`` is rounded to few enough bits that ``d i`` is exact, so the
removal is exact too. The running sum is compensated: ``P = hi + lo`` is the
detrended phase to O(eps**2), and a difference ``P[a] - P[b]`` is formed as
``(hi[a] - hi[b]) + (lo[a] - lo[b])``, accurate relative to the difference
rather than to ``P``.

Term by term, in O(1) each
--------------------------
* ``code 0``: second differences ``P[b + 2m] - 2 P[b + m] + P[b]`` (ADEV with
  ``b = k m``, OADEV with ``b = k``);
* ``code 1``: third differences ``P[b + 3m] - 3 P[b + 2m] + 3 P[b + m] - P[b]``
  (HDEV, OHDEV);
* ``code 2``: MDEV's window sums ``T_j = sum_{i=j}^{j+m-1} (second difference at i)``
  are third differences ``C[j + 3m] - 3 C[j + 2m] + 3 C[j + m] - C[j]`` of the
  running sum ``C`` of the (centred) phase, itself a compensated double-double
  sum built by :func:`detrended_phase` (kind 2);
* ``code 3``: TOTDEV's second differences of the phase reflected at both ends,
  ``x*_{-j} = 2 x_0 - x_j`` and ``x*_{N-1+j} = 2 x_{N-1} - x_{N-1-j}`` (0-based),
  evaluated in place without building the 3N-long series;
* ``code 4``: MHDEV's window sums ``sum_{i=j}^{j+m-1} (third difference at i)`` are
  fourth differences ``C[j + 4m] - 4 C[j + 3m] + 6 C[j + 2m] - 4 C[j + m] + C[j]`` of
  the same running sum ``C`` as code 2.

Terms are split into tasks of a fixed size (a function of the level only), so
the summation order, and the result, does not depend on the number of threads.
Gap-free levels of stride 1 (OHDEV, MDEV, TOTDEV, MHDEV) go by blocks of terms,
every level per block (:func:`fused_sums`): the phase around a block is read
from memory once for the small levels.

Gaps
----
``mode`` 0: no gaps. ``mode`` 1 (phase data with NaN): ``bad`` is the prefix
count of missing phase points (length N + 1) and a term is skipped when one of
the points it uses is missing. ``mode`` 2 (frequency data with NaN): ``bad``
is the prefix count of missing frequency values (length N, one per phase
increment) and a term is skipped when a missing value lies between the first
and the last phase point it uses. Missing values were filled before the
cumulative sum (any finite value keeps the other terms exact).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from avar._kernels.classic.phase import detrended_phase, scan  # noqa: F401 (re-exported)
from avar._kernels.classic.sums import (
    FUSED_BLOCK,
    FUSED_MAX_LEVELS,
    contiguous_squares,
    contiguous_third_squares,
    difference_kernels,
    squared_difference_sums,
)
from avar._kernels.dd import fast_sum
from avar._kernels.runtime.tasks import run_ranges, run_tasks

#: Terms per parallel task (MDEV tasks span at least m terms).
CHUNK = 1 << 15

#: Terms whose squares are summed by one vectorizable reduction.
BLOCK = 512


@njit(cache=True, inline="always")
def _second(hi, lo, b, m):
    """``P[b + 2m] - 2 P[b + m] + P[b]``."""
    return ((hi[b + 2 * m] - hi[b + m]) - (hi[b + m] - hi[b])) + np.float64(
        (lo[b + 2 * m] - lo[b + m]) - (lo[b + m] - lo[b])
    )


@njit(cache=True, inline="always")
def _third(hi, lo, b, m):
    """``P[b + 3m] - 3 P[b + 2m] + 3 P[b + m] - P[b]``."""
    h1 = hi[b + m] - hi[b]
    h2 = hi[b + 2 * m] - hi[b + m]
    h3 = hi[b + 3 * m] - hi[b + 2 * m]
    l1 = lo[b + m] - lo[b]
    l2 = lo[b + 2 * m] - lo[b + m]
    l3 = lo[b + 3 * m] - lo[b + 2 * m]
    return ((h3 - h2) - (h2 - h1)) + np.float64((l3 - l2) - (l2 - l1))


@njit(cache=True, inline="always")
def _fourth(hi, lo, b, m):
    """``P[b + 4m] - 4 P[b + 3m] + 6 P[b + 2m] - 4 P[b + m] + P[b]``: the third difference of the
    first differences ``P[b + (k + 1) m] - P[b + k m]``, each formed exactly in its double-double parts."""
    h1 = hi[b + m] - hi[b]
    h2 = hi[b + 2 * m] - hi[b + m]
    h3 = hi[b + 3 * m] - hi[b + 2 * m]
    h4 = hi[b + 4 * m] - hi[b + 3 * m]
    l1 = lo[b + m] - lo[b]
    l2 = lo[b + 2 * m] - lo[b + m]
    l3 = lo[b + 3 * m] - lo[b + 2 * m]
    l4 = lo[b + 4 * m] - lo[b + 3 * m]
    return (((h4 - h3) - (h3 - h2)) - ((h3 - h2) - (h2 - h1))) + np.float64(
        ((l4 - l3) - (l3 - l2)) - ((l3 - l2) - (l2 - l1)))


@njit(cache=True, inline="always")
def _reflected_minus(hi, lo, j, i, last):
    """``P*[j] - P[i]`` with ``P*`` the phase reflected at both ends (0-based, ``last = N - 1``)."""
    if j < 0:  # P*[j] = 2 P[0] - P[-j]
        return ((hi[0] - hi[-j]) + (hi[0] - hi[i])) + np.float64((lo[0] - lo[-j]) + (lo[0] - lo[i]))
    if j > last:  # P*[j] = 2 P[last] - P[2 last - j]
        k = 2 * last - j
        return ((hi[last] - hi[k]) + (hi[last] - hi[i])) + np.float64((lo[last] - lo[k]) + (lo[last] - lo[i]))
    return (hi[j] - hi[i]) + np.float64(lo[j] - lo[i])


@njit(cache=True, inline="always")
def _point_ok(bad, p):
    return bad[p + 1] == bad[p]


@njit(cache=True, inline="always")
def _range_ok(bad, mode, a, b):
    """No missing point in [a, b] (mode 1) or missing increment between points a and b (mode 2)."""
    if mode == 1:
        return bad[b + 1] == bad[a]
    return bad[b] == bad[a]


@njit(cache=True)
def _valid(code, bad, mode, b, m, last):
    """Whether term ``b`` of a level avoids every gap (see the module notes)."""
    if code == 2:
        return _range_ok(bad, mode, b, b + 3 * m - 1)
    if code == 4:
        return _range_ok(bad, mode, b, b + 4 * m - 1)
    if code == 3:
        low = b - m
        high = b + m
        if mode == 1:
            ok = _point_ok(bad, b)
            if low < 0:
                ok = ok and _point_ok(bad, 0) and _point_ok(bad, -low)
            else:
                ok = ok and _point_ok(bad, low)
            if high > last:
                ok = ok and _point_ok(bad, last) and _point_ok(bad, 2 * last - high)
            else:
                ok = ok and _point_ok(bad, high)
            return ok
        first = b
        final = b
        if low < 0:
            first = 0
            final = max(final, -low)
        else:
            first = low
        if high > last:
            final = last
            first = min(first, 2 * last - high)
        else:
            final = max(final, high)
        return _range_ok(bad, mode, first, final)
    order = 2 if code == 0 else 3
    if mode == 2:
        return _range_ok(bad, mode, b, b + order * m)
    for k in range(order + 1):
        if not _point_ok(bad, b + k * m):
            return False
    return True


@njit(cache=True)
def _totdev_term(hi, lo, k, m, last):
    return _reflected_minus(hi, lo, k - m, k, last) + _reflected_minus(hi, lo, k + m, k, last)


@njit(cache=True)
def _totdev_block(hi, lo, m, start, count, left, right, buffer):
    """Sum of squared TOTDEV terms ``start .. start + count - 1``, all reflected on the
    left (or none) and all on the right (or none)."""
    last = hi.shape[0] - 1
    h0 = hi[0]
    hl = hi[last]
    l0 = np.float64(lo[0])
    ll = np.float64(lo[last])
    if not left and not right:
        return contiguous_squares(hi, lo, m, start - m, count, buffer)
    for j in range(count):
        k = start + j
        hk = hi[k]
        lk = np.float64(lo[k])
        if left:  # P*[k - m] = 2 P[0] - P[m - k]
            a = (h0 - hi[m - k]) + (h0 - hk)
            b = (l0 - np.float64(lo[m - k])) + (l0 - lk)
        else:
            a = hi[k - m] - hk
            b = np.float64(lo[k - m]) - lk
        if right:  # P*[k + m] = 2 P[last] - P[2 last - k - m]
            c = (hl - hi[2 * last - k - m]) + (hl - hk)
            e = (ll - np.float64(lo[2 * last - k - m])) + (ll - lk)
        else:
            c = hi[k + m] - hk
            e = np.float64(lo[k + m]) - lk
        d = (a + c) + (b + e)
        buffer[j] = d * d
    return fast_sum(buffer, count)


@njit(cache=True)
def _fast_task_sum(hi, lo, code, m, stride, first, last_term, buffer):
    """:func:`_task_sum` without gaps: vectorized loops for every code."""
    last = hi.shape[0] - 1
    total = 0.0
    if code == 3:
        # segments where each end of the term is either direct or reflected
        cuts = np.array([first, min(max(first, m), last_term), min(max(first, last - m + 1), last_term), last_term])
        cuts[1:3] = np.sort(cuts[1:3])
        for s in range(3):
            for start in range(cuts[s], cuts[s + 1], BLOCK):
                count = min(BLOCK, cuts[s + 1] - start)
                total += _totdev_block(hi, lo, m, start, count, start < m, start + count - 1 > last - m, buffer)
        return total
    for start in range(first, last_term, BLOCK):
        count = min(BLOCK, last_term - start)
        if code == 4:
            for j in range(count):
                d = _fourth(hi, lo, start + j, m)
                buffer[j] = d * d
            total += fast_sum(buffer, count)
        elif stride == 1:
            if code == 0:
                total += contiguous_squares(hi, lo, m, start, count, buffer)
            else:
                total += contiguous_third_squares(hi, lo, m, start, count, buffer)
        else:
            for j in range(count):
                b = (start + j) * stride
                d = _second(hi, lo, b, m) if code == 0 else _third(hi, lo, b, m)
                buffer[j] = d * d
            total += fast_sum(buffer, count)
    return total


@njit(cache=True)
def _task_sum(hi, lo, code, m, stride, first, last_term, mode, bad, buffer):
    """Sum of squared terms ``first .. last_term - 1`` of one level and how many were used."""
    if mode == 0:
        return _fast_task_sum(hi, lo, code, m, stride, first, last_term, buffer), last_term - first
    last = hi.shape[0] - 1
    total = 0.0
    used = 0
    for start in range(first, last_term, BLOCK):
        count = min(BLOCK, last_term - start)
        for j in range(count):
            k = start + j
            if code == 0:
                d = _second(hi, lo, k * stride, m)
            elif code == 1:
                d = _third(hi, lo, k * stride, m)
            elif code == 2:
                d = _third(hi, lo, k, m)
            elif code == 4:
                d = _fourth(hi, lo, k, m)
            else:
                d = _totdev_term(hi, lo, k, m, last)
            if not _valid(code, bad, mode, k * stride, m, last):
                d = 0.0
            else:
                used += 1
            buffer[j] = d * d
        total += fast_sum(buffer, count)
    return total, used


@njit(cache=True, nogil=True)
def _task_range(hi, lo, code, task_m, task_stride, task_first, task_last, mode, bad, first, stop, sums, counts):
    """Tasks ``first .. stop - 1`` of :func:`task_sums`, each into its own slot."""
    buffer = np.empty(BLOCK)
    for t in range(first, stop):
        sums[t], counts[t] = _task_sum(
            hi, lo, code, task_m[t], task_stride[t], task_first[t], task_last[t], mode, bad, buffer
        )


def task_sums(hi, lo, code, task_m, task_stride, task_first, task_last, mode, bad):
    """Sums of squared terms and term counts of every task, on the threads.

    Task ``t`` covers terms ``task_first[t] .. task_last[t] - 1`` of the level
    with averaging factor ``task_m[t]`` and stride ``task_stride[t]`` between
    terms (``m`` for ADEV/HDEV, 1 otherwise). For TOTDEV (``code`` 3) term
    ``k`` is centred on phase point ``k`` (k = 1 .. N - 2).
    """
    n_tasks = task_m.shape[0]
    sums = np.empty(n_tasks)
    counts = np.empty(n_tasks, dtype=np.int64)
    run_ranges(n_tasks, lambda first, stop: _task_range(hi, lo, code, task_m, task_stride, task_first, task_last, mode,
                                                        bad, first, stop, sums, counts))
    return sums, counts


@njit(cache=True, nogil=True)
def _fused_block(hi, lo, code, b, factors, firsts, lasts, block, out):
    """The sums of every gap-free level of stride 1 over terms ``[b block, (b + 1) block)``."""
    buffer = np.empty(BLOCK)
    for k in range(factors.shape[0]):
        start = max(b * block, firsts[k])
        stop = min((b + 1) * block, lasts[k])
        out[b, k] = _fast_task_sum(hi, lo, code, factors[k], 1, start, stop, buffer) if start < stop else 0.0


def fused_sums(hi, lo, code, factors, firsts, lasts, block=FUSED_BLOCK):
    """Sums of squared terms of every gap-free level of stride 1 (OHDEV, MDEV, TOTDEV, MHDEV), one
    block of terms for all levels per task (as :func:`avar._kernels.classic.sums.fused_overlapping_sums`):
    the phase around a block is read from memory once for the small levels. Level ``k`` sums terms
    ``firsts[k] .. lasts[k] - 1``; the blocks' sums are added in order (the bits do not depend
    on the number of threads)."""
    n_blocks = max(1, -(-int(np.max(lasts, initial=0)) // block))
    out = np.zeros((n_blocks, factors.shape[0]))
    run_tasks(n_blocks, lambda b: _fused_block(hi, lo, code, b, factors, firsts, lasts, block, out))
    return out.sum(axis=0)


class LevelSums(NamedTuple):
    """Sum of squared terms and number of terms used, level by level (:func:`level_sums`)."""

    sums: np.ndarray
    counts: np.ndarray


def _fused(code, mode, strides, n_levels):
    """Whether :func:`level_sums` takes :func:`fused_sums`: gap-free levels of stride 1 (OHDEV, MDEV,
    TOTDEV, MHDEV), few enough for its table."""
    return code != 0 and mode == 0 and n_levels <= FUSED_MAX_LEVELS and bool(np.all(np.asarray(strides) == 1))


def level_sums(hi, lo, code, factors, strides, firsts, lasts, mode=0, bad=None, chunk=CHUNK):
    """Sum of squared terms and number of terms used, level by level.

    Parameters
    ----------
    hi, lo : float64 and float32 arrays of length N, the phase from :func:`detrended_phase`.
    code : int
        0 second differences, 1 third differences, 2 MDEV, 3 TOTDEV, 4 MHDEV.
    factors, strides, firsts, lasts : int64 arrays, one entry per level
        Averaging factor, stride between terms, and the range of term indices.
    mode, bad : gaps, see the module notes (``bad`` unused when ``mode`` is 0).
    chunk : int
        Terms per task (at least ``m`` for MDEV).

    Returns
    -------
    LevelSums
        ``sums`` (float64 array), ``counts`` (int64 array).
    """
    factors = np.asarray(factors, dtype=np.int64)
    if code == 0 and mode == 0:
        counts = np.asarray(lasts, dtype=np.int64) - np.asarray(firsts, dtype=np.int64)
        sums = squared_difference_sums(hi[None, :], lo[None, :], factors, np.asarray(strides, dtype=np.int64), counts)
        return LevelSums(sums[0], counts)
    if _fused(code, mode, strides, factors.shape[0]):
        firsts = np.asarray(firsts, dtype=np.int64)
        lasts = np.asarray(lasts, dtype=np.int64)
        return LevelSums(fused_sums(hi, lo, code, factors, firsts, lasts), np.maximum(lasts - firsts, 0))
    span = np.asarray(lasts, dtype=np.int64) - np.asarray(firsts, dtype=np.int64)
    size = np.full_like(factors, chunk)
    per_level = np.maximum(1, -(-span // size))
    level = np.repeat(np.arange(factors.shape[0]), per_level)
    offset = np.concatenate(([0], np.cumsum(per_level)[:-1]))
    first = np.asarray(firsts, dtype=np.int64)[level] + (np.arange(level.shape[0]) - offset[level]) * size[level]
    last = np.minimum(first + size[level], np.asarray(lasts, dtype=np.int64)[level])
    if bad is None:
        bad = np.zeros(1, dtype=np.int64)
    sums, counts = task_sums(
        hi, lo, code, factors[level], np.asarray(strides, dtype=np.int64)[level], first, last, mode, bad
    )
    n_levels = factors.shape[0]
    return LevelSums(
        np.bincount(level, weights=sums, minlength=n_levels),
        np.bincount(level, weights=counts, minlength=n_levels).astype(np.int64),
    )


def level_kernels(code, strides, mode=0):
    """The compiled loops :func:`level_sums` runs for levels of these strides (whether they are
    compiled yet: :func:`avar._kernels.runtime.paths.compiled`)."""
    if code == 0 and mode == 0:
        return difference_kernels(strides, len(strides))
    if _fused(code, mode, strides, len(strides)):
        return (_fused_block,)
    return (_task_range,)
