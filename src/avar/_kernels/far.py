"""Maximal-overlap Allan variance of the large power-of-two cluster sizes (numba).

For a cluster size ``m`` the differences are ``D_t = S[t+2m] - 2 S[t+m] + S[t]``
(``S`` the centred cumulative sum). For ``m`` a multiple of the table's
granularity ``F`` (:data:`SWEEP_FINE` samples; the table holds the exact
double-double ``S`` at every multiple of ``F``), time is cut into pieces of
``F`` samples and each piece runs the recurrence

    D_{t0} = S[t0+2m] - 2 S[t0+m] + S[t0]   (exact double-double, from the table)
    D_{t+1} = D_t + (x[t+2m] - 2 x[t+m] + x[t])

The running value is ``D`` itself, never a cumulative sum, so every addition
errs by at most ``u |D|`` (u = 2**-53): each ``D`` errs by at most about
``F u max |D|`` (1e-13 for the default piece) plus the error of its steps,
whatever the offset or the excursion of ``S``. :func:`chained_squares` runs a
piece as :data:`CHAINS` independent stretches so the additions do not wait on
one another.

The steps are first taken in plain float64,
``(x[t+2m] - x[t+m]) - (x[t+m] - x[t])`` (:func:`plain_second_differences`);
the table's spread of each piece (how far its samples lie from the centre)
bounds their accumulated error (:func:`step_error_bound`). A piece whose bound
could move its sum of squares by more than the tolerance
(:func:`avar._kernels.streaming.certified`, 1e-11 relative) is redone with
every step rounded once (:func:`second_differences`, TwoSum). Noise-like data
pass, also on a large offset (the spread is measured from the centre); a
piece whose ``D`` is tiny against its samples' spread (a strong component
periodic in ``m``, say) takes the exact steps.

Order of work: a level reads the pieces at ``t``, ``t + m`` and ``t + 2m``. All
large ``m`` are multiples of the smallest, ``P``, so those pieces are in the
same residue class modulo ``P``. A task takes one class (every ``P / F``-th
piece) and, piece by piece, every level: the pieces it reads for one level
are read again by the next levels and by its later pieces while they are
still in the cache, instead of once per level from memory (the input read in
time order meets each sample again only 2m samples later, long evicted).
The sums of the tasks are added in a fixed order, so the bits do not depend
on the number of threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange, types
from numba.extending import overload

from avar._kernels.haar import _is_wide, _pair
from avar._kernels.streaming import _EPS, CERTIFY_TOL, _two_sum, certified

#: Samples per piece: the table's granularity for the large levels and the steps summed per call.
SWEEP_FINE = 1 << 10


def _second_difference(x2, x1, x0, sc):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_second_difference, inline="always")
def _second_difference_overload(x2, x1, x0, sc):
    """``(x2 - 2 x1 + x0) * sc`` rounded once (TwoSum; 64-bit integers enter as two exact halves)."""
    if isinstance(x2, types.Integer) and x2.bitwidth == 64:

        def impl(x2, x1, x0, sc):
            h2, l2 = _pair(x2, sc)
            h1, l1 = _pair(x1, sc)
            h0, l0 = _pair(x0, sc)
            a, ea = _two_sum(h2, h0)
            b, eb = _two_sum(a, -2.0 * h1)
            return b + ((ea + eb) + ((l2 + l0) - 2.0 * l1))

        return impl

    def impl(x2, x1, x0, sc):
        a, ea = _two_sum(np.float64(x2) * sc, np.float64(x0) * sc)
        b, eb = _two_sum(a, -2.0 * (np.float64(x1) * sc))
        return b + (ea + eb)

    return impl


@njit(cache=True)
def second_differences(rows, col, t0, m, count, sc, out):
    """``out[i] = (x[t0+i+2m] - 2 x[t0+i+m] + x[t0+i]) * sc`` for ``i < count - 1``; ``out[count - 1] = 0``.

    These are the steps ``D_{t+1} - D_t`` of the level-``m`` differences (the centre
    cancels). Each is rounded once, so it errs by at most ``u |step|`` (u = 2**-53)
    plus ``u**2`` of the samples' magnitude. Elementwise: LLVM vectorizes it.
    """
    x0 = rows[col, t0 : t0 + count - 1]
    x1 = rows[col, t0 + m : t0 + m + count - 1]
    x2 = rows[col, t0 + 2 * m : t0 + 2 * m + count - 1]
    g = out[: count - 1]
    if sc == 1.0:  # the usual case: the products fold away
        for i in range(count - 1):
            g[i] = _second_difference(x2[i], x1[i], x0[i], 1.0)
    else:
        for i in range(count - 1):
            g[i] = _second_difference(x2[i], x1[i], x0[i], sc)
    out[count - 1] = 0.0


#: Independent running sums of :func:`chained_squares` (they hide the latency of the adds).
CHAINS = 8


@njit(cache=True, fastmath={"reassoc", "contract"})
def _plain_sum(g, lo, hi):
    total = 0.0
    x = g[lo:hi]
    for i in range(hi - lo):
        total += x[i]
    return total


@njit(cache=True)
def chained_squares(start, steps, count):
    """Sum over ``i < count`` of ``D_i**2`` where ``D_0 = start`` and ``D_{i+1} = D_i + steps[i]``.

    The running value is ``D`` itself, so each addition errs by at most ``u |D|``: the
    sum errs by at most ``2 count u`` relative, however large the samples or the
    cumulative sum. The block runs as :data:`CHAINS` stretches whose starting values
    come from the stretches' plain sums of steps, so the additions do not wait for one
    another (a single running sum is bound by the latency of one add per sample).
    """
    q = count // CHAINS
    if q < 4:
        d = start
        total = 0.0
        for i in range(count):
            total += d * d
            d += steps[i]
        return total
    d0 = start
    d1 = d0 + _plain_sum(steps, 0, q)
    d2 = d1 + _plain_sum(steps, q, 2 * q)
    d3 = d2 + _plain_sum(steps, 2 * q, 3 * q)
    d4 = d3 + _plain_sum(steps, 3 * q, 4 * q)
    d5 = d4 + _plain_sum(steps, 4 * q, 5 * q)
    d6 = d5 + _plain_sum(steps, 5 * q, 6 * q)
    d7 = d6 + _plain_sum(steps, 6 * q, 7 * q)
    s0 = s1 = s2 = s3 = s4 = s5 = s6 = s7 = 0.0
    g0 = steps[0:q]
    g1 = steps[q : 2 * q]
    g2 = steps[2 * q : 3 * q]
    g3 = steps[3 * q : 4 * q]
    g4 = steps[4 * q : 5 * q]
    g5 = steps[5 * q : 6 * q]
    g6 = steps[6 * q : 7 * q]
    g7 = steps[7 * q : 8 * q]
    for i in range(q):
        s0 += d0 * d0
        d0 += g0[i]
        s1 += d1 * d1
        d1 += g1[i]
        s2 += d2 * d2
        d2 += g2[i]
        s3 += d3 * d3
        d3 += g3[i]
        s4 += d4 * d4
        d4 += g4[i]
        s5 += d5 * d5
        d5 += g5[i]
        s6 += d6 * d6
        d6 += g6[i]
        s7 += d7 * d7
        d7 += g7[i]
    rest = steps[8 * q : count]
    for i in range(count - 8 * q):
        s7 += d7 * d7
        d7 += rest[i]
    return ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7))


@njit(cache=True, inline="always")
def _base(th, tl, col, k0, k1, k2):
    """``S[k2 F] - 2 S[k1 F] + S[k0 F]`` from the table (granularity ``F``), as a double-double."""
    s, e = _two_sum(th[col, k2], -2.0 * th[col, k1])
    s, e2 = _two_sum(s, th[col, k0])
    return s, (e + e2) + ((tl[col, k2] - 2.0 * tl[col, k1]) + tl[col, k0])


@njit(cache=True)
def plain_second_differences(rows, col, t0, m, count, sc, out):
    """Plain float64 steps ``out[i] = (x2 sc - x1 sc) - (x1 sc - x0 sc)`` with
    ``x_j = x[t0 + i + j m]``, for ``i < count - 1``; ``out[count - 1] = 0``.

    Each of the three subtractions errs by at most ``u`` times its exact result
    (u = 2**-53; the power-of-two ``sc`` is exact), so for any centre ``c`` a step
    errs by at most ``u (|x2 - x1| + |x1 - x0| + (1 + u)(|x2 - x1| + |x1 - x0|))
    <= 2.01 u (r2 + 2 r1 + r0)`` where ``r_j >= |x_j sc - c|`` (:func:`step_error_bound`).
    Differences of near samples are exact (Sterbenz). Elementwise: LLVM vectorizes
    it, at about two thirds the cost of :func:`second_differences`. Not for 64-bit
    integers (not exact in one float64).
    """
    x0 = rows[col, t0 : t0 + count - 1]
    x1 = rows[col, t0 + m : t0 + m + count - 1]
    x2 = rows[col, t0 + 2 * m : t0 + 2 * m + count - 1]
    g = out[: count - 1]
    for i in range(count - 1):
        a = np.float64(x2[i]) * sc - np.float64(x1[i]) * sc
        b = np.float64(x1[i]) * sc - np.float64(x0[i]) * sc
        g[i] = a - b
    out[count - 1] = 0.0


@njit(cache=True, inline="always")
def step_error_bound(r0, r1, r2, count):
    """Bound on the accumulated error of ``count`` steps of :func:`plain_second_differences`
    whose samples ``x_j`` lie within ``r_j`` of a common centre:
    ``2.5 u count (r2 + 2 r1 + r0)`` (2.01 per step, rounded up generously)."""
    return 2.5 * _EPS * count * (r2 + 2.0 * r1 + r0)


@njit(cache=True)
def far_task(rows, col, first, stride, sc, th, tl, spread, factors, nd, fine, tol, out_row):
    """Adds to ``out_row`` the sums of ``D**2`` of every level over the pieces
    ``first, first + stride, ...`` (pieces of ``fine`` samples, level ``k`` its
    differences ``0 .. nd[k] - 1``). ``spread[col, q]`` bounds ``|x sc - centre|`` over piece ``q``."""
    steps = np.empty(fine)
    wide = _is_wide(rows[col, 0])  # 64-bit integers: every step exact from the start
    q = first
    while q * fine < nd[0]:
        t0 = q * fine
        for k in range(factors.shape[0]):
            cnt = min(fine, nd[k] - t0)
            if cnt <= 0:
                break  # larger levels have fewer differences
            m = factors[k]
            o = m // fine
            ch, cl = _base(th, tl, col, q, q + o, q + 2 * o)
            if not wide:
                plain_second_differences(rows, col, t0, m, cnt, sc, steps)
                total = chained_squares(ch + cl, steps, cnt)
                delta = step_error_bound(spread[col, q], spread[col, q + o], spread[col, q + 2 * o], cnt)
                if certified(total, delta, cnt, tol):
                    out_row[k] += total
                    continue
            second_differences(rows, col, t0, m, cnt, sc, steps)
            out_row[k] += chained_squares(ch + cl, steps, cnt)
        q += stride


@njit(cache=True, parallel=True)
def far_sums(rows, scale, th, tl, spread, factors, nd, fine, tol=CERTIFY_TOL):
    """Sums of ``D**2`` per (column, level), shape (C, L), for ``factors`` strictly
    increasing multiples of the smallest, itself a multiple of ``fine``; ``nd`` the
    numbers of differences (all > 0). ``rows``: the input transposed (C, N);
    ``th, tl, spread``: :func:`avar._kernels.streaming.block_table` at granularity ``fine``."""
    channels = rows.shape[0]
    classes = factors[0] // fine
    out = np.zeros((channels, classes, factors.shape[0]))
    for task in prange(channels * classes):
        c = task // classes
        a = task % classes
        far_task(rows, c, a, classes, scale[c], th, tl, spread, factors, nd, fine, tol, out[c, a])
    result = np.zeros((channels, factors.shape[0]))
    for c in range(channels):
        for a in range(classes):
            result[c] += out[c, a]
    return result
