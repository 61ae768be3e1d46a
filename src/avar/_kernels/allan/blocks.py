"""Streaming Allan variance kernels (numba): blocks of the series, a small reused workspace.

Nothing here validates input. The entry point is
:func:`avar._kernels.streaming_allan_variance`; it calls these kernels on any
real (N, C) array (float64, float32, any integer dtype, any memory layout,
memory-mapped) without converting it to float64 as a whole.

How it works
------------
Both estimators are sums of ``D**2`` with ``D = S[b+2m] - 2 S[b+m] + S[b]``
and ``S`` the cumulative sum of the centred series (see :mod:`allan`). The
full ``S`` (12 bytes a sample) is never stored:

1. one pass sums every block of ``BLOCK`` samples (compensated, exact for
   64-bit integers, which are split as ``hi * 2**32 + lo``; plain float32 sums
   where provably exact: :mod:`avar._kernels.allan.tablesums`) and finds the
   largest magnitude; an exact double-double scan of the block sums gives the
   centred ``S`` at every block boundary (the *table*, N / BLOCK entries);
2. "to": one more pass. Each time block rebuilds its ``S`` values in a small
   buffer from the table, and every level reads ``S`` at its cluster
   boundaries from it, carrying the last two boundaries' values across blocks;
3. "mo": levels with ``m <= NEAR`` read a sliding window of ``S`` (the
   block plus a halo of ``2 NEAR``) computed once per block; each larger level
   rebuilds ``S`` on the block shifted by ``m`` and ``2 m`` from the table
   (for octave grids the ``2 m`` region of one level is the ``m`` region of
   the next, so the input is read about once per large level).

Every ``S`` value is anchored at the exactly scanned table and accumulated
with TwoSum (``hi + lo``), so the differences keep the accuracy of the old
full cumulative sum. Work is split into (column, chunk of ``CHUNK_BLOCKS``
blocks) tasks whose sums are added in a fixed order: the bits do not depend
on the number of threads.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, types
from numba.extending import overload

from avar._kernels.allan.tablesums import block_sum, float32_table_task
from avar._kernels.dd import EPS, fast_sum, fast_two_sum, two_sum
from avar._kernels.runtime.tasks import run_tasks

#: Samples per block: table granularity and differences per inner step.
BLOCK = 4096

#: Largest cluster size served by the sliding near window ("mo").
NEAR = 4096

#: Blocks per parallel task (fixes the summation order).
CHUNK_BLOCKS = 64

#: Length of the sliding near window: halo plus four blocks.
NEAR_LEN = 2 * NEAR + 4 * BLOCK

#: Magnitudes outside [2**-LIMIT_EXP, 2**LIMIT_EXP] are rescaled by a power of two.
LIMIT_EXP = 400


class Pair(NamedTuple):
    """A double-double value ``hi + lo`` (``|lo|`` about an ulp of ``hi`` or less); built inside
    compiled kernels too (numba types a NamedTuple as a tuple)."""

    hi: float
    lo: float


class BlockTable(NamedTuple):
    """:func:`block_table`'s pass over the data: ``table_hi + table_lo`` (C, blocks + 1) the centred
    cumulative sum at every block boundary, ``centre`` (C,), ``maxabs`` (C,) the largest magnitude,
    ``spread`` (C, blocks) a bound on ``|x * scale - centre|`` over every block."""

    table_hi: np.ndarray
    table_lo: np.ndarray
    centre: np.ndarray
    maxabs: np.ndarray
    spread: np.ndarray


class Window(NamedTuple):
    """Where the sliding window of :func:`window_level_sums` starts (``start``, a sample index) and
    how many samples past it it holds (``filled``)."""

    start: int
    filled: int


def read_only(x: np.ndarray) -> np.ndarray:
    """``x``, or a read-only view of it: numba compiles a kernel once for read-only input
    rather than again for writable arrays of the same dtype and layout."""
    if x.flags.writeable:
        x = x.view()
        x.flags.writeable = False
    return x


def _centred(x, c, sc):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_centred, inline="always")
def _centred_overload(x, c, sc):
    """``x * sc - c`` as an exact pair ``(hi, lo)``; 64-bit integers split in two halves."""
    if isinstance(x, types.Integer) and x.bitwidth == 64:
        if x.signed:

            def impl(x, c, sc):
                a = np.float64(x >> 32) * 4294967296.0
                b = np.float64(x & 0xFFFFFFFF)
                s1, e1 = two_sum(a, -c)
                s2, e2 = two_sum(s1, b)
                return s2, e1 + e2

        else:

            def impl(x, c, sc):
                a = np.float64(x >> np.uint64(32)) * 4294967296.0
                b = np.float64(x & np.uint64(0xFFFFFFFF))
                s1, e1 = two_sum(a, -c)
                s2, e2 = two_sum(s1, b)
                return s2, e1 + e2

        return impl

    def impl(x, c, sc):
        return two_sum(np.float64(x) * sc, -c)

    return impl


#: Samples summed per parallel task of :func:`block_table` (whole blocks), at least.
TABLE_TASK = 1 << 16

#: At most this many tasks per column in :func:`block_table` (longer tasks beyond): their sums
#: are added in a Python loop, ~8 us a task (at N = 1e8, 1526 tasks took 12 ms, 256 take 2 ms).
TABLE_TASKS = 256


@njit(cache=True, nogil=True)
def table_task(data, col, b0, b1, block, scale, ph, pl, low, high):
    """Blocks ``b0 .. b1 - 1`` of column ``col``: ``ph, pl[col, b]`` the double-double sum of
    ``data * scale`` over blocks ``b0 .. b`` (each block's sum compensated), and every block's
    least and largest value (of the high parts, for 64-bit integers): :func:`avar._kernels.allan.tablesums.block_sum`."""
    n = data.shape[0]
    h = 0.0
    lo = 0.0
    for b in range(b0, b1):
        total, comp, low[col, b], high[col, b] = block_sum(data, col, b * block, min(n, (b + 1) * block), scale)
        s, e = two_sum(h, total)
        e += lo + comp
        h, lo = fast_two_sum(s, e)
        ph[col, b] = h
        pl[col, b] = lo


def block_table(data, scale, integral, block=BLOCK):
    """Pass 1 over all columns: a :class:`BlockTable` (table_hi, table_lo, centre, maxabs, spread).

    ``table_*`` have shape (C, ceil(N / block) + 1) with the centred
    cumulative sum of ``data * scale`` at every block boundary (and at N), in
    double-double; ``spread`` (C, ceil(N / block)) bounds ``|x * scale - centre|``
    over each block (rounded up: it bounds the rounding of the plain local prefix
    sums of :mod:`avar._kernels.allan.far`). An integer series gets an integer centre:
    every centred value, and so every sum, is then an integer held exactly.
    The tasks sum their blocks in the kernel; the rest (a value per task, then
    elementwise double-double arithmetic) is NumPy, with nothing to compile.
    """
    n, channels = data.shape
    nb = -(-n // block)
    per_task = max(1, TABLE_TASK // block, -(-nb // TABLE_TASKS))  # a function of N: the bits do not depend on threads
    n_tasks = -(-nb // per_task)
    ph, pl, low, high = (np.empty((channels, nb)) for _ in range(4))

    bits = data.T.view(np.int32) if data.dtype == np.float32 and np.all(scale == 1.0) else None  # plain where exact

    def task(t):
        c, j = divmod(t, n_tasks)
        if bits is not None:
            float32_table_task(data, data.T, bits, c, j * per_task, min(nb, (j + 1) * per_task), block, ph, pl, low, high)
        else:
            table_task(data, c, j * per_task, min(nb, (j + 1) * per_task), block, scale[c], ph, pl, low, high)

    run_tasks(channels * n_tasks, task)
    with np.errstate(all="ignore"):  # non-finite data: NaN or inf sums, which the caller reports
        # The tasks' sums added in order, then S at the end of every block.
        before = np.zeros((2, channels, n_tasks))
        for j in range(1, n_tasks):
            last = j * per_task - 1
            before[0, :, j], before[1, :, j] = _dd_add(before[0, :, j - 1], before[1, :, j - 1], ph[:, last],
                                                       pl[:, last])
        task_of = np.arange(nb) // per_task
        table_hi, table_lo = np.zeros((channels, nb + 1)), np.zeros((channels, nb + 1))
        _dd_add(before[0][:, task_of], before[1][:, task_of], ph, pl, out_hi=table_hi[:, 1:], out_lo=table_lo[:, 1:])
        centre = (table_hi[:, nb] + table_lo[:, nb]) / n
        if integral:
            centre = np.round(centre)
        table_hi, table_lo = _less_centre(table_hi, table_lo, centre[:, None], block, n)
        maxabs = np.max(np.maximum(-low, high), axis=1)
        spread = np.maximum(high - centre[:, None], centre[:, None] - low) * (1.0 + 2.0**-40)
    return BlockTable(table_hi, table_lo, centre, maxabs, spread)


def _dd_add(ah, al, bh, bl, out_hi=None, out_lo=None):
    """``(ah + al) + (bh + bl)`` as a renormalized pair (elementwise): TwoSum of the high
    parts, then the low parts and the error added; written to ``out_hi, out_lo`` when given
    (they may be ``ah, al``).

    Three temporaries, operations in place: a fresh page costs about a microsecond, and at
    N = 1e8 (tables of 1e5 entries) the expression form's ten temporaries took 5 ms a call.
    """
    s = np.add(ah, bh)
    bv = np.subtract(s, ah)
    e = np.subtract(s, bv)
    np.subtract(ah, e, out=e)  # ah - (s - bv)
    np.subtract(bh, bv, out=bv)
    np.add(e, bv, out=e)
    np.add(al, bl, out=bv)
    np.add(e, bv, out=e)  # ((ah - (s - bv)) + (bh - bv)) + (al + bl)
    h = np.add(s, e, out=out_hi)
    np.subtract(h, s, out=s)
    return h, np.subtract(e, s, out=out_lo)  # e - (h - s)


def _less_centre(th, tl, centre, block, n):
    """``S[k block] - min(k block, N) * centre`` exactly (Dekker's product), as pairs, in place."""
    big = centre * 134217729.0  # Dekker split of the centre for exact products p * centre
    c_hi = big - (big - centre)
    c_lo = centre - c_hi
    p = np.minimum(np.arange(th.shape[1]) * block, n).astype(np.float64)
    bp = p * 134217729.0  # p < 2**53 is split the same way
    p_hi = bp - (bp - p)
    p_lo = np.subtract(p, p_hi, out=bp)
    minus_ph = np.multiply(p, centre)
    np.negative(minus_ph, out=minus_ph)
    minus_pe = np.multiply(p_hi, c_hi)  # -(the exact error of p * centre), term by term:
    np.add(minus_pe, minus_ph, out=minus_pe)  # ((p_hi c_hi - ph) + p_hi c_lo + p_lo c_hi) + p_lo c_lo
    minus_pe += p_hi * c_lo
    minus_pe += p_lo * c_hi
    minus_pe += p_lo * c_lo
    np.negative(minus_pe, out=minus_pe)
    return _dd_add(th, tl, minus_ph, minus_pe, out_hi=th, out_lo=tl)


@njit(cache=True, inline="always")
def fill_prefix(data, col, start, stop, centre, scale, s_hi, s_lo, out_hi, out_lo, at, bounds):
    """``out[at + i] = S[start + i]`` for ``i = 0 .. stop - start`` from ``S[start] = (s_hi, s_lo)``.

    Stored renormalized (``out_hi`` is ``S`` rounded to float64, ``out_lo`` the
    rest), so that :func:`certified_squares` can use ``out_hi`` alone; ``bounds``
    is raised to the largest ``|out_hi|`` and ``|out_lo|`` written. (Prefixes that
    only :func:`squares` reads need neither: :func:`fill_running`.)

    (Loops run over slices with ``range(count)``: non-negative indices, so
    numba emits no wraparound checks and LLVM can vectorize the loads.)
    """
    count = stop - start
    x = data[start:stop, col]
    oh = out_hi[at + 1 : at + 1 + count]
    ol = out_lo[at + 1 : at + 1 + count]
    total = s_hi
    comp = s_lo
    out_hi[at] = total
    out_lo[at] = comp
    big_h = max(bounds[0], abs(total))
    big_l = max(bounds[1], abs(comp))
    for i in range(count):
        yh, yl = _centred(x[i], centre, scale)
        total, e = two_sum(total, yh)
        comp += e + yl
        h, l = two_sum(total, comp)  # stored renormalized: h the rounded S, |l| <= ulp / 2
        oh[i] = h
        ol[i] = l
        big_h = max(big_h, abs(h))
        big_l = max(big_l, abs(l))
    bounds[0] = big_h
    bounds[1] = big_l


@njit(cache=True, inline="always")
def fill_running(data, col, start, stop, centre, scale, s_hi, s_lo, out_hi, out_lo, at):
    """:func:`fill_prefix` stored as the running sum and its compensation, not
    renormalized, and no magnitudes kept: two operations less per sample, for
    prefixes that only :func:`squares` reads."""
    count = stop - start
    x = data[start:stop, col]
    oh = out_hi[at + 1 : at + 1 + count]
    ol = out_lo[at + 1 : at + 1 + count]
    total = s_hi
    comp = s_lo
    out_hi[at] = total
    out_lo[at] = comp
    for i in range(count):
        yh, yl = _centred(x[i], centre, scale)
        total, e = two_sum(total, yh)
        comp += e + yl
        oh[i] = total
        ol[i] = comp


@njit(cache=True)
def point(data, col, p, centre, scale, table_hi, table_lo, block):
    """Centred ``S[p]`` as a :class:`Pair` ``(hi, lo)``: the table entry below ``p`` plus a partial block."""
    q = p // block
    total = table_hi[col, q]
    comp = table_lo[col, q]
    x = data[q * block : p, col]
    for i in range(p - q * block):
        yh, yl = _centred(x[i], centre, scale)
        total, e = two_sum(total, yh)
        comp += e + yl
    return Pair(total, comp)


@njit(cache=True, inline="always")
def squares(h0, l0, a0, h1, l1, a1, h2, l2, a2, count, buffer):
    """Sum over ``j < count`` of ``D_j**2`` from three windows of ``S`` (compensated differences)."""
    x0 = h0[a0 : a0 + count]
    x1 = h1[a1 : a1 + count]
    x2 = h2[a2 : a2 + count]
    y0 = l0[a0 : a0 + count]
    y1 = l1[a1 : a1 + count]
    y2 = l2[a2 : a2 + count]
    for j in range(count):
        d = ((x2[j] - x1[j]) - (x1[j] - x0[j])) + ((y2[j] - y1[j]) - (y1[j] - y0[j]))
        buffer[j] = d * d
    return fast_sum(buffer, count)


#: Relative bound on the error of a plain (float64) sum of squared differences accepted by
#: :func:`certified_squares`; beyond it the compensated :func:`squares` runs.
CERTIFY_TOL = 1e-11


@njit(cache=True, fastmath={"reassoc", "contract"})
def prefix_squares(p0, p1, p2, base_hi, base_lo, count):
    """Sum over ``i < count`` of ``D_i**2``, ``D_i = base + (p2[i] - 2 p1[i] + p0[i])`` (vectorized).

    Any association of the six terms is allowed (``reassoc``): the caller's error bound
    (:func:`certified_squares`, through :func:`plain_squares`) holds for every one of them.
    """
    a = p0[:count]
    b = p1[:count]
    c = p2[:count]
    total = 0.0
    for i in range(count):
        d = (base_hi + ((c[i] - b[i]) - (b[i] - a[i]))) + base_lo
        total += d * d
    return total


@njit(cache=True, inline="always")
def plain_squares(h, a, m, count):
    """Sum over ``j < count`` of ``(h[a+j+2m] - 2 h[a+j+m] + h[a+j])**2`` in plain float64 (vectorized):
    :func:`prefix_squares` with a zero base (the zeros add exactly; one function compiles
    instead of two)."""
    return prefix_squares(h[a:], h[a + m :], h[a + 2 * m :], 0.0, 0.0, count)


@njit(cache=True, inline="always")
def certified(total, delta, count, tol):
    """Whether ``count`` squares summing to ``total`` are within ``tol`` (relative) of
    their exact sum when every squared value errs by at most ``delta``: the bound
    ``2 delta sqrt(count total) + count delta**2`` (Cauchy-Schwarz). False for a zero,
    infinite or NaN ``total`` (the caller then takes its exact path)."""
    bound = 2.0 * delta * np.sqrt(count * total) + count * delta * delta
    return total > 0.0 and np.isfinite(total) and bound <= tol * total


@njit(cache=True, inline="always")
def certified_squares(h, l, a, m, count, buffer, bounds):
    """:func:`squares` of one window (``S = h + l`` at offsets a, a + m, a + 2m) by the plain
    :func:`plain_squares` of ``h`` alone when its error is provably below :data:`CERTIFY_TOL`.

    Every term then errs by at most ``delta = 4 max|l| + 9 u max|h|`` (u = 2**-53;
    ``bounds``: those maxima over the window, from :func:`fill_prefix`): dropping ``l``
    costs ``4 max|l|``, and any association of ``h2 - 2 h1 + h0`` rounds twice on values
    of at most ``4 max|h|`` (``8 u max|h|``, to first order). So the sum of ``count``
    squares errs by at most
    ``2 delta sqrt(count * sum) + count delta**2``. White-noise-like data pass; a large
    excursion of the centred cumulative sum (drift, offset, random walk) takes the
    compensated path, so the result keeps its accuracy either way. ``buffer``: the
    compensated path's workspace (allocated here if shorter than ``count``).
    """
    total = plain_squares(h, a, m, count)
    if certified(total, 4.0 * bounds[1] + 9.0 * EPS * bounds[0], count, CERTIFY_TOL):
        return total
    if buffer.shape[0] < count:  # a workspace only when needed
        buffer = np.empty(count)
    return squares(h, l, a, h, l, a + m, h, l, a + 2 * m, count, buffer)


@njit(cache=True, inline="always")
def window_level_sums(data, col, t0, need, centre, scale, wh, wl, w0, filled, factors, nd, count, block, out_row,
                      buffer, bounds):
    """Squared second differences of the first ``count`` levels for the block at ``t0``, from a sliding window.

    The window holds the compensated prefix sums ``S[w0 .. w0 + filled]`` in ``wh``/``wl``; it slides to
    start at ``t0`` when ``need`` would overrun its length and is filled up to ``need``. Adds into
    ``out_row[:count]`` and returns the new :class:`Window` ``(w0, filled)``. ``bounds``: the largest
    ``|wh|`` and ``|wl|`` the window has held (for :func:`certified_squares`; kept by the caller).
    """
    if need - w0 >= wh.shape[0]:
        shift = t0 - w0
        for i in range(filled + 1 - shift):
            wh[i] = wh[i + shift]
            wl[i] = wl[i + shift]
        w0 = t0
        filled -= shift
    if w0 + filled < need:
        fill_prefix(data, col, w0 + filled, need, centre, scale, wh[filled], wl[filled], wh, wl, filled, bounds)
        filled = need - w0
    a = t0 - w0
    for k in range(count):
        cnt = min(block, nd[k] - t0)
        if cnt > 0:
            out_row[k] += certified_squares(wh, wl, a, factors[k], cnt, buffer, bounds)
    return Window(w0, filled)
