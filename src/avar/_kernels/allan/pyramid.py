"""Maximal-overlap Allan variance of the small power-of-two cluster sizes: moving sums by pairs (numba).

For a cluster size ``m`` the differences are ``D_t = A_m[t+m] - A_m[t]`` with
``A_m[t] = sum_{i<m} y[t+i]`` the moving sum of ``y = x sc - c`` (any ``c``:
it cancels). The moving sums of the octave sizes come from each other,

    A_1 = y,    A_{2m}[t] = A_m[t] + A_m[t+m],

and the loads that build them also give the differences: one vectorized pass
handles two levels, ``m`` and ``2 m``, and leaves ``A_{4m}`` (:func:`two_levels`). No
recurrence anywhere: a compensated prefix sum (the former path,
:mod:`avar._kernels.allan.sweep`) waits for every addition and cost about 4 ns a sample
before any level was summed. Time is cut into blocks of ``block`` samples; each block
rebuilds its moving sums over the block plus a halo of ``2 M`` (``M`` the largest
size), in two buffers that stay in a core's L2 cache. Each block takes its own ``c``,
its first sample, so the plain values stay the size of the block's own excursion,
whatever the offset or the walk of the series.

Certified, else exact: every ``y`` is rounded once (at most ``u r``, u = 2**-53, ``r``
the largest ``|y|`` of the block and halo) and every ``D`` is a sum of such values in
a few levels of additions, so it errs by at most ``(3 log2 m + 8) u m r``
(:func:`pair_error_bound`), which bounds its block's sum of squares
(:func:`avar._kernels.allan.blocks.certified`, 1e-11 relative). A (block, level) that
fails (a ``D`` tiny against the samples' excursion: white phase noise fed as frequency
at the larger sizes, or a strong drift at the smallest) is marked, and the marked ones
are redone after the pass by the compensated sliding window of
:mod:`avar._kernels.allan.sweep` (runs of consecutive blocks with the same levels
marked share one window). 64-bit integers (not exact in one float64) take that path
for every block. The sums of the tasks, then of the runs, are added in a fixed order:
the bits do not depend on the number of threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.allan.blocks import CERTIFY_TOL, certified
from avar._kernels.allan.haar import largest_magnitude
from avar._kernels.allan.sweep import sweep_task
from avar._kernels.dd import EPS
from avar._kernels.runtime.tasks import run_tasks

#: Samples per block (a power of two, at least twice the largest pyramid level).
PYRAMID_BLOCK = 1 << 15

#: Levels below this cluster size are the pyramid's (a power of two); the others are
#: :mod:`avar._kernels.allan.far`'s. Buffers of ``PYRAMID_BLOCK + PYRAMID_NEAR`` float64,
#: two per task: 576 kB, in a core's L2. (At 2**13, the pyramid's thirteenth level took a
#: pass of its own over a halo twice as long: octave "mo" of 1e8 float32 samples took 5 %
#: more time than with that level among the far ones, summed four levels a pass.)
PYRAMID_NEAR = 1 << 12

#: Blocks per parallel task (fixes the summation order).
PYRAMID_CHUNK = 8


@njit(cache=True)
def centred_block(rows, col, start, count, sc, out):
    """``out[i] = x[start+i] sc - x[start] sc`` for ``i < count`` (each rounded once); returns
    ``r``, the largest ``|out[i]|`` (inf if one is not finite). (Not inlined: inside
    :func:`pyramid_task`'s loop its loops did not vectorize, 2.3 against 0.6 ns a sample.)"""
    x = rows[col, start : start + count]
    o = out[:count]
    c = np.float64(x[0]) * sc
    for i in range(count):
        o[i] = np.float64(x[i]) * sc - c
    return largest_magnitude(o)


@njit(cache=True, fastmath={"reassoc", "contract"})
def _fused(a, m, count, b, store):
    """Both levels' sums over ``i < count``, and ``b[i]`` (``A_4m``) there when ``store``."""
    x0 = a[:count]
    x1 = a[m : m + count]
    x2 = a[2 * m : 2 * m + count]
    x3 = a[3 * m : 3 * m + count]
    s1 = 0.0
    s2 = 0.0
    if store:
        out = b[:count]
        for i in range(count):
            p = x0[i] + x1[i]
            q = x2[i] + x3[i]
            out[i] = p + q
            d1 = x1[i] - x0[i]
            d2 = q - p
            s1 += d1 * d1
            s2 += d2 * d2
    else:
        for i in range(count):
            d1 = x1[i] - x0[i]
            d2 = (x2[i] + x3[i]) - (x0[i] + x1[i])
            s1 += d1 * d1
            s2 += d2 * d2
    return s1, s2


@njit(cache=True, fastmath={"reassoc", "contract"})
def _first(a, m, start, stop):
    """Sum of ``(a[i+m] - a[i])**2`` over ``start <= i < stop``."""
    x0 = a[start:stop]
    x1 = a[m + start : m + stop]
    total = 0.0
    for i in range(stop - start):
        d = x1[i] - x0[i]
        total += d * d
    return total


@njit(cache=True, fastmath={"reassoc", "contract"})
def _second(a, m, start, stop):
    """Sum of ``((a[i+2m] + a[i+3m]) - (a[i] + a[i+m]))**2`` over ``start <= i < stop``."""
    x0 = a[start:stop]
    x1 = a[m + start : m + stop]
    x2 = a[2 * m + start : 2 * m + stop]
    x3 = a[3 * m + start : 3 * m + stop]
    total = 0.0
    for i in range(stop - start):
        d = (x2[i] + x3[i]) - (x0[i] + x1[i])
        total += d * d
    return total


@njit(cache=True, fastmath={"reassoc", "contract"})
def _store(a, m, start, stop, b):
    """``b[i] = (a[i] + a[i+m]) + (a[i+2m] + a[i+3m])`` for ``start <= i < stop``."""
    x0 = a[start:stop]
    x1 = a[m + start : m + stop]
    x2 = a[2 * m + start : 2 * m + stop]
    x3 = a[3 * m + start : 3 * m + stop]
    out = b[start:stop]
    for i in range(stop - start):
        out[i] = (x0[i] + x1[i]) + (x2[i] + x3[i])


@njit(cache=True)
def two_levels(a, m, count, count2, length, b):
    """Levels ``m`` and ``2 m`` in one pass: ``b[i] = (a[i] + a[i+m]) + (a[i+2m] + a[i+3m])``
    (``A_{4m}`` from ``A_m``) for ``i < length`` (none when ``length <= 0``), and the sums of
    ``(a[i+m] - a[i])**2`` over ``i < count`` and of ``((a[i+2m] + a[i+3m]) - (a[i] + a[i+m]))**2``
    over ``i < count2``. Every loop runs over slices and vectorizes (any association:
    :func:`pair_error_bound` holds for all)."""
    store = length > 0
    both = max(0, min(count, count2, length) if store else min(count, count2))
    s1, s2 = _fused(a, m, both, b, store)
    if count > both:
        s1 += _first(a, m, both, count)
    if count2 > both:
        s2 += _second(a, m, both, count2)
    if length > both:
        _store(a, m, both, length, b)
    return s1, s2


@njit(cache=True, inline="always")
def pair_error_bound(depth, m, big):
    """Bound on the error of every ``D`` of level ``m = 2**depth``: ``1.01 (3 depth + 8) u m r``.

    Each ``y`` errs by at most ``u r``; a pass adds four moving sums in any association
    (three roundings, each at most ``u`` times the sum of their magnitudes, ``4 m r`` at level
    ``m``), so ``A_m`` errs by at most ``(1.5 depth + 1) u m r``, and ``D`` (a difference of two of
    them, or of four for the second level of a pass: three roundings more) by the bound.
    """
    return 1.01 * (3.0 * depth + 8.0) * EPS * m * big


@njit(cache=True, nogil=True)
def pyramid_task(rows, col, kb0, kb1, sc, factors, nd, block, tol, out_row, marked, wide):
    """Adds to ``out_row`` the sums of ``D**2`` of every level over the differences starting in
    blocks ``kb0 .. kb1 - 1`` whose certificate holds; sets ``marked[kb, k]`` for the others
    (every one when ``wide``: 64-bit integers). ``factors``: increasing powers of two.

    Once the largest levels fail in a block, they are marked in the task's later blocks
    without being tried (the smaller levels then need a shorter halo): data that fail there
    (white phase noise fed as frequency) would otherwise pay both paths.
    """
    n = rows.shape[1]
    n_levels = factors.shape[0]
    cap = 0 if wide else block + 2 * factors[n_levels - 1]
    a = np.empty(cap)
    b = np.empty(cap)
    active = 0 if wide else n_levels  # levels computed; the ones above are marked without trying
    for kb in range(kb0, kb1):
        t0 = kb * block
        if t0 >= nd[0]:
            break
        for k in range(active, n_levels):
            if nd[k] > t0:
                marked[kb, k] = True
        if active == 0:
            continue
        top = factors[active - 1]
        length = min(n - t0, block + 2 * top - 1)  # samples the block's largest level reads
        big = centred_block(rows, col, t0, length, sc, a)
        m = 1
        depth = 0
        k = 0
        valid = length  # A_m is valid at t < length - m + 1
        while k < active:  # levels m and 2m in one pass, then A_4m
            first = factors[k] == m
            k2 = k + 1 if first else k
            second = k2 < active and factors[k2] == 2 * m
            count = max(0, min(block, nd[k] - t0)) if first else 0
            count2 = max(0, min(block, nd[k2] - t0)) if second else 0
            s1, s2 = two_levels(a, m, count, count2, valid - 3 * m if 4 * m <= top else 0, b)
            a, b = b, a
            if count > 0:
                if certified(s1, pair_error_bound(depth, m, big), count, tol):
                    out_row[k] += s1
                else:
                    marked[kb, k] = True
            if count2 > 0:
                if certified(s2, pair_error_bound(depth + 1, 2 * m, big), count2, tol):
                    out_row[k2] += s2
                else:
                    marked[kb, k2] = True
            k = k2 + 1 if second else k2
            valid -= 3 * m
            m *= 4
            depth += 2
        while active > 0 and marked[kb, active - 1]:  # the largest levels failed: marked from now on
            active -= 1


def pyramid_sums(data, centre, scale, factors, nd, block=PYRAMID_BLOCK, chunk=PYRAMID_CHUNK, tol=CERTIFY_TOL):
    """Sums of ``D**2`` per (column, level), shape (C, L), for ``factors`` increasing powers of two
    of at most ``block / 2``; ``nd`` the numbers of differences (all > 0). ``data``: (N, C);
    ``centre``: the columns' centres (for the exact path, :func:`avar._kernels.allan.sweep.sweep_task`)."""
    channels = data.shape[1]
    rows = data.T
    n_blocks = -(-int(nd[0]) // block)
    n_chunks = -(-n_blocks // chunk)
    out = np.zeros((channels, n_chunks, factors.shape[0]))
    marked = np.zeros((channels, n_blocks, factors.shape[0]), dtype=np.bool_)
    wide = data.dtype.kind in "iu" and data.dtype.itemsize == 8

    def task(t):
        c, j = divmod(t, n_chunks)
        pyramid_task(rows, c, j * chunk, min(n_blocks, (j + 1) * chunk), scale[c], factors, nd, block, tol, out[c, j],
                     marked[c], wide)

    run_tasks(channels * n_chunks, task)
    result = out[:, 0].copy()
    for j in range(1, n_chunks):  # in a fixed order: the bits do not depend on the threads
        result += out[:, j]
    if marked.any():
        result += marked_sums(data, centre, scale, factors, nd, block, chunk, marked)
    return result


def marked_runs(marked, chunk):
    """``(column, first block, stop block, levels)`` of every run of consecutive blocks with the
    same levels marked (none empty), cut at multiples of ``chunk`` blocks (runs shared among the
    threads), in order."""
    runs = []
    for c in range(marked.shape[0]):
        rows = marked[c]
        changes = np.flatnonzero(np.any(rows[1:] != rows[:-1], axis=1)) + 1
        cuts = np.arange(chunk, rows.shape[0], chunk)
        edges = np.unique(np.concatenate(([0], changes, cuts, [rows.shape[0]])))
        for first, stop in zip(edges[:-1], edges[1:]):
            levels = np.flatnonzero(rows[first])
            if levels.size:
                runs.append((c, int(first), int(stop), levels))
    return runs


def marked_sums(data, centre, scale, factors, nd, block, chunk, marked):
    """Sums of ``D**2`` per (column, level) of the (block, level) pairs ``marked`` (C, blocks, L),
    by the compensated sliding window, added in the order of the runs (:func:`marked_runs`)."""
    runs = marked_runs(marked, chunk)
    sums = np.zeros((len(runs), factors.shape[0]))

    def task(i):
        c, first, stop, levels = runs[i]
        row = np.zeros(levels.shape[0])
        sweep_task(data, c, first, stop, centre[c], scale[c], factors[levels], nd[levels], row, block)
        sums[i, levels] = row

    run_tasks(len(runs), task)
    out = np.zeros((marked.shape[0], factors.shape[0]))
    for i, run in enumerate(runs):
        out[run[0]] += sums[i]
    return out
