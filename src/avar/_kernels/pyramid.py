"""ADEV and HDEV of frequency data at octave factors by the Haar pyramid (numba).

The non-overlapping estimators use the cluster sums ``S_m[k]`` of m
consecutive (detrended, scaled) frequency values: ADEV's term at level m is
``S_m[k + 1] - S_m[k]`` and HDEV's ``S_m[k + 2] - 2 S_m[k + 1] + S_m[k]``
(the phase's second and third differences at stride m). At the octave factors
m = 1, 2, 4, ... the cluster sums of level 2m are the sums of pairs at level
m, so every level comes from one read of the data and N / 2 + N / 4 + ...
more work. Each cluster sum is a double-double ``hi + lo``: the level-1 values
are the exact pairs of :func:`avar._kernels.deviation_phase._increment` and
every pair sum keeps its rounding error (TwoSum), so a term is accurate
relative to itself, not to the offset removed. One thread, a fixed order:
the result does not depend on the thread count. The tests compare it with the
general kernels of :mod:`avar._kernels.deviations` and with exact arithmetic.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.deviation_phase import _increment
from avar._kernels.streaming import _two_sum

_NO_LO = np.zeros(1, dtype=np.float32)


@njit(cache=True, nogil=True)
def octave_sums(y, centre, slope, scale, order, n_levels, sums, phase):
    """Sums of squared ``order``-th differences (1: ADEV, 2: HDEV) of consecutive cluster
    sums at m = 1, 2, ..., 2**(n_levels - 1) into ``sums``, and the plain running sum of
    the level-1 values into ``phase`` (length N + 1, for noise identification).

    Level 1 holds ``(y_i - centre - slope i) scale`` (``slope i`` exact, ``scale`` a power of two).
    """
    n = y.shape[0]
    size = n // 2
    hi = np.empty(max(size, 1))
    lo = np.empty(max(size, 1))
    total = 0.0
    ph = pl = pph = ppl = 0.0  # the previous two values
    running = 0.0
    phase[0] = 0.0
    for i in range(n):
        h, l = _increment(y, _NO_LO, i, 0, centre, slope, scale)
        running += h + l
        phase[i + 1] = running
        if order == 1:
            if i >= 1:
                d = (h - ph) + (l - pl)
                total += d * d
        elif i >= 2:
            d = ((h - ph) - (ph - pph)) + ((l - pl) - (pl - ppl))
            total += d * d
        if i % 2 == 1 and i // 2 < size:
            s, e = _two_sum(ph, h)
            hi[i // 2] = s
            lo[i // 2] = (pl + l) + e
        pph, ppl, ph, pl = ph, pl, h, l
    sums[0] = total
    count = size
    for level in range(1, n_levels):
        total = 0.0
        for k in range(order, count):
            if order == 1:
                d = (hi[k] - hi[k - 1]) + (lo[k] - lo[k - 1])
            else:
                d = ((hi[k] - hi[k - 1]) - (hi[k - 1] - hi[k - 2])) + ((lo[k] - lo[k - 1]) - (lo[k - 1] - lo[k - 2]))
            total += d * d
        sums[level] = total
        half = count // 2
        for j in range(half):  # in place: j <= 2 j
            s, e = _two_sum(hi[2 * j], hi[2 * j + 1])
            lo[j] = (lo[2 * j] + lo[2 * j + 1]) + e
            hi[j] = s
        count = half
