"""Maximal-overlap Allan variance of power-of-two cluster sizes: one cache-blocked sweep (numba).

For a cluster size ``m`` the differences are ``D_t = S[t+2m] - 2 S[t+m] + S[t]``
(``S`` the centred cumulative sum). Time is cut into blocks of
:data:`SWEEP_BLOCK` samples; a task sweeps a run of consecutive blocks and,
for each block, serves every level:

* small levels (``m < SWEEP_NEAR``) from one sliding window of the centred
  ``S`` (block plus a halo of ``2 m``), computed once per sample;
* large levels (``m`` a multiple of the block) from the recurrence

      D_{t0} = S[t0+2m] - 2 S[t0+m] + S[t0]   (exact double-double, from the block table)
      D_{t+1} = D_t + (x[t+2m] - 2 x[t+m] + x[t])

  Each step is rounded once (:func:`second_differences`, TwoSum), and the
  running value is ``D`` itself, never a cumulative sum, so every addition
  errs by at most ``u |D|``: over a block of ``B`` samples each ``D`` errs by
  at most about ``B u (max |D| + sum |steps|)`` (``B u`` = 1e-12 for the
  default block), whatever the offset or the excursion of ``S``.
  :func:`chained_squares` runs the block as :data:`CHAINS` independent
  stretches so the additions do not wait on one another. A level reads three
  streams of the input once, about one read of the input per level.

The block table (exact double-double ``S`` at every block boundary) comes
from :func:`avar._kernels.streaming.block_table`; the sums of every task are
added in a fixed order, so the bits do not depend on the number of threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange, types
from numba.extending import overload

from avar._kernels.haar import _pair
from avar._kernels.streaming import _two_sum, window_level_sums

#: Samples per block: the table's granularity, the steps of a large level per block, the window's advance.
SWEEP_BLOCK = 1 << 13

#: Levels below this cluster size are served by the sliding window (a power of
#: two, at least the block): the window is the block plus a halo of 2 m.
SWEEP_NEAR = 1 << 15

#: Blocks per parallel task (fixes the summation order).
SWEEP_CHUNK = 32


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
    """``S[k2 B] - 2 S[k1 B] + S[k0 B]`` from the table, as a double-double."""
    s, e = _two_sum(th[col, k2], -2.0 * th[col, k1])
    s, e2 = _two_sum(s, th[col, k0])
    return s, (e + e2) + ((tl[col, k2] - 2.0 * tl[col, k1]) + tl[col, k0])


@njit(cache=True)
def sweep_task(data, rows, col, kb0, kb1, centre, scale, th, tl, factors, nd, n_small, out_row, block):
    """Sums of ``D**2`` of every level for the differences starting in blocks ``kb0 .. kb1 - 1``."""
    n = data.shape[0]
    n_levels = factors.shape[0]
    halo = 2 * factors[n_small - 1] if n_small > 0 else 0
    cap = 2 * (block + halo) + 1
    wh = np.empty(cap)
    wl = np.empty(cap)
    steps = np.empty(block)
    buffer = np.empty(block)
    bounds = np.zeros(2)  # largest |S| hi and lo parts the window has held
    w0 = kb0 * block
    filled = 0
    # The window holds S less S[kb0 B] (differences need no anchor): its values stay the
    # size of the task's own excursion, which lets certified_squares use plain sums.
    wh[0] = 0.0
    wl[0] = 0.0
    for kb in range(kb0, kb1):
        t0 = kb * block
        if t0 >= nd[0]:
            break
        if n_small > 0:
            w0, filled = window_level_sums(data, col, t0, min(n, t0 + block + halo), centre, scale, wh, wl, w0,
                                           filled, factors, nd, n_small, block, out_row, buffer, bounds)
        if n_small == n_levels or nd[n_small] <= t0:
            continue
        # large levels: D at the block start from the table, then its steps
        for k in range(n_small, n_levels):
            cnt = min(block, nd[k] - t0)
            if cnt <= 0:
                break
            o = factors[k] // block
            second_differences(rows, col, t0, factors[k], cnt, scale, steps)
            ch, cl = _base(th, tl, col, kb, kb + o, kb + 2 * o)
            out_row[k] += chained_squares(ch + cl, steps, cnt)
    return out_row


@njit(cache=True, parallel=True)
def sweep_sums(data, rows, centre, scale, th, tl, factors, nd, n_small, block, chunk):
    """Sums of ``D**2`` per (column, level), shape (C, L).

    ``factors`` strictly increasing, those from index ``n_small`` on multiples
    of ``block`` (octave grids: powers of two); ``nd`` the numbers of
    differences, all > 0.
    """
    channels = data.shape[1]
    n_blocks = (nd[0] + block - 1) // block
    n_chunks = (n_blocks + chunk - 1) // chunk
    out = np.zeros((channels, n_chunks, factors.shape[0]))
    for task in prange(channels * n_chunks):
        c = task // n_chunks
        j = task % n_chunks
        sweep_task(data, rows, c, j * chunk, min(n_blocks, (j + 1) * chunk), centre[c], scale[c], th, tl, factors, nd,
                   n_small, out[c, j], block)
    result = np.zeros((channels, factors.shape[0]))
    for c in range(channels):
        for j in range(n_chunks):
            result[c] += out[c, j]
    return result
