"""Maximal-overlap Allan variance of the large power-of-two cluster sizes (numba).

For a cluster size ``m`` the differences are ``D_t = S[t+2m] - 2 S[t+m] + S[t]``
(``S`` the centred cumulative sum). For ``m`` a multiple of the table's
granularity ``F`` (:data:`SWEEP_FINE` samples; the table holds the exact
double-double ``S`` at every multiple of ``F``), time is cut into pieces of
``F`` samples. A piece's *local prefix* ``L[i] = sum_{s<i} (x[p+s] sc - c)``
(plain float64, :func:`local_prefix`) is computed once, and every level that
reads the piece takes its differences elementwise from three of them:

    D_{t0+i} = (S[t0+2m] - 2 S[t0+m] + S[t0]) + (L2[i] - 2 L1[i] + L0[i])

with the first term exact (double-double, from the table). No level runs a
recurrence of its own, so every level is one vectorized pass, and the levels whose
cluster sizes double from one to the next share it: up to four levels a loop over the
piece, which reads the prefixes they have in common once
(:func:`avar._kernels.allan.far_squares.fused_squares`).

Certified, else exact: a local prefix errs by at most ``1.01 u F (r + B)``
(u = 2**-53; ``r`` the table's spread of the piece, how far its samples lie
from the centre; ``B`` the largest ``|L|``). That bounds the error of every
``D`` of a piece (:func:`difference_error_bound`), and so of its sum of
squares (:func:`avar._kernels.allan.blocks.certified`, 1e-11 relative). A piece
that fails (a ``D`` tiny against its samples' excursion: a component periodic
in ``m`` far above the noise, say) is marked, and redone after the pass with its
steps ``x[t+2m] - 2 x[t+m] + x[t]`` each rounded once driving the running ``D``
(:mod:`avar._kernels.allan.far_steps`, compiled only when a piece is marked): each
addition then errs by at most ``u |D|``, whatever the offset or the excursion of
``S``. 64-bit integers (not exact in one float64) always take that path.

Order of work: a level reads the pieces at ``t``, ``t + m`` and ``t + 2m``. All
large ``m`` are multiples of the smallest, ``P``, so those pieces are in the
same residue class modulo ``P``. A task takes one class (every ``P / F``-th
piece), keeps the local prefixes of the pieces its levels still read in a ring,
and, piece by piece, runs every level: each prefix is computed once and read
about twice per level while it is still in the cache. A class's pieces lie ``P`` samples
apart, beyond the reach of the CPU's stream prefetcher, so :func:`local_prefix` announces
the next piece while it reads the current one (:func:`avar._kernels.prefetch.prefetch`: on
1e8 float32 samples the two groups' CPU time went from 0.278 + 0.259 s to 0.192 + 0.189 s).
(Filling four prefixes at once, interleaved, was 15 % faster on the prefixes, 3 % on a
whole call, and took a quarter of far_task's compilation.) The sums of the tasks
are added in a fixed order, so the bits do not depend on the number of threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.allan.blocks import CERTIFY_TOL, certified
from avar._kernels.allan.far_squares import FUSED, fused_squares
from avar._kernels.allan.far_steps import exact_sums, table_base
from avar._kernels.allan.haar import largest_magnitude
from avar._kernels.dd import EPS
from avar._kernels.prefetch import prefetch
from avar._kernels.runtime.tasks import run_tasks

#: Samples per piece: the table's granularity for the large levels and the length of a local prefix.
SWEEP_FINE = 1 << 10

#: Largest ratio of the largest to the smallest factor of one :func:`far_sums` call: a task's
#: ring then holds at most ``2 FAR_SPAN + 2`` local prefixes (528 kB), however long the series,
#: and stays in a core's L2 cache. (At 2**9, one 8 MB ring read from L3, a whole octave "mo"
#: call on 1e8 samples took 7-25 % more CPU time than with the ten far levels as two groups
#: of this span, each computing its local prefixes once.)
FAR_SPAN = 1 << 5


#: Samples per group of :func:`local_prefix`: their partial sums run apart from the carry.
GROUP = 8


@njit(cache=True)
def local_prefix(rows, col, start, count, centre, sc, out, ahead):
    """``out[i] = sum_{s<i} (x[start+s] sc - centre)`` in plain float64 for ``i < count``
    (and ``i = count`` when ``out`` is longer: a last, short piece is read up to its end),
    prefetching ``x[ahead : ahead + count]`` (the next piece this task reads; ``ahead + count <= N``).

    Returns ``B``, the largest ``|out[i]|`` (NaN if one is not finite). Samples go in groups of
    :data:`GROUP`: the group's own partial sums ``p_k`` (``k < GROUP``, independent of the
    other groups), then ``out = carry + p_k`` and one addition to the carry per group, so the
    CPU overlaps the groups (a plain running sum waits for every addition). The rounding
    errors: :func:`prefix_error_bound` (``r >= |x sc - centre|`` over the piece).
    Not for 64-bit integers (not exact in one float64).
    """
    row = rows[col]
    x = row[start : start + count]
    o = out[:count]
    carry = 0.0
    for j in range(count // GROUP):  # GROUP = 8, written out: LLVM then keeps the group in registers
        xs = x[GROUP * j : GROUP * j + GROUP]
        og = o[GROUP * j : GROUP * j + GROUP]
        prefetch(row, ahead + GROUP * j)
        p1 = np.float64(xs[0]) * sc - centre
        p2 = p1 + (np.float64(xs[1]) * sc - centre)
        p3 = p2 + (np.float64(xs[2]) * sc - centre)
        p4 = p3 + (np.float64(xs[3]) * sc - centre)
        p5 = p4 + (np.float64(xs[4]) * sc - centre)
        p6 = p5 + (np.float64(xs[5]) * sc - centre)
        p7 = p6 + (np.float64(xs[6]) * sc - centre)
        p8 = p7 + (np.float64(xs[7]) * sc - centre)
        og[0] = carry
        og[1] = carry + p1
        og[2] = carry + p2
        og[3] = carry + p3
        og[4] = carry + p4
        og[5] = carry + p5
        og[6] = carry + p6
        og[7] = carry + p7
        carry += p8
    for i in range(GROUP * (count // GROUP), count):
        o[i] = carry
        carry += np.float64(x[i]) * sc - centre
    if count < out.shape[0]:
        out[count] = carry
    if not np.isfinite(carry):
        return np.inf
    return max(abs(carry), largest_magnitude(o))


@njit(cache=True, inline="always")
def prefix_error_bound(count, spread, big):
    """Bound on the error of every value of :func:`local_prefix`:
    ``1.01 u (count + GROUP) (GROUP r + B)``.

    Per group: the centring of its samples (``u r`` each), its partial sums (``GROUP - 1``
    roundings of at most ``u GROUP r``) and one addition to the carry (``u B``): at most
    ``u (GROUP r + B / GROUP)`` a sample; a stored value adds one rounding of at most ``u B``
    and a part of its own group.
    """
    return 1.01 * EPS * (count + GROUP) * (GROUP * spread + big)


@njit(cache=True, inline="always")
def difference_error_bound(errors, bigs, base_hi, base_lo, table_mag):
    """Bound on the error of every ``D`` of a far level (:func:`avar._kernels.allan.far_squares.fused_squares`).

    ``errors`` and ``bigs``: the three prefixes' :func:`prefix_error_bound` and ``B``,
    weighted ``(1, 2, 1)``; then at most five roundings, each of at most ``u`` times the
    sum of the terms' magnitudes (whatever their order), and the table's double-double
    error (``8 u**2`` of the weighted ``|S|``).
    """
    return errors + 5.05 * EPS * (abs(base_hi) + abs(base_lo) + bigs) + 8.0 * EPS * EPS * table_mag


@njit(cache=True, nogil=True)
def far_task(rows, col, first, stride, sc, centre, th, tl, spread, factors, nd, fine, tol, out_row, marked, wide):
    """Adds to ``out_row`` the sums of ``D**2`` of every level over the pieces
    ``first, first + stride, ...`` (pieces of ``fine`` samples, level ``k`` its
    differences ``0 .. nd[k] - 1``) whose certificate holds, and sets ``marked[q, k]``
    for the others (:mod:`avar._kernels.allan.far_steps` redoes them exactly).
    ``spread[col, q]`` bounds ``|x sc - centre|`` over piece ``q``; ``wide``: the samples are
    64-bit integers (not exact in one float64): every piece is marked."""
    n = rows.shape[1]
    n_levels = factors.shape[0]
    reach = 2 * (factors[n_levels - 1] // factors[0])  # farthest piece a level reads, in class steps
    ring = reach + 2  # the pieces a level reads, and the one filled ahead
    prefixes = np.empty((0 if wide else ring) * fine)  # slot s: [s fine, (s + 1) fine); 1-d, as every allocation
    for s in range(0 if wide else ring):  # a piece starting at N is never filled; its prefix is S[N] - S[N] = 0
        prefixes[s * fine] = 0.0
    errors = np.empty(ring)
    bigs = np.empty(ring)
    slots = np.empty(FUSED + 2, dtype=np.int64)  # a fused pass's prefixes (offsets in the ring)
    bases = np.empty(FUSED)  # its levels' table bases, rounded to float64
    deltas = np.empty(FUSED)  # ... and the bounds on their differences' errors
    totals = np.empty(FUSED)
    ready = 0  # class steps whose local prefix is in the ring
    j = 0
    while (first + stride * j) * fine < nd[0]:
        q = first + stride * j
        t0 = q * fine
        while not wide and ready <= j + reach and (first + stride * ready) * fine < n:
            p = first + stride * ready
            count = min(fine, n - p * fine)
            slot = ready % ring
            ahead = min((p + stride) * fine, n - count)  # the next piece of the class (its misses overlap this one)
            bigs[slot] = local_prefix(rows, col, p * fine, count, centre, sc, prefixes[slot * fine : (slot + 1) * fine],
                                      ahead)
            errors[slot] = prefix_error_bound(count, spread[col, p], bigs[slot])
            ready += 1
        k = 0
        while k < n_levels:
            cnt = min(fine, nd[k] - t0)
            if cnt <= 0:
                break  # larger levels have fewer differences
            if wide:
                marked[q, k] = True
                k += 1
                continue
            width = 1  # levels in this pass: full pieces, each level's factor twice the one before
            while (cnt == fine and width < FUSED and k + width < n_levels and nd[k + width] - t0 >= fine
                   and factors[k + width] == 2 * factors[k + width - 1]):
                width += 1
            h = factors[k] // fine // stride
            slots[0] = (j % ring) * fine
            for w in range(width + 1):
                slots[w + 1] = ((j + (h << w)) % ring) * fine
            s0 = j % ring
            for w in range(width):  # each level's base and the bound on its differences' errors
                o = factors[k + w] // fine
                ch, cl = table_base(th, tl, col, q, q + o, q + 2 * o)
                bases[w] = ch + cl
                s1, s2 = (j + (h << w)) % ring, (j + (h << (w + 1))) % ring
                table_mag = abs(th[col, q]) + 2.0 * abs(th[col, q + o]) + abs(th[col, q + 2 * o])
                deltas[w] = difference_error_bound(errors[s0] + 2.0 * errors[s1] + errors[s2],
                                                   bigs[s0] + 2.0 * bigs[s1] + bigs[s2], ch, cl, table_mag)
            fused_squares(prefixes, slots, bases, width, cnt, totals)
            for w in range(width):
                if certified(totals[w], deltas[w], cnt, tol):
                    out_row[k + w] += totals[w]
                else:
                    marked[q, k + w] = True
            k += width
        j += 1


def far_sums(rows, scale, centre, th, tl, spread, factors, nd, fine, tol=CERTIFY_TOL):
    """Sums of ``D**2`` per (column, level), shape (C, L), for ``factors`` strictly
    increasing multiples of the smallest, itself a multiple of ``fine``; ``nd`` the
    numbers of differences (all > 0). ``rows``: the input transposed (C, N);
    ``th, tl, centre, spread``: :func:`avar._kernels.allan.blocks.block_table` at granularity ``fine``.
    The pieces that fail their certificate are redone by :mod:`avar._kernels.allan.far_steps`
    (compiled only then: most series have none)."""
    channels = rows.shape[0]
    classes = int(factors[0]) // fine
    out = np.zeros((channels, classes, factors.shape[0]))
    marked = np.zeros((channels, -(-int(nd[0]) // fine), factors.shape[0]), dtype=np.bool_)
    wide = rows.dtype.kind in "iu" and rows.dtype.itemsize == 8

    def task(t):
        c, a = divmod(t, classes)
        far_task(rows, c, a, classes, scale[c], centre[c], th, tl, spread, factors, nd, fine, tol, out[c, a],
                 marked[c], wide)

    run_tasks(channels * classes, task)
    result = out[:, 0].copy()
    for a in range(1, classes):  # in a fixed order: the bits do not depend on the threads
        result += out[:, a]
    if marked.any():
        result += exact_sums(rows, marked, scale, th, tl, factors, nd, fine)
    return result
