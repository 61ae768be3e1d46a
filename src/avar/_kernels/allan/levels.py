"""Per-task level sums of the streaming kernels ("mo" and "to"), and their drivers.

See :mod:`avar._kernels.allan.blocks` for the method. A task is one column and
a run of ``CHUNK_BLOCKS`` consecutive blocks; it owns a small workspace (the
near window, two region buffers, a squares buffer: about 0.6 MB) and adds
its sums into its own row of the output, so the summation order is fixed by
the block and chunk sizes alone.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.allan.blocks import fill_running, point, squares, window_level_sums
from avar._kernels.runtime.tasks import run_tasks


@njit(cache=True)
def _region(p, last, w0, w_end, rs, re_):
    """Index of the buffer holding S[p .. last]: -1 near window, 0/1 region buffers, -2 none."""
    if p >= w0 and last <= w_end:
        return -1
    for k in range(2):
        if p >= rs[k] and last <= re_[k]:
            return k
    return -2


@njit(cache=True, nogil=True)
def mo_task(data, col, kb0, kb1, centre, scale, th, tl, factors, nd, small_count, out_row, block, near):
    """Maximal-overlap sums of the differences starting in blocks ``kb0 .. kb1 - 1`` of one column."""
    n = data.shape[0]
    n_levels = factors.shape[0]
    near_len = 2 * near + 4 * block
    nh = np.empty(near_len + 1)
    nl = np.empty(near_len + 1)
    rh = np.empty((2, 2 * block + 1))
    rl = np.empty((2, 2 * block + 1))
    rs = np.full(2, -1, dtype=np.int64)
    re_ = np.full(2, -2, dtype=np.int64)
    buffer = np.empty(block)
    bounds = np.zeros(2)  # largest |S| hi and lo parts the window has held
    idx = np.empty(2, dtype=np.int64)
    w0 = kb0 * block
    filled = np.int64(0)  # not the literal 0: window_level_sums compiles once
    nh[0] = th[col, kb0]
    nl[0] = tl[col, kb0]
    for kb in range(kb0, kb1):
        t0 = kb * block
        if t0 >= nd[0]:
            break
        w0, filled = window_level_sums(data, col, t0, min(n, t0 + block + 2 * near), centre, scale, nh, nl, w0,
                                       filled, factors, nd, small_count, block, out_row, buffer, bounds)
        a = t0 - w0
        for k in range(small_count, n_levels):
            cnt = min(block, nd[k] - t0)
            if cnt <= 0:
                continue
            m = factors[k]
            used = -3
            starts = (t0 + m, t0 + 2 * m)
            for r in range(2):
                p = starts[r]
                where = _region(p, p + cnt - 1, w0, w0 + filled, rs, re_)
                if where == -2:
                    where = 0 if used != 0 else 1
                    q = p // block
                    fill_running(data, col, q * block, p + cnt - 1, centre, scale, th[col, q], tl[col, q],
                                 rh[where], rl[where], 0)
                    rs[where] = q * block
                    re_[where] = p + cnt - 1
                if where >= 0:
                    used = where
                idx[r] = where
            if idx[0] == -1:
                h1, l1, a1 = nh, nl, t0 + m - w0
            else:
                h1, l1, a1 = rh[idx[0]], rl[idx[0]], t0 + m - rs[idx[0]]
            if idx[1] == -1:
                h2, l2, a2 = nh, nl, t0 + 2 * m - w0
            else:
                h2, l2, a2 = rh[idx[1]], rl[idx[1]], t0 + 2 * m - rs[idx[1]]
            out_row[k] += squares(nh, nl, a, h1, l1, a1, h2, l2, a2, cnt, buffer)


@njit(cache=True, nogil=True)
def to_task(data, col, kb0, kb1, centre, scale, th, tl, factors, clusters, out_row, block):
    """Tau-overlap sums of the cluster boundaries in blocks ``kb0 .. kb1 - 1`` (positions (kb0 B, kb1 B])."""
    n = data.shape[0]
    n_levels = factors.shape[0]
    s0h = np.zeros(n_levels)
    s0l = np.zeros(n_levels)
    s1h = np.zeros(n_levels)
    s1l = np.zeros(n_levels)
    have = np.zeros(n_levels, dtype=np.int64)
    start = kb0 * block
    last_pos = 0
    for k in range(n_levels):
        m = factors[k]
        last_pos = max(last_pos, clusters[k] * m)
        p1 = (start // m) * m
        if p1 > clusters[k] * m:
            continue
        s1h[k], s1l[k] = point(data, col, p1, centre, scale, th, tl, block)
        have[k] = 1
        if p1 - m >= 0:
            s0h[k], s0l[k] = point(data, col, p1 - m, centre, scale, th, tl, block)
            have[k] = 2
    bh = np.empty(block + 1)
    bl = np.empty(block + 1)
    for kb in range(kb0, kb1):
        t0 = kb * block
        if t0 >= last_pos:
            break
        stop = min(n, t0 + block, last_pos)
        fill_running(data, col, t0, stop, centre, scale, th[col, kb], tl[col, kb], bh, bl, 0)
        for k in range(n_levels):
            m = factors[k]
            e = (t0 // m + 1) * m
            lim = min(stop, clusters[k] * m)
            total = 0.0
            while e <= lim:
                eh = bh[e - t0]
                el = bl[e - t0]
                if have[k] >= 2:
                    d = ((eh - s1h[k]) - (s1h[k] - s0h[k])) + ((el - s1l[k]) - (s1l[k] - s0l[k]))
                    total += d * d
                s0h[k] = s1h[k]
                s0l[k] = s1l[k]
                s1h[k] = eh
                s1l[k] = el
                have[k] = min(have[k] + 1, 2)
                e += m
            out_row[k] += total


def level_sums(data, centre, scale, th, tl, factors, counts, is_mo, small_count, block, near, chunk_blocks):
    """Sums of ``D**2`` per (column, level), shape (C, L); ``factors`` increasing, all counts > 0.

    ``counts``: "mo" the number of differences N - 2m + 1; "to" the number of
    clusters floor(N / m).
    """
    channels = data.shape[1]
    span = int(counts[0]) if is_mo else data.shape[0]
    n_blocks = -(-span // block)
    n_chunks = max(1, -(-n_blocks // chunk_blocks))
    out = np.zeros((channels, n_chunks, factors.shape[0]))

    def task(t):
        c, j = divmod(t, n_chunks)
        kb1 = min(n_blocks, (j + 1) * chunk_blocks)
        if is_mo:
            mo_task(data, c, j * chunk_blocks, kb1, centre[c], scale[c], th, tl, factors, counts, small_count,
                    out[c, j], block, near)
        else:
            to_task(data, c, j * chunk_blocks, kb1, centre[c], scale[c], th, tl, factors, counts, out[c, j], block)

    run_tasks(channels * n_chunks, task)
    result = out[:, 0].copy()
    for j in range(1, n_chunks):  # in a fixed order: the bits do not depend on the threads
        result += out[:, j]
    return result
