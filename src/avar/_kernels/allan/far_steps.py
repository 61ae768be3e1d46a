"""The far levels' exact path (numba): pieces whose plain local prefixes fail their certificate.

:mod:`avar._kernels.allan.far` sums a piece's squared differences from plain local prefixes
when their error bound allows it; a piece that fails (a ``D`` tiny against its samples'
excursion: a component periodic in ``m`` far above the noise, say), and every piece of
64-bit integers (not exact in one float64), is only marked there. The pieces marked are
redone here, after the pass: their steps ``x[t+2m] - 2 x[t+m] + x[t]`` each rounded once
(:func:`second_differences`, TwoSum) drive the running ``D`` (:func:`chained_squares`),
so each addition errs by at most ``u |D|``, whatever the offset or the excursion of ``S``.
Most series never need it: it compiles only when a piece is marked.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numba.extending import overload

from avar._kernels.allan.blocks import Pair
from avar._kernels.allan.haar import exact_pair
from avar._kernels.dd import two_sum
from avar._kernels.runtime.tasks import run_tasks


def _second_difference(x2, x1, x0, sc):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_second_difference, inline="always")
def _second_difference_overload(x2, x1, x0, sc):
    """``(x2 - 2 x1 + x0) * sc`` rounded once (TwoSum; 64-bit integers enter as two exact halves)."""
    if isinstance(x2, types.Integer) and x2.bitwidth == 64:

        def impl(x2, x1, x0, sc):
            h2, l2 = exact_pair(x2, sc)
            h1, l1 = exact_pair(x1, sc)
            h0, l0 = exact_pair(x0, sc)
            a, ea = two_sum(h2, h0)
            b, eb = two_sum(a, -2.0 * h1)
            return b + ((ea + eb) + ((l2 + l0) - 2.0 * l1))

        return impl

    def impl(x2, x1, x0, sc):
        a, ea = two_sum(np.float64(x2) * sc, np.float64(x0) * sc)
        b, eb = two_sum(a, -2.0 * (np.float64(x1) * sc))
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
    for i in range(count - 1):
        g[i] = _second_difference(x2[i], x1[i], x0[i], sc)
    out[count - 1] = 0.0


@njit(cache=True, fastmath={"reassoc", "contract"})
def _plain_sum(g):
    total = 0.0
    for i in range(g.shape[0]):
        total += g[i]
    return total


@njit(cache=True)
def chained_squares(start, steps, count):
    """Sum over ``i < count`` of ``D_i**2`` where ``D_0 = start`` and ``D_{i+1} = D_i + steps[i]``.

    The running value is ``D`` itself, so each addition errs by at most ``u |D|``: the
    sum errs by at most ``2 count u`` relative, however large the samples or the
    cumulative sum. The block runs as two halves, the second starting from the plain sum
    of the first half's steps, so that the two running sums do not wait for each other
    (one is bound by the latency of an add per sample; more halves compiled slower, for
    no gain on this rarely taken path).
    """
    q = count // 2
    g0 = steps[:q]
    g1 = steps[q : 2 * q]
    d0 = start
    d1 = start + _plain_sum(g0)
    s0 = 0.0
    s1 = 0.0
    for i in range(q):
        s0 += d0 * d0
        d0 += g0[i]
        s1 += d1 * d1
        d1 += g1[i]
    if count > 2 * q:
        s1 += d1 * d1
    return s0 + s1


@njit(cache=True, inline="always")
def table_base(th, tl, col, k0, k1, k2):
    """``S[k2 F] - 2 S[k1 F] + S[k0 F]`` from the table (granularity ``F``), as a double-double :class:`Pair`."""
    s, e = two_sum(th[col, k2], -2.0 * th[col, k1])
    s, e2 = two_sum(s, th[col, k0])
    return Pair(s, (e + e2) + ((tl[col, k2] - 2.0 * tl[col, k1]) + tl[col, k0]))


@njit(cache=True, nogil=True)
def exact_pieces(rows, cols, pieces, levels, first, stop, scale, th, tl, factors, nd, fine, out):
    """``out[i]``: the sum of ``D**2`` of piece ``pieces[i]`` (``fine`` samples) of column
    ``cols[i]`` at level ``factors[levels[i]]``, for ``i = first .. stop - 1``, by the exact steps."""
    steps = np.empty(fine)
    for i in range(first, stop):
        col = cols[i]
        q = pieces[i]
        m = factors[levels[i]]
        o = m // fine
        t0 = q * fine
        count = min(fine, nd[levels[i]] - t0)
        ch, cl = table_base(th, tl, col, q, q + o, q + 2 * o)
        second_differences(rows, col, t0, m, count, scale[col], steps)
        out[i] = chained_squares(ch + cl, steps, count)


#: Marked pieces per task of :func:`exact_sums`.
PIECES_PER_TASK = 64

#: At most this many marked pieces (of samples exact in one float64) are redone in NumPy,
#: which has nothing to compile: a few pieces fail the certificate by chance in most long
#: series (a piece where ``D`` stays near zero), many only in a few kinds of data.
NUMPY_PIECES = 256


def exact_sums(rows, marked, scale, th, tl, factors, nd, fine):
    """Sums of ``D**2`` per (column, level) of the pieces ``marked`` (C, pieces, L) by
    the exact steps, added in the order of the pieces (the bits do not depend on the threads)."""
    cols, pieces, levels = np.nonzero(marked)
    if cols.shape[0] <= NUMPY_PIECES and (rows.dtype.itemsize < 8 or rows.dtype == np.float64):
        sums = numpy_pieces(rows, cols, pieces, levels, scale, th, tl, factors, nd, fine)
    else:
        sums = np.empty(cols.shape[0])
        n_tasks = -(-cols.shape[0] // PIECES_PER_TASK)

        def task(t):
            exact_pieces(rows, cols, pieces, levels, t * PIECES_PER_TASK,
                         min(cols.shape[0], (t + 1) * PIECES_PER_TASK), scale, th, tl, factors, nd, fine, sums)

        run_tasks(n_tasks, task)
    out = np.zeros((marked.shape[0], marked.shape[2]))
    np.add.at(out, (cols, levels), sums)  # one by one, in index order
    return out


def _two_sums(a, b):
    """TwoSum, elementwise: ``a + b`` and its rounding error."""
    s = a + b
    bv = s - a
    return s, (a - (s - bv)) + (b - bv)


def numpy_pieces(rows, cols, pieces, levels, scale, th, tl, factors, nd, fine):
    """:func:`exact_pieces` of every given piece at once, in NumPy (samples exact in one float64).

    The same steps, each rounded once, and the same double-double start; the running ``D``
    is a cumulative sum started from it (each addition errs by at most ``u |D|``).
    """
    m = factors[levels][:, None]
    t0 = (pieces * fine)[:, None]
    count = np.minimum(fine, nd[levels] - pieces * fine)[:, None]
    i = np.arange(fine)[None, :]
    step = i < count - 1  # the steps between the piece's differences
    at = np.where(step, t0 + i, 0)
    c = cols[:, None]
    sc = scale[cols][:, None]
    with np.errstate(all="ignore"):
        x0, x1, x2 = (rows[c, np.where(step, at + k * m, 0)].astype(np.float64) * sc for k in range(3))
        a, ea = _two_sums(x2, x0)
        b, eb = _two_sums(a, -2.0 * x1)
        g = np.where(step, b + (ea + eb), 0.0)
        o = (m // fine)[:, 0]
        q = pieces
        s, e = _two_sums(th[cols, q + 2 * o], -2.0 * th[cols, q + o])
        s, e2 = _two_sums(s, th[cols, q])
        start = s + ((e + e2) + ((tl[cols, q + 2 * o] - 2.0 * tl[cols, q + o]) + tl[cols, q]))
        d = np.cumsum(np.concatenate([start[:, None], g[:, :-1]], axis=1), axis=1)  # D_0 .. D_{fine-1}
        return np.sum(np.where(i < count, d * d, 0.0), axis=1)
