"""Maximal-overlap Allan variance of power-of-two cluster sizes: the small levels' compensated sliding window (numba).

The exact path of :mod:`avar._kernels.allan.pyramid` (the (block, level) pairs its plain moving
sums cannot certify, and 64-bit integers), and its twin (``run_sweep(window=True)``): until
the pyramid, every small octave level took this path.

For a cluster size ``m`` the differences are ``D_t = S[t+2m] - 2 S[t+m] + S[t]``
(``S`` the centred cumulative sum). The levels ``m < SWEEP_NEAR`` share one
sliding window of ``S``: time is cut into blocks of :data:`SWEEP_BLOCK`
samples, a task sweeps a run of consecutive blocks, and for each block it
extends the window (block plus a halo of ``2 m``; ``S`` computed once per
sample, compensated) and sums every level's squares from it
(:func:`avar._kernels.allan.blocks.window_level_sums`). The larger levels are
:mod:`avar._kernels.allan.far`'s. The sums of every task are added in a fixed
order, so the bits do not depend on the number of threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.allan.blocks import window_level_sums
from avar._kernels.runtime.tasks import run_tasks

#: Samples per block: the window's advance.
SWEEP_BLOCK = 1 << 13

#: Levels below this cluster size are served by the sliding window (a power of
#: two, at least the block): the window is the block plus a halo of 2 m.
SWEEP_NEAR = 1 << 15

#: Blocks per parallel task (fixes the summation order).
SWEEP_CHUNK = 32


@njit(cache=True, nogil=True)
def sweep_task(data, col, kb0, kb1, centre, scale, factors, nd, out_row, block):
    """Sums of ``D**2`` of every level for the differences starting in blocks ``kb0 .. kb1 - 1``."""
    n = data.shape[0]
    n_levels = factors.shape[0]
    halo = 2 * factors[n_levels - 1]
    cap = 2 * (block + halo) + 1
    wh = np.empty(cap)
    wl = np.empty(cap)
    buffer = np.empty(block)
    bounds = np.empty(2)  # largest |S| hi and lo parts the window has held (np.zeros would compile more)
    bounds[0] = 0.0
    bounds[1] = 0.0
    w0 = kb0 * block
    filled = np.int64(0)  # not the literal 0: window_level_sums compiles once
    # The window holds S less S[kb0 B] (differences need no anchor): its values stay the
    # size of the task's own excursion, which lets certified_squares use plain sums.
    wh[0] = 0.0
    wl[0] = 0.0
    for kb in range(kb0, kb1):
        t0 = kb * block
        if t0 >= nd[0]:
            break
        w0, filled = window_level_sums(data, col, t0, min(n, t0 + block + halo), centre, scale, wh, wl, w0,
                                       filled, factors, nd, n_levels, block, out_row, buffer, bounds)
    return out_row


def sweep_sums(data, centre, scale, factors, nd, block, chunk):
    """Sums of ``D**2`` per (column, level), shape (C, L).

    ``factors`` strictly increasing (at least one); ``nd`` the numbers of
    differences, all > 0.
    """
    channels = data.shape[1]
    n_blocks = -(-int(nd[0]) // block)
    n_chunks = -(-n_blocks // chunk)
    out = np.zeros((channels, n_chunks, factors.shape[0]))

    def task(t):
        c, j = divmod(t, n_chunks)
        sweep_task(data, c, j * chunk, min(n_blocks, (j + 1) * chunk), centre[c], scale[c], factors, nd, out[c, j],
                   block)

    run_tasks(channels * n_chunks, task)
    result = out[:, 0].copy()
    for j in range(1, n_chunks):  # in a fixed order: the bits do not depend on the threads
        result += out[:, j]
    return result
