"""Noise identification from sums the kernels gather on the way (numba): the lag-1 rule from
the Haar pyramid's moments (:func:`lag1_alpha_from_moments`, no phase, no pass of its own),
R(n)'s running sums (:func:`running_sum`, :func:`rn_clusters`) and a removed drift added back
to the moments (:func:`moments_with_drift`). The lag-1 rule on the decimated phase itself is
:mod:`avar._kernels.uncertainty.lag1`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.uncertainty.lag1 import FAST_MATH, QUADRATIC


@njit(cache=True, nogil=True, fastmath=FAST_MATH)
def running_sum(x, drift, step, out):
    """R(n)'s running sum of the phase ``x_i + drift i (i - 1) / 2`` at every ``step``-th index:
    ``out[q] = sum_{i < q step}`` for q = 0 .. len(out) - 1 (block sums, then their running sum)."""
    total = 0.0
    out[0] = 0.0
    for q in range(out.shape[0] - 1):
        block = 0.0
        for i in range(q * step, (q + 1) * step):
            block += x[i] + drift * (i * (i - 1.0) / 2.0)
        total += block
        out[q + 1] = total


#: :func:`lag1_alpha_from_moments` returns this when cancellation leaves too few digits.
ILL_CONDITIONED = -99.0
#: Largest ratio of a raw sum of squares to the residual one derived from it (about 6 of
#: 16 digits lost) for which the moments decide; beyond, the two-pass kernel does.
KAPPA_MAX = 1e6


@njit(cache=True, nogil=True)
def _order_stats(row, d):
    """total, squares, first, last of the order-``d`` differences of the residual phase
    (its least-squares line, or quadratic, removed), and the raw sum of squares ``squares`` was derived from,
    from the moments of :mod:`avar._kernels.classic.pyramid` (``row``: one level, see ``MOMENTS``)."""
    c = row[0]
    k = c + 1.0
    half = c / 2.0
    c2 = (k * k - 1.0) / 12.0
    s0, s1, q0, v_squares, e1, e2 = row[1], row[2], row[4], row[5], row[6], row[7]
    s2 = row[3] - c2 * s0  # sum (t^2 - c2) z
    a0 = s0 / k
    a1 = s1 / (k * (k * k - 1.0) / 12.0)
    a2 = s2 / (k * (k * k - 1.0) * (k * k - 4.0) / 180.0) if QUADRATIC and k > 2.0 else 0.0
    z_last, v_first, v_last = row[9], row[10], row[11]
    if d == 0:  # r = z - q(t): orthogonal projections of z removed
        squares = q0 - s0 * a0 - s1 * a1 - s2 * a2
        q_first = a0 - a1 * half + a2 * (half * half - c2)
        q_last = a0 + a1 * half + a2 * (half * half - c2)
        return s0 - k * a0, squares, -q_first, z_last - q_last, q0
    if d == 1:  # v_j - l_j, l_j = a1 + a2 u_j, u_j = 2 j - (C - 1): sum u = 0, sum u^2 = C (C^2 - 1) / 3,
        # sum v = z_C, sum u v = (C + 1) z_C - 2 sum z (summation by parts)
        u_v = (c + 1.0) * z_last - 2.0 * s0
        squares = v_squares - 2.0 * (a1 * z_last + a2 * u_v) + c * a1 * a1 + a2 * a2 * c * (c * c - 1.0) / 3.0
        return (z_last - c * a1, squares, v_first - (a1 - a2 * (c - 1.0)), v_last - (a1 + a2 * (c - 1.0)),
                v_squares)
    if d == 2:  # the first differences of v less 2 a2
        rise = v_last - v_first
        squares = e1 - 4.0 * a2 * rise + 4.0 * a2 * a2 * (c - 1.0)
        return rise - 2.0 * a2 * (c - 1.0), squares, row[12] - 2.0 * a2, row[13] - 2.0 * a2, e1
    if d == 3:  # the second differences of v: the quadratic is gone
        return row[13] - row[12], e2, row[14], row[15], e2
    return 0.0, row[8], 0.0, 0.0, row[8]  # d == 4: only its sum of squares is used


@njit(cache=True, nogil=True, inline="always")
def _lost(raw, squares):
    """True when ``squares``, derived from the raw sum ``raw`` by cancellation, kept too few digits."""
    return raw != 0.0 and not (squares > 0.0 and raw <= KAPPA_MAX * squares)


@njit(cache=True, nogil=True)
def lag1_alpha_from_moments(row, dmax):
    """:func:`avar._kernels.uncertainty.lag1.lag1_alpha_decimated` of one level from its moments, without the phase.

    The lag-1 sum of products of each order of differences w follows from sums
    of squares: sum w_i w_{i+1} = (2 sum w^2 - w_first^2 - w_last^2 - sum (dw)^2) / 2.
    Returns NaN for a constant series and :data:`ILL_CONDITIONED` when a sum it
    needs lost more than log10(:data:`KAPPA_MAX`) digits to cancellation (the sums of
    squares derived from raw ones, or the variance about a mean far above the noise).
    """
    length = row[0] + 1.0
    total, squares, first, last, raw = _order_stats(row, 0)
    for d in range(dmax + 1):
        n_total, n_squares, n_first, n_last, n_raw = _order_stats(row, d + 1)
        if _lost(raw, squares) or _lost(n_raw, n_squares):
            return ILL_CONDITIONED
        mean = total / length
        power = squares - total * mean
        if squares > 0.0 and not power > squares / KAPPA_MAX:  # a mean far above the noise (the
            return ILL_CONDITIONED  # constant second differences of a large drift) took its digits
        if not power > 0.0:
            return np.nan
        products = (2.0 * squares - first * first - last * last - n_squares) / 2.0
        lag = products - mean * (2.0 * total - first - last) + (length - 1.0) * mean * mean
        r1 = lag / power * (length - 1.0) / length  # Stable32: the variance over n - 1
        rho = r1 / (1.0 + r1)
        if rho < 0.25 or d >= dmax:
            return 2.0 - np.round(2.0 * rho) - 2.0 * d
        total, squares, first, last, raw = n_total, n_squares, n_first, n_last, n_raw
        length -= 1.0
    return np.nan


@njit(cache=True, nogil=True, fastmath=FAST_MATH)
def rn_clusters(y, centre, slope, scale, step, z, running):
    """What R(n) needs at stride ``step`` from frequency data, without the phase.

    With ``x_i = sum_{j < i} (y_j - centre - slope j) scale`` the detrended
    phase (N + 1 points), fill ``z[k] = x[k step]`` (k = 0 .. N // step) and
    ``running[k] = sum_{i < k step} x_i`` (k = 0 .. (N + 1) // step): the
    ``step`` phase points from ``k step`` add ``step x[k step] + sum_r
    (step - 1 - r) y'_{k step + r}``. One pass over the data (plain sums: R(n)
    is a ratio).
    """
    n = y.shape[0]
    z[0] = 0.0
    running[0] = 0.0
    phase = 0.0
    total = 0.0
    for k in range((n + 1) // step):
        base = k * step
        weighted = 0.0
        cluster = 0.0
        for r in range(step - 1):
            v = ((y[base + r] - centre) - slope * (base + r)) * scale
            cluster += v
            weighted += (step - 1 - r) * v
        total += step * phase + weighted
        running[k + 1] = total
        if base + step <= n:  # the phase at the next cluster
            last = base + step - 1
            phase += cluster + ((y[last] - centre) - slope * last) * scale
            z[k + 1] = phase


@njit(cache=True, nogil=True)
def moments_with_drift(row, drift, m):
    """The moments ``row`` of one level (see :func:`_order_stats`) of the decimated phase
    z_i (i = 0 .. C, z_0 = 0) with ``drift * (i m) (i m - 1) / 2`` added back to it.

    With p_i = a i**2 + b i (a = drift m**2 / 2, b = -drift m / 2): the sums of p, t p,
    t**2 p, p**2 and of its differences (2 a (2 j + 1) / 2 + ..., then the constant 2 a) are
    power sums; the cross sums follow from those of z (sum i z = sum t z + h sum z, ...,
    sum j (z_{j+1} - z_j) = C z_C - sum z). Differences of order 3 and up lose p.
    """
    out = row.copy()
    c = row[0]
    h = c / 2.0
    a = drift * m * m / 2.0
    b = -drift * m / 2.0
    s1_ = c * (c + 1.0) / 2.0
    s2_ = c * (c + 1.0) * (2.0 * c + 1.0) / 6.0
    s3_ = s1_ * s1_
    s4_ = c * (c + 1.0) * (2.0 * c + 1.0) * (3.0 * c * c + 3.0 * c - 1.0) / 30.0
    p_sum = a * s2_ + b * s1_
    ip_sum = a * s3_ + b * s2_
    iip_sum = a * s4_ + b * s3_
    z_sum, z_t, z_t2 = row[1], row[2], row[3]
    iz = z_t + h * z_sum
    iiz = z_t2 + 2.0 * h * z_t + h * h * z_sum
    out[1] = z_sum + p_sum
    out[2] = z_t + ip_sum - h * p_sum
    out[3] = z_t2 + iip_sum - 2.0 * h * ip_sum + h * h * p_sum
    out[4] = row[4] + 2.0 * (a * iiz + b * iz) + a * a * s4_ + 2.0 * a * b * s3_ + b * b * s2_
    # first differences: dp_j = 2 a j + (a + b), j = 0 .. C - 1
    t1 = c * (c - 1.0) / 2.0
    t2 = (c - 1.0) * c * (2.0 * c - 1.0) / 6.0
    z_last = row[9]
    jdz = c * z_last - z_sum  # sum j (z_{j+1} - z_j), z_0 = 0
    out[5] = (row[5] + 2.0 * ((a + b) * z_last + 2.0 * a * jdz)
              + 4.0 * a * a * t2 + 4.0 * a * (a + b) * t1 + (a + b) * (a + b) * c)
    # second differences gain the constant 2 a (C - 1 of them)
    out[6] = row[6] + 4.0 * a * (row[11] - row[10]) + 4.0 * a * a * (c - 1.0)
    out[9] = z_last + a * c * c + b * c
    out[10] = row[10] + a + b
    out[11] = row[11] + a * (2.0 * c - 1.0) + b
    out[12] = row[12] + 2.0 * a
    out[13] = row[13] + 2.0 * a
    return out
