"""The small-input path of the Allan variance (numba): one call, no workspace.

For short series the cost of a call is dispatch, thread start-up and
allocation, not arithmetic. Here one compiled function does everything for
every column: a plain sum (a centre near the mean, and the largest
magnitude), the centred compensated cumulative sum ``S = hi + lo`` of the
column (2 x 8 bytes a sample, at most :data:`avar._kernels.allan.columns.SMALL_MAX`
samples) and, per level, the squared second differences
``D = S[b + 2m] - 2 S[b + m] + S[b]`` (``b`` every sample for "mo", every
``m`` samples for "to"). The arithmetic is that of :mod:`streaming`: exact
centred pairs, TwoSum accumulation, compensated differences ("mo": plain
ones where :func:`avar._kernels.allan.blocks.certified_squares` proves them
accurate). :func:`small_allan_variance` runs on one thread (the shortest
calls: starting the thread pool would cost more than the work);
:func:`small_allan_variance_parallel` shares the levels among the threads.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from avar._kernels.allan.blocks import LIMIT_EXP, certified_squares, fill_prefix, read_only
from avar._kernels.runtime.tasks import run_tasks


@njit(cache=True)
def _scale_of(big):
    """Power of two bringing a largest magnitude outside [2**-LIMIT_EXP, 2**LIMIT_EXP] near 1."""
    if np.isfinite(big) and big > 0.0 and (big > 2.0**LIMIT_EXP or big < 2.0**-LIMIT_EXP):
        _, e = math.frexp(big)
        return math.ldexp(1.0, -min(max(e, -1000), 1000))
    return 1.0


@njit(cache=True)
def _sum_and_big(data, c, scale):
    """Plain sum and largest magnitude of ``data[:, c] * scale``, in index order (a
    vectorized sum would depend on the memory layout, and so would the bits)."""
    x = data[:, c]
    total = 0.0
    big = 0.0
    for i in range(x.shape[0]):
        v = np.float64(x[i]) * scale
        total += v
        big = max(big, abs(v))
    return total, big


@njit(cache=True)
def _prepare(data, c, integral, hi, lo, bounds):
    """Fill ``hi/lo`` with the centred compensated cumulative sum of column ``c`` (and ``bounds``
    with its largest parts); return the power-of-two scale applied."""
    n = data.shape[0]
    total, big = _sum_and_big(data, c, 1.0)
    scale = _scale_of(big)
    if scale != 1.0:
        total, big = _sum_and_big(data, c, scale)
    centre = total / n  # any centre keeps S exact; near the mean keeps it small
    if integral:
        centre = np.floor(centre + 0.5)  # any integer keeps the centred integers exact (a float:
        # no int64 overflow; not np.round, whose general implementation takes 0.7 s to compile)
    bounds[:] = 0.0
    zero = np.int64(0)  # not the literal 0: fill_prefix compiles once
    fill_prefix(data, c, zero, n, centre, scale, 0.0, 0.0, hi, lo, zero, bounds)
    return scale


@njit(cache=True, inline="always")
def _level(hi, lo, m, count, is_mo, bounds, buffer):
    """Sum of the ``count`` squared second differences of level ``m``."""
    if is_mo:
        return certified_squares(hi, lo, np.int64(0), m, count, buffer, bounds)
    total = 0.0
    for j in range(count):
        b = j * m
        d = ((hi[b + 2 * m] - hi[b + m]) - (hi[b + m] - hi[b])) + ((lo[b + 2 * m] - lo[b + m]) - (lo[b + m] - lo[b]))
        total += d * d
    return total


@njit(cache=True)
def small_allan_variance(data, factors, counts, is_mo, integral):
    """Allan variance of every column of ``data`` (N, C), shape (C, L).

    ``factors`` valid cluster sizes (any order); ``counts`` their numbers of
    differences (N - 2m + 1 for "mo", floor(N / m) - 1 for "to"), all > 0.
    """
    n, channels = data.shape
    n_levels = factors.shape[0]
    out = np.empty((channels, n_levels))
    hi = np.empty(n + 1)
    lo = np.empty(n + 1)
    buffer = np.empty(n)
    bounds = np.zeros(2)
    for c in range(channels):
        scale = _prepare(data, c, integral, hi, lo, bounds)
        unscale = 1.0 / scale
        for k in range(n_levels):
            mf = np.float64(factors[k])
            sums = _level(hi, lo, factors[k], counts[k], is_mo, bounds, buffer)
            out[c, k] = sums / (2.0 * mf * mf * counts[k]) * unscale * unscale
    return out


@njit(cache=True, nogil=True)
def _level_task(hi, lo, factors, counts, k, is_mo, bounds, unscale, out_row):
    """Level ``k`` of one column whose cumulative sum is in ``hi/lo`` (a task of the threads)."""
    buffer = np.empty(0)  # certified_squares allocates one if it needs it
    mf = np.float64(factors[k])
    sums = _level(hi, lo, factors[k], counts[k], is_mo, bounds, buffer)
    out_row[k] = sums / (2.0 * mf * mf * counts[k]) * unscale * unscale


def small_allan_variance_parallel(data, factors, counts, is_mo, integral):
    """:func:`small_allan_variance` with the levels shared among the threads (each level's
    sum is one thread's: the bits do not depend on the thread count)."""
    data = read_only(data)
    n, channels = data.shape
    out = np.empty((channels, factors.shape[0]))
    hi = np.empty(n + 1)
    lo = np.empty(n + 1)
    bounds = np.zeros(2)
    for c in range(channels):
        unscale = 1.0 / _prepare(data, c, integral, hi, lo, bounds)

        def task(k, unscale=unscale, row=out[c]):
            _level_task(hi, lo, factors, counts, k, is_mo, bounds, unscale, row)

        run_tasks(factors.shape[0], task)
    return out


#: The compiled loop :func:`small_allan_variance_parallel` adds to the ones it shares with
#: :func:`small_allan_variance` (whether it is compiled yet: :func:`avar._kernels.runtime.paths.compiled`).
PARALLEL_KERNEL = _level_task
