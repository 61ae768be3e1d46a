"""The small-input path of the Allan variance (numba): one call, one thread, no workspace.

For short series the cost of a call is dispatch, thread start-up and
allocation, not arithmetic. Here one compiled function does everything for
every column: a compensated sum (the exact centre and the largest
magnitude), the centred compensated cumulative sum ``S = hi + lo`` of the
column (2 x 8 bytes a sample, at most :data:`avar._kernels.columns.SMALL_MAX`
samples) and, per level, the squared second differences
``D = S[b + 2m] - 2 S[b + m] + S[b]`` (``b`` every sample for "mo", every
``m`` samples for "to"). The arithmetic is that of :mod:`streaming`: exact
centred pairs, TwoSum accumulation, compensated differences.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from avar._kernels.streaming import LIMIT_EXP, _block_sum, fill_prefix, squares


@njit(cache=True)
def _scale_of(big):
    """Power of two bringing a largest magnitude outside [2**-LIMIT_EXP, 2**LIMIT_EXP] near 1."""
    if np.isfinite(big) and big > 0.0 and (big > 2.0**LIMIT_EXP or big < 2.0**-LIMIT_EXP):
        _, e = math.frexp(big)
        return math.ldexp(1.0, -min(max(e, -1000), 1000))
    return 1.0


@njit(cache=True)
def small_allan_variance(data, factors, counts, is_mo, integral):
    """Allan variance of every column of ``data`` (N, C), shape (C, L).

    ``factors`` valid cluster sizes (any order); ``counts`` their numbers of
    differences (N - 2m + 1 for "mo", floor(N / m) - 1 for "to"), all > 0.
    """
    n, channels = data.shape
    n_levels = factors.shape[0]
    out = np.empty((channels, n_levels))
    hi = np.empty(n + 1)
    lo = np.empty(n + 1)
    buffer = np.empty(n)
    for c in range(channels):
        total, comp, big = _block_sum(data, c, 0, n, 1.0)
        scale = _scale_of(big)
        if scale != 1.0:
            total, comp, big = _block_sum(data, c, 0, n, scale)
        centre = (total + comp) / n
        if integral:
            centre = np.round(centre)
        fill_prefix(data, c, 0, n, centre, scale, 0.0, 0.0, hi, lo, 0)
        unscale = 1.0 / scale
        for k in range(n_levels):
            m = factors[k]
            count = counts[k]
            if is_mo:
                sums = squares(hi, lo, 0, hi, lo, m, hi, lo, 2 * m, count, buffer)
            else:
                sums = 0.0
                for j in range(count):
                    b = j * m
                    d = ((hi[b + 2 * m] - hi[b + m]) - (hi[b + m] - hi[b])) + (
                        (lo[b + 2 * m] - lo[b + m]) - (lo[b + m] - lo[b])
                    )
                    sums += d * d
            mf = np.float64(m)
            out[c, k] = sums / (2.0 * mf * mf * count) * unscale * unscale
    return out
