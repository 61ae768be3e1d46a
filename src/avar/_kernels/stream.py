"""The compiled update of :class:`avar.Stream`: O(levels) per sample, memory bounded by the largest tau.

State (all updated in place): ``ring_hi``/``ring_lo``, the last R phase
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
def _difference(ring_hi, ring_lo, a, b):
    """X_a - X_b of two double-double ring entries, rounded once."""
    ah, bh = ring_hi[a], ring_hi[b]
    s = ah - bh
    bb = s - ah
    e = (ah - (s - bb)) + (-bh - bb)
    return s + (e + (ring_lo[a] - ring_lo[b]))


@njit(cache=True)
def _add(sums, comps, level, value):
    y = value - comps[level]
    t = sums[level] + y
    comps[level] = (t - sums[level]) - y
    sums[level] = t


@njit(cache=True)
def stream_update(chunk, is_freq, kind, state, ring_hi, ring_lo, m, sums, comps, counts, dring, doffsets, dsum,
                  dcount):
    """Feed ``chunk`` (float64 samples). ``kind``: 0 Allan overlapping, 1 Allan non-overlapping,
    2 Hadamard overlapping, 3 Hadamard non-overlapping, 4 modified Allan.

    ``state`` = [phase points stored, reference y_0, whether y_0 is set]; a
    frequency stream starts with X_0 = 0 stored (state[0] = 1).
    """
    mask = ring_hi.size - 1  # a power of two
    for value in chunk:
        j = np.int64(state[0])
        if is_freq:
            if state[2] == 0.0:
                state[1] = value
                state[2] = 1.0
            prev = (j - 1) & mask
            hi, lo = ring_hi[prev], ring_lo[prev]
            v = value - state[1]
            s = hi + v
            bb = s - hi
            e = (hi - (s - bb)) + (v - bb)
            lo = lo + e
            hi = s + lo
            lo = lo - (hi - s)
        else:
            hi, lo = value, 0.0
        ring_hi[j & mask] = hi
        ring_lo[j & mask] = lo
        state[0] = j + 1
        for level in range(m.size):
            k = m[level]
            if kind <= 1 or kind == 4:
                if j < 2 * k or (kind == 1 and j % k != 0):
                    continue
                d1 = _difference(ring_hi, ring_lo, j & mask, (j - k) & mask)
                d0 = _difference(ring_hi, ring_lo, (j - k) & mask, (j - 2 * k) & mask)
                term = d1 - d0
                if kind == 4:  # the sum of the last m second differences
                    base = doffsets[level]
                    c = dcount[level]
                    old = dring[base + c % k] if c >= k else 0.0
                    dring[base + c % k] = term
                    c += 1
                    dcount[level] = c
                    if c % k == 0:  # exact window sum every m differences: rounding cannot drift
                        total = 0.0
                        for q in range(k):
                            total += dring[base + q]
                        dsum[level] = total
                    else:
                        dsum[level] += term - old
                    if c < k:
                        continue
                    term = dsum[level]
            else:
                if j < 3 * k or (kind == 3 and j % k != 0):
                    continue
                d2 = _difference(ring_hi, ring_lo, j & mask, (j - k) & mask)
                d1 = _difference(ring_hi, ring_lo, (j - k) & mask, (j - 2 * k) & mask)
                d0 = _difference(ring_hi, ring_lo, (j - 2 * k) & mask, (j - 3 * k) & mask)
                term = (d2 - d1) - (d1 - d0)
            _add(sums, comps, level, term * term)
            counts[level] += 1
