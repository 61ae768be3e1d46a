"""Every window's sum of squared terms at one level, from prefix sums of the record's terms (numba).

Nothing here validates input: :mod:`avar.stability.dynamic.estimator` does that once and calls
:func:`window_sums` on the record's compensated phase ``hi + lo`` (or its running sum, for the
modified statistics) as :func:`avar.stability.classic.core.phase_parts` builds it.

A classic statistic's terms are differences of that phase which do not depend on where the
window starts: term ``b`` of the record is term ``b - s`` of the window that starts at phase
point ``s``, so a window's sum of squared terms is a sum over a stretch of the record's terms
(every ``stride``-th one: ``m`` for ADEV and HDEV, 1 for the others). Each level therefore costs
one pass over the record's terms and O(1) per window:

1. the squares ``d_b^2`` of every term ``b`` (``code`` as in :mod:`avar._kernels.classic.levels`:
   0 second differences, 1 third differences, 2 third and 4 fourth differences of the running
   sum), with 0 for a term that touches a gap;
2. their prefix sums along each residue class modulo ``stride``, compensated (TwoSum: the
   prefix is ``ph + pl`` to O(eps^2) of the prefix), and the prefix count of the valid terms;
3. window ``w``: ``(ph[e] - ph[s]) + (pl[e] - pl[s])`` with ``s = starts[w]`` and ``e = s +
   count * stride``, accurate relative to the window's own sum (not to the record's), so every
   window equals its statistic computed alone to a few ulps.

Gaps: ``mode`` and ``bad`` as in :mod:`avar._kernels.classic.levels` (1: phase points missing,
``bad`` their prefix count; 2: frequency values missing, ``bad`` their prefix count).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.dd import two_sum

#: How far past its first point each code's term reaches, in units of m (on the running sum for 2 and 4).
REACH = {0: 2, 1: 3, 2: 3, 4: 4}


@njit(cache=True, inline="always")
def _term(hi, lo, code, b, m):
    """Term ``b`` of a level: the code's difference of ``hi + lo`` at lag ``m``, formed in parts."""
    h1 = hi[b + m] - hi[b]
    h2 = hi[b + 2 * m] - hi[b + m]
    l1 = np.float64(lo[b + m] - lo[b])
    l2 = np.float64(lo[b + 2 * m] - lo[b + m])
    if code == 0:
        return (h2 - h1) + (l2 - l1)
    h3 = hi[b + 3 * m] - hi[b + 2 * m]
    l3 = np.float64(lo[b + 3 * m] - lo[b + 2 * m])
    if code != 4:
        return ((h3 - h2) - (h2 - h1)) + ((l3 - l2) - (l2 - l1))
    h4 = hi[b + 4 * m] - hi[b + 3 * m]
    l4 = np.float64(lo[b + 4 * m] - lo[b + 3 * m])
    return (((h4 - h3) - (h3 - h2)) - ((h3 - h2) - (h2 - h1))) + (((l4 - l3) - (l3 - l2)) - ((l3 - l2) - (l2 - l1)))


@njit(cache=True, inline="always")
def _valid(code, mode, bad, b, m):
    """Whether term ``b`` avoids every gap: its points (phase gaps, codes 0 and 1), the points it
    spans (phase gaps, codes 2 and 4) or the frequency values between its first and last point."""
    reach = 2 * m if code == 0 else (4 * m if code == 4 else 3 * m)
    if mode == 2:
        last = b + reach if code < 2 else b + reach - 1
        return bad[last] == bad[b]
    if code >= 2:
        return bad[b + reach] == bad[b]
    for k in range(0, reach + 1, m):
        if bad[b + k + 1] != bad[b + k]:
            return False
    return True


@njit(cache=True, nogil=True)
def window_sums(hi, lo, code, m, stride, starts, count, mode, bad, sums, counts):
    """Sum of squared terms and number of terms used of every window at one level.

    Parameters
    ----------
    hi, lo : float64, float32 arrays
        The record's phase (or running sum) as two parts.
    code, m, stride : int
        The terms (see the module notes), the averaging factor, the step between a window's terms.
    starts : int64 array
        The first term of every window (its first phase point).
    count : int
        Terms per window without gaps.
    mode, bad : gaps (mode 0: none; ``bad`` unused).
    sums, counts : float64 and int64 arrays, one slot per window (written).
    """
    reach = 2 * m if code == 0 else (4 * m if code == 4 else 3 * m)
    n_terms = hi.shape[0] - reach
    size = n_terms + stride
    ph = np.zeros(size)
    pl = np.zeros(size)
    pc = np.zeros(size, dtype=np.int64)
    for b in range(n_terms):
        ok = mode == 0 or _valid(code, mode, bad, b, m)
        d = _term(hi, lo, code, b, m) if ok else 0.0
        total, error = two_sum(ph[b], d * d)
        ph[b + stride] = total
        pl[b + stride] = pl[b] + error
        pc[b + stride] = pc[b] + (1 if ok else 0)
    for w in range(starts.shape[0]):
        s = starts[w]
        e = s + count * stride
        sums[w] = (ph[e] - ph[s]) + (pl[e] - pl[s])
        counts[w] = pc[e] - pc[s]
