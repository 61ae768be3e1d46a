"""ADEV and HDEV of frequency data at octave factors by the Haar pyramid, with the
moments of the lag-1 noise identification of every level (numba).

The non-overlapping estimators use the cluster sums ``v_k = S_m[k]`` of m
consecutive (detrended, scaled) frequency values: ADEV's term at level m is
``v_{k+1} - v_k`` and HDEV's ``v_{k+2} - 2 v_{k+1} + v_k`` (the phase's second
and third differences at stride m). At the octave factors m = 1, 2, 4, ...
the cluster sums of level 2m are the sums of pairs at level m, so every level
comes from one read of the data and N / 2 + N / 4 + ... more work. Each
cluster sum is a double-double ``hi + lo``: the level-1 values are the exact
pairs of :func:`avar._kernels.classic.phase.phase_increment` and every pair sum
keeps its rounding error (TwoSum), so a term is accurate relative to itself,
not to the offset removed.

The same pass sums, per level, what the lag-1 autocorrelation of the
decimated phase ``z_k = v_0 + ... + v_{k-1}`` (k = 0 .. C) and of its
differences needs (:data:`MOMENTS`, read by
:func:`avar._kernels.uncertainty.noise_id.lag1_alpha_from_moments`): the phase is never
stored, and the noise identification costs no pass of its own. Levels with
at most :data:`TAIL` clusters also hand back their cluster sums (Barnes's B1
ratio needs the few decimated points).

The lower levels go block by block (2**:data:`BLOCK_EXP` samples): a block's pyramid
lives in two buffers of a block and each level carries its running state (:data:`STATE`)
from block to block: some kilobytes of workspace, never O(N) fresh memory (whose page
faults cost more than the arithmetic). A level's chunk goes array by array
(:func:`_chunk_fast`: exact differences and pair sums elementwise, the phase as four
running sums side by side, the moments as vectorized plain sums) in pieces that stay in
the L1 cache; a stretch's first clusters and short chunks go one cluster at a time
(:func:`_chunk_body`, its plain twin, which the tests compare). A long series runs as two
stretches on two threads, cut at a block boundary fixed by N: the bits do not depend on
the thread count. The tests compare the sums with the general kernels of
:mod:`avar._kernels.classic.levels` and with exact arithmetic, the moments with a NumPy
transcription, and the noise identification with the plain two-pass kernel.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.classic.phase import phase_increment
from avar._kernels.dd import two_sum
from avar._kernels.runtime.tasks import run_tasks

_NO_LO = np.zeros(1, dtype=np.float32)

#: Columns of the per-level moments (C clusters v_0 .. v_{C-1}; phase z_0 = 0, z_{k+1} = z_k + v_k;
#: t_k = k - C / 2 the centred phase index; the differences from the double-double cluster sums;
#: "d3_squares" only for HDEV, whose noise identification goes to third differences).
MOMENTS = ("count", "z_sum", "z_t", "z_t2", "z_squares", "v_squares", "d1_squares", "d2_squares", "d3_squares",
           "z_last", "v_first", "v_last", "d1_first", "d1_last", "d2_first", "d2_last")
#: Levels with at most this many clusters also return them (for the B1 ratio).
TAIL = 32
#: The columns of ADEV's and HDEV's sums of squares (order 1 and 2).
SUM_COLUMN = {1: 6, 2: 7}


#: Per-level running state of one stretch (see :func:`_chunk`).
STATE = 26
_Z, _S0, _S1, _S2, _Q0, _VSQ, _E1, _E2, _E3 = 0, 1, 2, 3, 4, 5, 6, 7, 8  # running sums
_PH, _PL, _PPH, _PPL, _P3H, _P3L = 9, 10, 11, 12, 13, 14  # the last three clusters (h, l)
_PD1, _PD2, _D1F, _D2F, _T = 15, 16, 17, 18, 19  # last and first differences; centred index
_F0 = 20  # the first three clusters: h, l at 20 .. 25

#: Level-1 samples per block: the pyramid of a block lives in a small buffer (no O(N) workspace).
BLOCK_EXP = 12
#: A series of at least this many blocks runs as two stretches, one per thread.
SPLIT_BLOCKS = 8


@njit(cache=True, nogil=True)
def _chunk_body(src_hi, src_lo, order, count, j0, state, dst_hi, dst_lo, tail, k0):
    """Carry one level of a stretch over its next ``count`` clusters ``src_hi/lo[:count]``
    (stretch indices ``j0 ..``), one cluster at a time: the plain twin of :func:`_chunk_fast`,
    and the path of a stretch's first clusters and of the levels that keep a ``tail``.

    ``state`` (:data:`STATE` values) holds the running moments, the last three
    and the first three clusters. The sum of the estimator's own ``order``-th
    differences is exact (double-double terms); the other orders, for the noise
    identification only, are differences of those. The pair sums go to
    ``dst_hi/lo[: count // 2]`` (``j0`` even; may alias ``src``: j // 2 <= j);
    with a non-empty ``tail``, the clusters go to ``tail[k0 + j0 + j]``.
    """
    z, s0, s1, s2, q0 = state[_Z], state[_S0], state[_S1], state[_S2], state[_Q0]
    v_squares, e1, e2, e3 = state[_VSQ], state[_E1], state[_E2], state[_E3]
    ph, pl, pph, ppl, p3h, p3l = state[_PH], state[_PL], state[_PPH], state[_PPL], state[_P3H], state[_P3L]
    pd1, pd2, d1_first, d2_first, t = state[_PD1], state[_PD2], state[_D1F], state[_D2F], state[_T]
    keep = tail.shape[0] > 0
    for j in range(count):
        h, l = src_hi[j], src_lo[j]
        jj = j0 + j
        v = h + l
        z += v
        s0 += z
        s1 += t * z
        s2 += (t * t) * z
        q0 += z * z
        v_squares += v * v
        t += 1.0
        if keep:
            tail[k0 + jj] = v
        if jj < 3:
            state[_F0 + 2 * jj] = h
            state[_F0 + 2 * jj + 1] = l
        if jj >= 1:
            d1 = (h - ph) + (l - pl)
            e1 += d1 * d1
            if jj >= 2:
                if order == 1:
                    d2 = d1 - pd1
                else:
                    d2 = ((h - ph) - (ph - pph)) + ((l - pl) - (pl - ppl))
                    if jj >= 3:
                        d3 = d2 - pd2
                        e3 += d3 * d3
                e2 += d2 * d2
                if jj == 2:
                    d2_first = d2
                pd2 = d2
            else:
                d1_first = d1
            pd1 = d1
        if j % 2 == 1:
            s, e = two_sum(ph, h)
            dst_hi[j // 2] = s
            dst_lo[j // 2] = (pl + l) + e
        p3h, p3l, pph, ppl, ph, pl = pph, ppl, ph, pl, h, l
    state[_Z], state[_S0], state[_S1], state[_S2], state[_Q0] = z, s0, s1, s2, q0
    state[_VSQ], state[_E1], state[_E2], state[_E3] = v_squares, e1, e2, e3
    state[_PH], state[_PL], state[_PPH], state[_PPL], state[_P3H], state[_P3L] = ph, pl, pph, ppl, p3h, p3l
    state[_PD1], state[_PD2], state[_D1F], state[_D2F], state[_T] = pd1, pd2, d1_first, d2_first, t


@njit(cache=True, nogil=True)
def _increments(y, start, count, centre, slope, scale, hh, ll):
    """Level 1's clusters ``(y[start + j] - centre - slope (start + j)) scale`` into ``hh/ll[3 : 3 + count]``,
    as :func:`avar._kernels.classic.phase.phase_increment` forms them; without a drift, by its
    arithmetic written out branch free, so that the loop vectorizes (the same bits: the tests compare)."""
    if slope != 0.0:
        for j in range(count):
            hh[3 + j], ll[3 + j] = phase_increment(y, _NO_LO, start + j, 0, centre, slope, scale)
        return
    values = y[start : start + count]
    for j in range(count):
        h, e = two_sum(values[j], -centre)
        hh[3 + j] = h * scale
        ll[3 + j] = (0.0 + e) * scale


@njit(cache=True, nogil=True)
def _terms(hh, ll, count, order, v, d1, d2, d3, pair_hi, pair_lo):
    """The values, differences and pair sums of a chunk (clusters at ``hh/ll[3 :]``, the
    three before them at ``hh/ll[:3]``), elementwise (vectorized; no reassociation, so the
    double-double differences stay exact): the values ``v``, the differences ``d1`` (from
    the previous cluster on: count + 1), ``d2``, ``d3`` (order 2); the pair sums go to
    ``pair_hi/lo[3 :]``."""
    d1[0] = (hh[2] - hh[1]) + (ll[2] - ll[1])
    if order == 1:
        for j in range(count):
            h, l, h1, l1 = hh[3 + j], ll[3 + j], hh[2 + j], ll[2 + j]
            v[j] = h + l
            d1[j + 1] = (h - h1) + (l - l1)
            d2[j] = d1[j + 1] - ((h1 - hh[1 + j]) + (l1 - ll[1 + j]))
    else:
        for j in range(count):
            h, l, h1, l1 = hh[3 + j], ll[3 + j], hh[2 + j], ll[2 + j]
            h2, l2, h3, l3 = hh[1 + j], ll[1 + j], hh[j], ll[j]
            v[j] = h + l
            d1[j + 1] = (h - h1) + (l - l1)
            d2[j] = ((h - h1) - (h1 - h2)) + ((l - l1) - (l1 - l2))
            d3[j] = d2[j] - (((h1 - h2) - (h2 - h3)) + ((l1 - l2) - (l2 - l3)))
    for i in range(count // 2):
        s, e = two_sum(hh[3 + 2 * i], hh[4 + 2 * i])
        pair_hi[3 + i] = s
        pair_lo[3 + i] = (ll[3 + 2 * i] + ll[4 + 2 * i]) + e


@njit(cache=True, nogil=True)
def _running(v, count, z0, z):
    """The phase after each value, ``z[j] = z0 + v[0] + ... + v[j]``: four running sums side
    by side (one per quarter of the piece, each from 0: their additions overlap, where one
    chain of ``count`` would wait on each), then each quarter shifted by ``z0`` and the
    quarters before it. Equal to :func:`_chunk_body`'s single chain to rounding (the tests compare)."""
    part = count // 4
    a = b = c = d = 0.0
    for j in range(part):
        a += v[j]
        b += v[part + j]
        c += v[2 * part + j]
        d += v[3 * part + j]
        z[j], z[part + j], z[2 * part + j], z[3 * part + j] = a, b, c, d
    for j in range(4 * part, count):
        d += v[j]
        z[j] = d
    shift = z0
    for lane in range(4):  # vectorized: an addition per value
        stop = count if lane == 3 else (lane + 1) * part
        end = z[stop - 1] if stop > lane * part else 0.0
        for j in range(lane * part, stop):
            z[j] += shift
        shift += end


@njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _sums(z, v, d1, d2, d3, count, t0, order):
    """The chunk's moments (plain sums, vectorized): z, t z, t^2 z, z^2, v^2, d1^2, d2^2, d3^2."""
    s0 = s1 = s2 = q0 = vs = e1 = e2 = e3 = 0.0
    for j in range(count):
        zj = z[j]
        tj = t0 + j
        s0 += zj
        s1 += tj * zj
        s2 += (tj * tj) * zj
        q0 += zj * zj
        vs += v[j] * v[j]
        e1 += d1[j + 1] * d1[j + 1]
        e2 += d2[j] * d2[j]
    if order == 2:
        for j in range(count):
            e3 += d3[j] * d3[j]
    return s0, s1, s2, q0, vs, e1, e2, e3


#: Chunks of at least this many clusters (past a stretch's first three) take :func:`_chunk_fast`.
FAST_MIN = 128
#: Clusters per piece of :func:`_chunk_fast` (even): its work arrays stay in the L1 cache.
PIECE = 512


@njit(cache=True, nogil=True)
def _chunk_fast(hh, ll, order, count, state, dst_hh, dst_ll, v, d1, d2, d3, z):
    """:func:`_chunk_body` of a chunk past the stretch's first three clusters, without a tail,
    array by array in pieces of :data:`PIECE` (the clusters at ``hh/ll[3 :]``; the pair sums
    to ``dst_hh/dst_ll[3 :]``; ``v, d1, d2, d3, z``: work arrays of ``PIECE + 1``)."""
    hh[0], hh[1], hh[2] = state[_P3H], state[_PPH], state[_PH]
    ll[0], ll[1], ll[2] = state[_P3L], state[_PPL], state[_PL]
    running = state[_Z]
    t = state[_T]
    s0 = s1 = s2 = q0 = vs = e1 = e2 = e3 = 0.0
    size = 0
    for start in range(0, count, PIECE):
        size = min(PIECE, count - start)
        half = start // 2
        _terms(hh[start:], ll[start:], size, order, v, d1, d2, d3, dst_hh[half:], dst_ll[half:])
        _running(v, size, running, z)
        running = z[size - 1]
        a0, a1, a2, a3, a4, a5, a6, a7 = _sums(z, v, d1, d2, d3, size, t + start, order)
        s0 += a0
        s1 += a1
        s2 += a2
        q0 += a3
        vs += a4
        e1 += a5
        e2 += a6
        e3 += a7
    state[_S0] += s0
    state[_S1] += s1
    state[_S2] += s2
    state[_Q0] += q0
    state[_VSQ] += vs
    state[_E1] += e1
    state[_E2] += e2
    state[_E3] += e3
    state[_Z] = running
    state[_T] = t + count
    state[_P3H], state[_PPH], state[_PH] = hh[count], hh[count + 1], hh[count + 2]
    state[_P3L], state[_PPL], state[_PL] = ll[count], ll[count + 1], ll[count + 2]
    state[_PD1] = d1[size]
    state[_PD2] = d2[size - 1]


@njit(cache=True, nogil=True)
def _stretch(y, centre, slope, scale, order, first_block, stop_block, levels, states, top_hi, top_lo, tails,
             block_exp):
    """The lower ``levels`` levels (at most ``block_exp``) of the blocks ``first_block ..
    stop_block - 1`` (the last may be partial), block by block: each block's pyramid in two
    buffers of a block (each level's clusters after the three before them), the per-level
    state carried from block to block; every full block's level-``block_exp`` cluster sum
    goes to ``top_hi/lo[block]``."""
    n = y.shape[0]
    block = 1 << block_exp
    a_hi = np.empty(block + 3)
    a_lo = np.empty(block + 3)
    b_hi = np.empty(block + 3)
    b_lo = np.empty(block + 3)
    v = np.empty(PIECE + 1)
    d1 = np.empty(PIECE + 1)
    d2 = np.empty(PIECE + 1)
    d3 = np.empty(PIECE + 1)
    z = np.empty(PIECE + 1)
    no_tail = np.empty(0)
    for b in range(first_block, stop_block):
        count = min(block, n - b * block)
        j0 = (b - first_block) * block
        _increments(y, b * block, count, centre, slope, scale, a_hi, a_lo)
        src_hi, src_lo, dst_hi, dst_lo = a_hi, a_lo, b_hi, b_lo
        for level in range(levels):
            tail = tails[level] if (n >> level) <= tails.shape[1] else no_tail
            k0 = first_block << (block_exp - level)
            if j0 >= 3 and count >= FAST_MIN and tail.shape[0] == 0:
                _chunk_fast(src_hi, src_lo, order, count, states[level], dst_hi, dst_lo, v, d1, d2, d3, z)
            else:
                _chunk_body(src_hi[3:], src_lo[3:], order, count, j0, states[level], dst_hi[3:], dst_lo[3:], tail,
                            k0)
            src_hi, src_lo, dst_hi, dst_lo = dst_hi, dst_lo, src_hi, src_lo
            count //= 2
            j0 //= 2
        if levels == block_exp and count == 1:
            top_hi[b] = src_hi[3]
            top_lo[b] = src_lo[3]


@njit(cache=True, nogil=True)
def _seam(left, right, order, row):
    """Add to the moments ``row`` the squared differences that straddle the seam between two
    stretches (``left``/``right``: their states, each stretch >= 3 clusters), as
    :func:`_chunk_body` forms them."""
    h = np.array([left[_P3H], left[_PPH], left[_PH], right[_F0], right[_F0 + 2], right[_F0 + 4]])
    l = np.array([left[_P3L], left[_PPL], left[_PL], right[_F0 + 1], right[_F0 + 3], right[_F0 + 5]])
    d1 = np.zeros(6)
    d2 = np.zeros(6)
    for j in range(1, 6):
        d1[j] = (h[j] - h[j - 1]) + (l[j] - l[j - 1])
        if j >= 2:
            if order == 1:
                d2[j] = d1[j] - d1[j - 1]
            else:
                d2[j] = ((h[j] - h[j - 1]) - (h[j - 1] - h[j - 2])) + ((l[j] - l[j - 1]) - (l[j - 1] - l[j - 2]))
    row[6] += d1[3] * d1[3]
    row[7] += d2[3] * d2[3] + d2[4] * d2[4]
    if order == 2:
        for j in range(3, 6):
            d3 = d2[j] - d2[j - 1]
            row[8] += d3 * d3


@njit(cache=True, nogil=True)
def _start(state, count, k_first, z0):
    """A fresh state for a stretch starting at cluster ``k_first`` of a level of ``count``, phase ``z0``."""
    state[:] = 0.0
    state[_Z] = z0
    state[_T] = k_first + 1.0 - count / 2.0


@njit(cache=True, nogil=True)
def _moments_row(state, count, row):
    """The :data:`MOMENTS` of a level from the state of its only (or left) stretch."""
    row[0] = count
    row[1], row[2], row[3], row[4], row[5] = state[_S0], state[_S1], state[_S2], state[_Q0], state[_VSQ]
    row[6], row[7], row[8] = state[_E1], state[_E2], state[_E3]
    row[9], row[10], row[11] = state[_Z], state[_F0] + state[_F0 + 1], state[_PH] + state[_PL]
    row[12], row[13], row[14], row[15] = state[_D1F], state[_PD1], state[_D2F], state[_PD2]


@njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _phase_at(y, centre, slope, scale, stop):
    """The (plain) phase after the first ``stop`` level-1 values: where the right stretch starts."""
    total = 0.0
    for i in range(stop):
        total += (y[i] - centre) - slope * i
    return total * scale


@njit(cache=True, nogil=True)
def _start_states(states, n, low, cut, block_exp, z_cut):
    """Fresh states of the lower levels for the left stretch and for the right one (from block ``cut``)."""
    for level in range(low):
        _start(states[0, level], n >> level, 0, 0.0)
        _start(states[1, level], n >> level, cut << (block_exp - level), z_cut)


@njit(cache=True, nogil=True)
def _finish_moments(n, low, n_levels, sides, order, full, states, top_hi, top_lo, stats, tails):
    """The lower levels' moments from the stretches' states; the upper levels on the blocks' sums."""
    for level in range(low):
        row = stats[level]
        _moments_row(states[0, level], n >> level, row)
        if sides == 2:  # the right stretch's sums, its ends, and the differences across the cut
            right = states[1, level]
            row[1] += right[_S0]
            row[2] += right[_S1]
            row[3] += right[_S2]
            row[4] += right[_Q0]
            row[5] += right[_VSQ]
            row[6] += right[_E1]
            row[7] += right[_E2]
            row[8] += right[_E3]
            row[9], row[11], row[13], row[15] = right[_Z], right[_PH] + right[_PL], right[_PD1], right[_PD2]
            _seam(states[0, level], right, order, row)
    state = np.zeros(STATE)
    count = full
    no_tail = np.empty(0)
    for level in range(low, n_levels):  # the upper levels: on the full blocks' sums, in place
        _start(state, count, 0, 0.0)
        tail = tails[level] if count <= tails.shape[1] else no_tail
        _chunk_body(top_hi, top_lo, order, count, 0, state, top_hi, top_lo, tail, 0)
        _moments_row(state, count, stats[level])
        count //= 2


def octave_moments(y, centre, slope, scale, order, n_levels, stats, tails):
    """Moments (``stats``, shape (L, len(MOMENTS))) and small levels' clusters (``tails``,
    shape (L, TAIL)) at m = 1, 2, ..., 2**(L - 1); ``order`` 1 for ADEV, 2 for HDEV, whose
    sum of squares at each level is ``stats[:, SUM_COLUMN[order]]``.

    Level 1 holds ``(y_i - centre - slope i) scale`` (``slope i`` exact, ``scale`` a power of two).
    The lower levels go block by block (:func:`_stretch`); a long series runs as two
    stretches on two threads, cut at a block boundary that depends on N alone (the bits
    do not depend on the thread count). The upper levels run on the blocks' sums.
    """
    n = y.shape[0]
    block_exp = BLOCK_EXP
    n_blocks = -(-n >> block_exp) if n > 0 else 0
    full = n >> block_exp
    low = min(n_levels, block_exp)
    sides = 2 if n_blocks >= SPLIT_BLOCKS else 1
    cut = n_blocks // 2 if sides == 2 else n_blocks  # the right stretch starts at this block
    states = np.zeros((2, max(low, 1), STATE))
    _start_states(states, n, low, cut, block_exp, 0.0)
    top_hi = np.empty(max(full, 1))
    top_lo = np.empty(max(full, 1))

    def stretch(side: int) -> None:
        if side == 1:  # the phase where the right stretch starts, found on its own thread
            states[1, :low, _Z] = _phase_at(y, centre, slope, scale, cut << block_exp)
        _stretch(y, centre, slope, scale, order, 0 if side == 0 else cut, cut if side == 0 else n_blocks, low,
                 states[side], top_hi, top_lo, tails, block_exp)

    run_tasks(sides, stretch)
    _finish_moments(n, low, n_levels, sides, order, full, states, top_hi, top_lo, stats, tails)


#: The compiled loops of :func:`octave_moments` (whether they are compiled yet: :func:`avar._kernels.runtime.paths.compiled`).
OCTAVE_KERNELS = (_stretch, _finish_moments)
