"""The compiled update of :class:`avar.Stream`: O(levels) per sample, memory bounded by the largest tau.

State (all updated in place): ``hist_hi``/``hist_lo``, the last L phase
points as double-double numbers (phase of frequency data is the running sum
of y - y_first, in units of y times samples, accumulated with TwoSum so that
no rounding accumulates); ``state`` = [points so far (as float), reference
value]; per level the compensated sum of squared terms (``sums``,
``comps``) and the term count (``counts``); for the modified deviation the
last m second differences of every level (``dring``, at ``doffsets``) and
their running window sum (``dsum``, recomputed exactly every m differences).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _difference(hi, lo, a, b):
    """X_a - X_b of two double-double entries, rounded once."""
    ah, bh = hi[a], hi[b]
    s = ah - bh
    bb = s - ah
    e = (ah - (s - bb)) + (-bh - bb)
    return s + (e + (lo[a] - lo[b]))


@njit(cache=True)
def stream_update(chunk, is_freq, kind, state, hist_hi, hist_lo, m, sums, comps, counts, dring, doffsets, dsum,
                  dcount):
    """Feed ``chunk`` (float64 samples). ``kind``: 0 Allan overlapping, 1 Allan non-overlapping,
    2 Hadamard overlapping, 3 Hadamard non-overlapping, 4 modified Allan.

    ``hist_hi``/``hist_lo``: the last L phase points, oldest first (L at least
    span max(m)); ``state`` = [phase points so far, reference y_0, whether
    y_0 is set]; a frequency stream starts with X_0 = 0 (state[0] = 1). The
    chunk's phase points are appended to a copy of the history, then every
    level runs over them with its sums in registers.
    """
    size = hist_hi.size
    c = chunk.size
    buf_hi = np.empty(size + c)
    buf_lo = np.empty(size + c)
    buf_hi[:size] = hist_hi
    buf_lo[:size] = hist_lo
    p = np.int64(state[0])
    for t in range(c):
        value = chunk[t]
        if is_freq:
            if state[2] == 0.0:
                state[1] = value
                state[2] = 1.0
            hi, lo = buf_hi[size + t - 1], buf_lo[size + t - 1]
            v = value - state[1]
            s = hi + v
            bb = s - hi
            e = (hi - (s - bb)) + (v - bb)
            lo = lo + e
            hi = s + lo
            lo = lo - (hi - s)
        else:
            hi, lo = value, 0.0
        buf_hi[size + t] = hi
        buf_lo[size + t] = lo
    origin = p - size  # global index of buf[0]
    for level in range(m.size):
        k = m[level]
        total, comp, count = sums[level], comps[level], counts[level]
        base, dc, window = doffsets[level], dcount[level], dsum[level]
        for q in range(size, size + c):
            j = origin + q
            if kind <= 1 or kind == 4:
                if j < 2 * k or (kind == 1 and j % k != 0):
                    continue
                term = _difference(buf_hi, buf_lo, q, q - k) - _difference(buf_hi, buf_lo, q - k, q - 2 * k)
                if kind == 4:  # the sum of the last m second differences
                    slot = base + dc % k
                    old = dring[slot] if dc >= k else 0.0
                    dring[slot] = term
                    dc += 1
                    if dc % k == 0:  # exact window sum every m differences: rounding cannot drift
                        window = 0.0
                        for r in range(k):
                            window += dring[base + r]
                    else:
                        window += term - old
                    if dc < k:
                        continue
                    term = window
            else:
                if j < 3 * k or (kind == 3 and j % k != 0):
                    continue
                d2 = _difference(buf_hi, buf_lo, q, q - k)
                d1 = _difference(buf_hi, buf_lo, q - k, q - 2 * k)
                d0 = _difference(buf_hi, buf_lo, q - 2 * k, q - 3 * k)
                term = (d2 - d1) - (d1 - d0)
            y = term * term - comp
            tsum = total + y
            comp = (tsum - total) - y
            total = tsum
            count += 1
        sums[level], comps[level], counts[level] = total, comp, count
        dcount[level], dsum[level] = dc, window
    hist_hi[:] = buf_hi[c:]
    hist_lo[:] = buf_lo[c:]
    state[0] = p + c
