"""ADEV and HDEV of frequency data at octave factors by the Haar pyramid, with the
moments of the lag-1 noise identification of every level (numba).

The non-overlapping estimators use the cluster sums ``v_k = S_m[k]`` of m
consecutive (detrended, scaled) frequency values: ADEV's term at level m is
``v_{k+1} - v_k`` and HDEV's ``v_{k+2} - 2 v_{k+1} + v_k`` (the phase's second
and third differences at stride m). At the octave factors m = 1, 2, 4, ...
the cluster sums of level 2m are the sums of pairs at level m, so every level
comes from one read of the data and N / 2 + N / 4 + ... more work. Each
cluster sum is a double-double ``hi + lo``: the level-1 values are the exact
pairs of :func:`avar._kernels.deviation_phase._increment` and every pair sum
keeps its rounding error (TwoSum), so a term is accurate relative to itself,
not to the offset removed.

The same pass sums, per level, what the lag-1 autocorrelation of the
decimated phase ``z_k = v_0 + ... + v_{k-1}`` (k = 0 .. C) and of its
differences needs (:data:`MOMENTS`, read by
:func:`avar._kernels.noise_id.lag1_alpha_from_moments`): the phase is never
stored, and the noise identification costs no pass of its own. Levels with
at most :data:`TAIL` clusters also hand back their cluster sums (Barnes's B1
ratio needs the few decimated points). One thread, a fixed order: the result
does not depend on the thread count. The tests compare it with the general
kernels of :mod:`avar._kernels.deviations`, with exact arithmetic, and the
noise identification with the plain two-pass kernel on the stored phase.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from avar._kernels.deviation_phase import _increment
from avar._kernels.streaming import _two_sum

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


@njit(cache=True, nogil=True, inline="always")
def _value(y, start, centre, slope, scale, src_hi, src_lo, first_level, j):
    """Cluster j of a stretch: level 1's from ``y[start + j]``, the others' from ``src_hi/lo``."""
    if first_level:
        return _increment(y, _NO_LO, start + j, 0, centre, slope, scale)
    return src_hi[j], src_lo[j]


@njit(cache=True, nogil=True, inline="always")
def _level_body(y, start, centre, slope, scale, src_hi, src_lo, first_level, order, count, k0, z0, half, dst_hi,
                dst_lo, acc, ends):
    """Add one stretch of a level to the moments ``acc`` (see :data:`MOMENTS`; the
    stretch's clusters have the level indices ``k0 .. k0 + count - 1`` and the phase
    before it is ``z0``) and write the pair sums of its clusters into
    ``dst_hi/lo[: count // 2]`` (may alias ``src``: index j // 2 <= j). The sum of the
    estimator's own ``order``-th differences is exact (double-double terms); the other
    orders, for the noise identification only, are differences of those. ``ends``: the
    first and last three clusters (h, l), for the seams."""
    z = z0
    s0 = s1 = s2 = q0 = v_squares = e1 = e2 = e3 = 0.0
    ph = pl = pph = ppl = 0.0  # the previous two clusters
    pd1 = pd2 = 0.0
    d1_first = d1_last = d2_first = d2_last = 0.0
    t = k0 + 1.0 - half  # the centred index of the phase point after cluster j
    for j in range(count):
        h, l = _value(y, start, centre, slope, scale, src_hi, src_lo, first_level, j)
        v = h + l
        z += v
        s0 += z
        s1 += t * z
        s2 += (t * t) * z
        q0 += z * z
        v_squares += v * v
        t += 1.0
        if j < 3:  # before the pairs overwrite them
            ends[0, j] = h
            ends[1, j] = l
        if j >= 1:
            d1 = (h - ph) + (l - pl)
            e1 += d1 * d1
            if j >= 2:
                if order == 1:
                    d2 = d1 - pd1
                else:
                    d2 = ((h - ph) - (ph - pph)) + ((l - pl) - (pl - ppl))
                    if j >= 3:
                        d3 = d2 - pd2
                        e3 += d3 * d3
                e2 += d2 * d2
                if j == 2:
                    d2_first = d2
                pd2 = d2
            else:
                d1_first = d1
            pd1 = d1
        if j % 2 == 1:
            s, e = _two_sum(ph, h)
            dst_hi[j // 2] = s
            dst_lo[j // 2] = (pl + l) + e
        pph, ppl, ph, pl = ph, pl, h, l
    d1_last = pd1
    d2_last = pd2
    for j in range(max(0, count - 3), count):  # the last three (re-read; intact when count >= 6)
        ends[0, 6 + j - count], ends[1, 6 + j - count] = _value(y, start, centre, slope, scale, src_hi, src_lo,
                                                                first_level, j)
    acc[0] += count
    acc[1] += s0
    acc[2] += s1
    acc[3] += s2
    acc[4] += q0
    acc[5] += v_squares
    acc[6] += e1
    acc[7] += e2
    acc[8] += e3
    acc[9] = z
    acc[11] = ph + pl
    acc[13] = d1_last
    acc[15] = d2_last
    if k0 == 0:
        acc[10] = ends[0, 0] + ends[1, 0]
        acc[12] = d1_first
        acc[14] = d2_first


@njit(cache=True, nogil=True)
def _first_level(y, start, centre, slope, scale, order, count, k0, z0, half, dst_hi, dst_lo, acc, ends):
    """:func:`_level_body` of level 1 (the values from ``y``)."""
    _level_body(y, start, centre, slope, scale, dst_hi, dst_lo, True, order, count, k0, z0, half, dst_hi, dst_lo, acc,
                ends)


@njit(cache=True, nogil=True)
def _upper_level(src_hi, src_lo, order, count, k0, z0, half, dst_hi, dst_lo, acc, ends):
    """:func:`_level_body` of a level from the cluster sums ``src_hi/lo``."""
    _level_body(src_hi, 0, 0.0, 0.0, 1.0, src_hi, src_lo, False, order, count, k0, z0, half, dst_hi, dst_lo, acc,
                ends)


@njit(cache=True, nogil=True)
def _seam(left, right, order, acc):
    """Add to ``acc`` the squared differences that straddle the seam between two stretches
    (``left``/``right``: their ``ends``; each stretch >= 3 clusters), as :func:`_level_body` forms them."""
    h = np.empty(6)
    l = np.empty(6)
    for i in range(3):
        h[i], l[i] = left[0, 3 + i], left[1, 3 + i]
        h[3 + i], l[3 + i] = right[0, i], right[1, i]
    d1 = np.zeros(6)
    d2 = np.zeros(6)
    for j in range(1, 6):
        d1[j] = (h[j] - h[j - 1]) + (l[j] - l[j - 1])
        if j >= 2:
            if order == 1:
                d2[j] = d1[j] - d1[j - 1]
            else:
                d2[j] = ((h[j] - h[j - 1]) - (h[j - 1] - h[j - 2])) + ((l[j] - l[j - 1]) - (l[j - 1] - l[j - 2]))
    acc[6] += d1[3] * d1[3]
    acc[7] += d2[3] * d2[3] + d2[4] * d2[4]
    if order == 2:
        for j in range(3, 6):
            d3 = d2[j] - d2[j - 1]
            acc[8] += d3 * d3


@njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _phase_at(y, centre, slope, scale, stop):
    """The (plain) phase after the first ``stop`` level-1 values: where the right stretch starts."""
    total = 0.0
    for i in range(stop):
        total += (y[i] - centre) - slope * i
    return total * scale


#: Series of at least this many samples are cut in two stretches, one per thread, for the
#: levels that keep at least SPLIT_MIN clusters on each side.
SPLIT_MIN = 1 << 12


@njit(cache=True, nogil=True, parallel=True)
def octave_moments(y, centre, slope, scale, order, n_levels, stats, tails):
    """Moments (``stats``, shape (L, len(MOMENTS))) and small levels' clusters (``tails``,
    shape (L, TAIL)) at m = 1, 2, ..., 2**(L - 1); ``order`` 1 for ADEV, 2 for HDEV, whose
    sum of squares at each level is ``stats[:, SUM_COLUMN[order]]``.

    Level 1 holds ``(y_i - centre - slope i) scale`` (``slope i`` exact, ``scale`` a power of two).
    The lower levels of a long series run as two stretches on two threads, cut at a
    point that depends on N alone (the bits do not depend on the thread count).
    """
    n = y.shape[0]
    split = 0  # levels computed as two stretches
    while split < n_levels and (n >> (split + 1)) >= 2 * SPLIT_MIN:
        split += 1
    cut = ((n // 2) >> split) << split if split > 0 else n  # level-1 index where the right stretch starts
    left_hi = np.empty(max(cut // 2, 1))
    left_lo = np.empty(max(cut // 2, 1))
    right_hi = np.empty(max((n - cut) // 2, 1))
    right_lo = np.empty(max((n - cut) // 2, 1))
    right_acc = np.zeros((max(split, 1), stats.shape[1]))
    ends = np.zeros((2, max(split, 1), 2, 6))
    z_cut = _phase_at(y, centre, slope, scale, cut) if split > 0 else 0.0
    for side in prange(2 if split > 0 else 0):
        for level in range(split):
            count = n >> level
            half = count / 2.0
            k_cut = cut >> level
            if side == 0:
                if level == 0:
                    _first_level(y, 0, centre, slope, scale, order, k_cut, 0, 0.0, half, left_hi, left_lo, stats[0],
                                 ends[0, 0])
                else:
                    _upper_level(left_hi, left_lo, order, k_cut, 0, 0.0, half, left_hi, left_lo, stats[level],
                                 ends[0, level])
            else:
                if level == 0:
                    _first_level(y, cut, centre, slope, scale, order, count - k_cut, k_cut, z_cut, half, right_hi,
                                 right_lo, right_acc[0], ends[1, 0])
                else:
                    _upper_level(right_hi, right_lo, order, count - k_cut, k_cut, z_cut, half, right_hi, right_lo,
                                 right_acc[level], ends[1, level])
    count = n
    top_hi = left_hi
    top_lo = left_lo
    if split > 0:
        for level in range(split):  # the two stretches' moments, and the differences across the cut
            row = stats[level]
            for c in range(9):
                row[c] += right_acc[level, c]
            for c in (9, 11, 13, 15):
                row[c] = right_acc[level, c]
            _seam(ends[0, level], ends[1, level], order, row)
        count = n >> split
        k_cut = cut >> split
        top_hi = np.concatenate((left_hi[:k_cut], right_hi[: count - k_cut]))  # side by side
        top_lo = np.concatenate((left_lo[:k_cut], right_lo[: count - k_cut]))
    one_end = np.zeros((2, 6))
    for level in range(split, n_levels):
        if count <= tails.shape[1]:
            for j in range(count):
                h, l = _value(y, 0, centre, slope, scale, top_hi, top_lo, level == 0, j)
                tails[level, j] = h + l
        if level == 0:
            _first_level(y, 0, centre, slope, scale, order, count, 0, 0.0, count / 2.0, top_hi, top_lo, stats[0],
                         one_end)
        else:
            _upper_level(top_hi, top_lo, order, count, 0, 0.0, count / 2.0, top_hi, top_lo, stats[level], one_end)
        count //= 2
