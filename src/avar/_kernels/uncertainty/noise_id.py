"""Lag-1 autocorrelation noise identification (numba).

Per averaging factor m: decimate the phase to x[0], x[m], x[2m], ..., remove its mean
(phase data) or its least-squares line (phase integrated from frequency data: the mean
frequency), as Stable32, then difference until the lag-1
autocorrelation says the series is stationary enough. Two streaming passes over the K = N / m
decimated points and no workspace: the first sums the line's
projections, the second forms the residuals and their differences on the fly and
accumulates, for two orders of difference at a time, the sum, the sum of squares and the lag-1 sum of products. The plain
twin is :func:`avar.stability.uncertainty.noise_id.lag1_alpha` (NumPy), which the tests
compare.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.runtime.tasks import run_tasks

#: Sums may be reassociated (vectorized): the statistic is a ratio compared with 0.25 and rounded.
_FAST = {"reassoc", "contract"}
#: Remove a least-squares quadratic (frequency drift too) rather than a line before the lag-1
#: rule. Stable32 removes only the line: on its table of a 10,000-point flicker FM record (OADEV,
#: m = 326, 30 averages) the quadratic turns its white FM into flicker PM (alpha 0.52 vs 0.46).
QUADRATIC = False


@njit(cache=True, nogil=True)
def _point(x, k, half_drift):
    """``x[k] + drift k (k - 1) / 2`` (``half_drift = drift / 2``), rounded as
    :func:`avar.stability.uncertainty.lag1.with_drift` rounds it (no contraction: compiled apart)."""
    return x[k] + ((k - 1.0) * k) * half_drift


@njit(cache=True, nogil=True)
def lag1_alpha_decimated(x, m, dmax, line, drift=0.0):
    """alpha of x[0], x[m], x[2m], ... by the lag-1 autocorrelation (Riley and Greenhall 2004).

    ``line`` NaN (phase integrated from frequency data): the decimated series
    z (K points) loses its least-squares line, the mean frequency (the
    quadratic too if :data:`QUADRATIC`), computed with the discrete orthogonal
    polynomials 1, t, t**2 - (K**2 - 1) / 12 of the centred index t (sums, no
    linear system). ``line`` a number (phase data): ``x`` lacks ``line * i``,
    which the phase data had; z is taken with it and loses only its mean, as
    Stable32 (the differences, d >= 1, do not see the line; they are formed
    from the least-squares residuals, which keeps a large frequency offset
    from cancelling their digits). Then, with n points left,
    r1 = (sum (z_i - zbar)(z_{i+1} - zbar) / n) / (sum (z_i - zbar)**2 / (n - 1)) and
    rho = r1 / (1 + r1), z is differenced until rho < 0.25 or d = dmax, and
    alpha = 2 - round(2 rho) - 2 d (round half to even, as ``numpy.round``).
    ``drift``: ``x`` lacks ``drift * i (i - 1) / 2`` (a removed linear frequency drift), which
    the decimated series gets back (as :func:`avar.stability.uncertainty.lag1.with_drift` adds it).
    Returns NaN for a constant series. Needs K >= 3 and dmax <= 3.
    """
    half_drift = 0.5 * drift  # exact halving: (p / 2) drift and p (drift / 2) round alike
    k = (x.shape[0] - 1) // m + 1
    half = (k - 1) / 2.0
    c2 = (k * k - 1.0) / 12.0
    s0, s1, s2 = _projections(x, m, k, half, c2, half_drift)
    kf = float(k)
    a0 = s0 / kf
    a1 = s1 / (kf * (kf * kf - 1.0) / 12.0)
    a2 = s2 / (kf * (kf * kf - 1.0) * (kf * kf - 4.0) / 180.0) if QUADRATIC and k > 2 else 0.0
    stats = np.zeros((4, 5))  # per order d: sum, sum of squares, lag-1 products, first, last value
    for d in range(dmax + 1):
        if d % 2 == 0:  # orders d and d + 1 in one pass (most series stop at d = 0 or 1)
            _order_pass(x, m, k, half, c2, a0, a1, a2, d, stats, half_drift)
            if d == 0 and not np.isnan(line):  # order 0 of the phase as given: only its mean removed
                given = np.zeros((2, 5))
                _order_pass(x, m, k, half, c2, a0, -line * m, 0.0, 0, given, half_drift)
                stats[0, :] = given[0, :]
        length = k - d
        total, squares, products, first, last = stats[d, 0], stats[d, 1], stats[d, 2], stats[d, 3], stats[d, 4]
        mean = total / length
        power = squares - total * mean
        if not power > 0.0:
            return np.nan
        lag = products - mean * (2.0 * total - first - last) + (length - 1) * mean * mean
        r1 = lag / power * (length - 1.0) / length  # Stable32: the variance over n - 1
        rho = r1 / (1.0 + r1)
        if rho < 0.25 or d >= dmax:
            return 2.0 - np.round(2.0 * rho) - 2.0 * d
    return np.nan


@njit(cache=True, nogil=True, fastmath=_FAST)
def _projections(x, m, k, half, c2, half_drift):
    """Sums of x[i m] times 1, t and t**2 - c2 (t = i - half); ``half_drift`` (not 0): of
    :func:`_point`."""
    s0 = 0.0
    s1 = 0.0
    s2 = 0.0
    for i in range(k):
        v = x[i * m] if half_drift == 0.0 else _point(x, i * m, half_drift)
        t = i - half
        s0 += v
        s1 += t * v
        s2 += (t * t - c2) * v
    return s0, s1, s2


@njit(cache=True, nogil=True, fastmath=_FAST)
def _order_pass(x, m, k, half, c2, a0, a1, a2, low, stats, half_drift):
    """Stats of the differences of orders ``low`` and ``low + 1`` (0 or 2) of the residuals, streamed:
    per order, the sum, sum of squares, lag-1 sum of products, first and last value of its values
    less its first one (the lag-1 statistic is unchanged by the shift, and a constant far above the
    noise, such as the second differences of a large frequency drift, cancels exactly first).
    ``half_drift`` (not 0): the points are :func:`_point`'s."""
    ta = tb = qa = qb = pa = pb = 0.0
    w0 = w1 = w2 = w3 = 0.0  # the latest value of every order
    fa = fb = 0.0
    sa = sb = 0.0  # every order's sums are of its values less its first value: a drift's constant
    # difference (or any offset far above the noise) then cancels before the squares, not in them
    head = min(k, low + 2)
    for i in range(head):  # the first points, where the orders start: branches
        t = i - half
        v0 = (x[i * m] if half_drift == 0.0 else _point(x, i * m, half_drift)) - (a0 + a1 * t + a2 * (t * t - c2))
        v1 = v0 - w0
        v2 = v1 - w1
        v3 = v2 - w2
        if low == 0:
            va, vb, ua, ub = v0, v1, w0, w1
        else:
            va, vb, ua, ub = v2, v3, w2, w3
        if i == low:
            sa = va
        if i == low + 1:
            sb = vb
        va -= sa
        vb -= sb
        ua -= sa
        ub -= sb
        pa += ua * va
        pb += ub * vb
        ta += va
        tb += vb
        qa += va * va
        qb += vb * vb
        w0, w1, w2, w3 = v0, v1, v2, v3
        if i < low:  # order d starts at point d: drop what came before
            ta = qa = pa = 0.0
        elif i == low:
            fa = va
            pa = 0.0
        if i <= low:
            tb = qb = pb = 0.0
        else:
            fb = vb
            pb = 0.0
    if low == 0:  # no branch in the loops over the rest
        ua, ub = w0 - sa, w1 - sb
        for i in range(head, k):
            t = i - half
            v0 = (x[i * m] if half_drift == 0.0 else _point(x, i * m, half_drift)) - (a0 + a1 * t + a2 * (t * t - c2))
            v1 = v0 - w0
            va = v0 - sa
            vb = v1 - sb
            pa += ua * va
            pb += ub * vb
            ta += va
            tb += vb
            qa += va * va
            qb += vb * vb
            w0, w1, ua, ub = v0, v1, va, vb
    else:
        ua, ub = w2 - sa, w3 - sb
        for i in range(head, k):
            t = i - half
            v0 = (x[i * m] if half_drift == 0.0 else _point(x, i * m, half_drift)) - (a0 + a1 * t + a2 * (t * t - c2))
            v1 = v0 - w0
            v2 = v1 - w1
            v3 = v2 - w2
            va = v2 - sa
            vb = v3 - sb
            pa += ua * va
            pb += ub * vb
            ta += va
            tb += vb
            qa += va * va
            qb += vb * vb
            w0, w1, w2, w3, ua, ub = v0, v1, v2, v3, va, vb
    stats[low, 0], stats[low, 1], stats[low, 2], stats[low, 3] = ta, qa, pa, fa
    stats[low, 4] = (w0 if low == 0 else w2) - sa
    stats[low + 1, 0], stats[low + 1, 1], stats[low + 1, 2] = tb, qb, pb
    stats[low + 1, 3], stats[low + 1, 4] = fb, (w1 if low == 0 else w3) - sb


@njit(cache=True, nogil=True)
def lag1_levels(x, factors, dmax, line, out, drift=0.0):
    """:func:`lag1_alpha_decimated` at every factor into ``out``, serially (``drift`` as there)."""
    for i in range(factors.shape[0]):
        out[i] = lag1_alpha_decimated(x, factors[i], dmax, line, drift)


def lag1_levels_split(x, factors, dmax, line, out, drift=0.0):
    """:func:`lag1_levels` on two threads: the first level (the longest; at the octave
    m = 1 it holds half the points) on one, the others on the other."""

    def worker(w):
        if w == 0:
            out[0] = lag1_alpha_decimated(x, factors[0], dmax, line, drift)
        else:
            _decimating_levels(x, factors, dmax, line, out, drift)

    run_tasks(2, worker)


@njit(cache=True, nogil=True)
def _decimating_levels(x, factors, dmax, line, out, drift):
    """Levels 1, 2, ... of :func:`lag1_levels_split`: where a factor is a multiple of the one
    before (octaves), the decimated points are taken from that level's contiguous copy
    (decimated in place) rather than from ``x`` at a long stride: the same values, fewer
    cache lines read. The copy gets ``drift``'s points back (:func:`_point`)."""
    n = x.shape[0]
    half_drift = 0.5 * drift
    buffer = np.empty((n - 1) // factors[1] + 1) if factors.shape[0] > 1 else np.empty(1)
    held = 0  # the factor whose points ``buffer`` holds (0: none)
    length = 0
    for i in range(1, factors.shape[0]):
        m = factors[i]
        if held > 0 and m % held == 0:
            step = m // held
            length = (length - 1) // step + 1
            for j in range(length):
                buffer[j] = buffer[j * step]
        else:
            length = (n - 1) // m + 1
            if length > buffer.shape[0]:
                buffer = np.empty(length)
            if half_drift == 0.0:
                for j in range(length):
                    buffer[j] = x[j * m]
            else:
                for j in range(length):
                    buffer[j] = _point(x, j * m, half_drift)
        held = m
        out[i] = lag1_alpha_decimated(buffer[:length], 1, dmax, line * m, 0.0)


#: The compiled loops of :func:`lag1_levels_split` and of :func:`lag1_levels` (:func:`lag1_kernels`).
SPLIT_KERNELS = (lag1_alpha_decimated, _decimating_levels)
SERIAL_KERNELS = (lag1_levels,)


def lag1_kernels(n_levels):
    """The compiled loops :func:`lag1_levels_split` (several levels) or :func:`lag1_levels` (one)
    runs (whether they are compiled yet: :func:`avar._kernels.runtime.paths.compiled`)."""
    return SPLIT_KERNELS if n_levels > 1 else SERIAL_KERNELS


@njit(cache=True, nogil=True, fastmath=_FAST)
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
    """:func:`lag1_alpha_decimated` of one level from its moments, without the phase.

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


@njit(cache=True, nogil=True, fastmath=_FAST)
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
