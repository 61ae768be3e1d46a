"""Maximal-overlap Allan variance of power-of-two cluster sizes: one cache-blocked sweep (numba).

For a cluster size ``m`` the differences are ``D_t = S[t+2m] - 2 S[t+m] + S[t]``
(``S`` the centred cumulative sum). Time is cut into blocks of
:data:`SWEEP_BLOCK` samples; a task sweeps a run of consecutive blocks and,
for each block, serves every level:

* small levels (``m < SWEEP_NEAR``) from one sliding window of the centred
  ``S`` (block plus a halo of ``2 m``), computed once per sample;
* large levels (``m`` a multiple of the block) from *regions*: the block
  itself and the blocks ``m`` and ``2 m`` later. Each region gets a local
  compensated prefix of the raw samples ``L(i)``, and

      D_{t0+i} = C + (L_2m(i) - 2 L_m(i) + L_0(i)),
      C = S[t0+2m] - 2 S[t0+m] + S[t0]   (double-double, from the block table)

  (the centring term ``i * centre`` cancels exactly in the second
  difference, so the regions need no centring). For octave grids the ``2 m``
  region of one level is the ``m`` region of the next, so each large level
  costs one region prefix: about one read of the input per level, each
  region loaded into the cache once per block.

The block table (exact double-double ``S`` at every block boundary) comes
from :func:`avar._kernels.streaming.block_table`; the sums of every task are
added in a fixed order, so the bits do not depend on the number of threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange, types
from numba.extending import overload

from avar._kernels.haar import _pair
from avar._kernels.streaming import _fast_sum, _two_sum, window_level_sums

#: Samples per block (region alignment, table granularity).
SWEEP_BLOCK = 1 << 13

#: Levels below this cluster size are served by the sliding window (a power of
#: two, at least the block): the window is the block plus a halo of 2 m.
SWEEP_NEAR = 1 << 15

#: Blocks per parallel task (fixes the summation order).
SWEEP_CHUNK = 32


def _add_raw(total, comp, x, sc):  # pragma: no cover - replaced by the overload in compiled code
    raise NotImplementedError


@overload(_add_raw, inline="always")
def _add_raw_overload(total, comp, x, sc):
    """``(total, comp) + x * sc`` compensated (64-bit integers enter as two exact halves)."""
    if isinstance(x, types.Integer) and x.bitwidth == 64:

        def impl(total, comp, x, sc):
            a, b = _pair(x, sc)
            total, e = _two_sum(total, a)
            return total, comp + (e + b)

        return impl

    def impl(total, comp, x, sc):
        total, e = _two_sum(total, np.float64(x) * sc)
        return total, comp + e

    return impl


@njit(cache=True)
def raw_prefix(data, col, start, count, sc, oh, ol):
    """``oh/ol[i]`` = compensated sum of ``data[start:start+i, col] * sc``, ``i < count``."""
    x = data[start : start + count - 1, col]
    h = oh[1:count]
    l = ol[1:count]
    oh[0] = 0.0
    ol[0] = 0.0
    total = 0.0
    comp = 0.0
    if sc == 1.0:  # the usual case: the product folds away
        for i in range(count - 1):
            total, comp = _add_raw(total, comp, x[i], 1.0)
            h[i] = total
            l[i] = comp
    else:
        for i in range(count - 1):
            total, comp = _add_raw(total, comp, x[i], sc)
            h[i] = total
            l[i] = comp


@njit(cache=True)
def based_squares(ch, cl, h0, l0, h1, l1, h2, l2, count, buffer):
    """Sum over ``i < count`` of ``(C + L2(i) - 2 L1(i) + L0(i))**2``, all compensated."""
    x0 = h0[:count]
    x1 = h1[:count]
    x2 = h2[:count]
    y0 = l0[:count]
    y1 = l1[:count]
    y2 = l2[:count]
    for i in range(count):
        d = (ch + ((x2[i] - x1[i]) - (x1[i] - x0[i]))) + (cl + ((y2[i] - y1[i]) - (y1[i] - y0[i])))
        buffer[i] = d * d
    return _fast_sum(buffer, count)


@njit(cache=True, inline="always")
def _base(th, tl, col, k0, k1, k2):
    """``S[k2 B] - 2 S[k1 B] + S[k0 B]`` from the table, as a double-double."""
    s, e = _two_sum(th[col, k2], -2.0 * th[col, k1])
    s, e2 = _two_sum(s, th[col, k0])
    return s, (e + e2) + ((tl[col, k2] - 2.0 * tl[col, k1]) + tl[col, k0])


@njit(cache=True)
def sweep_task(data, col, kb0, kb1, centre, scale, th, tl, factors, nd, n_small, out_row, block):
    """Sums of ``D**2`` of every level for the differences starting in blocks ``kb0 .. kb1 - 1``."""
    n = data.shape[0]
    n_levels = factors.shape[0]
    halo = 2 * factors[n_small - 1] if n_small > 0 else 0
    cap = 2 * (block + halo) + 1
    wh = np.empty(cap)
    wl = np.empty(cap)
    rh = np.empty((3, block))
    rl = np.empty((3, block))
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
        # large levels: region 0 (this block), then the m and 2m regions level by level
        raw_prefix(data, col, t0, min(block, nd[n_small] - t0), scale, rh[0], rl[0])
        mid = 1
        held = -1  # offset (in blocks) of the region in rh[mid]
        for k in range(n_small, n_levels):
            cnt = min(block, nd[k] - t0)
            if cnt <= 0:
                break
            o = factors[k] // block
            if held != o:  # not the 2m region of the level before (a grid with gaps)
                raw_prefix(data, col, t0 + o * block, cnt, scale, rh[mid], rl[mid])
            far = 3 - mid
            raw_prefix(data, col, t0 + 2 * o * block, cnt, scale, rh[far], rl[far])
            ch, cl = _base(th, tl, col, kb, kb + o, kb + 2 * o)
            out_row[k] += based_squares(ch, cl, rh[0], rl[0], rh[mid], rl[mid], rh[far], rl[far], cnt, buffer)
            mid = far
            held = 2 * o
    return out_row


@njit(cache=True, parallel=True)
def sweep_sums(data, centre, scale, th, tl, factors, nd, n_small, block, chunk):
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
        sweep_task(data, c, j * chunk, min(n_blocks, (j + 1) * chunk), centre[c], scale[c], th, tl, factors, nd,
                   n_small, out[c, j], block)
    result = np.zeros((channels, factors.shape[0]))
    for c in range(channels):
        for j in range(n_chunks):
            result[c] += out[c, j]
    return result
