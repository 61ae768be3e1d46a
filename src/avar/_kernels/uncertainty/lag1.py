"""Lag-1 autocorrelation noise identification of the decimated phase (numba).

Per averaging factor m: decimate the phase to x[0], x[m], x[2m], ..., remove its mean
(phase data) or its least-squares line (phase integrated from frequency data: the mean
frequency), as Stable32, then difference until the lag-1
autocorrelation says the series is stationary enough. Two streaming passes over the K = N / m
decimated points and no workspace: the first sums the line's
projections, the second forms the residuals and their differences on the fly and
accumulates, for two orders of difference at a time, the sum, the sum of squares and the lag-1 sum of products.
A contiguous series (m = 1: the first level, and the decimated copies of the others) takes
branch-free passes the compiler vectorizes (:func:`projections_contiguous`,
:func:`order_pass_contiguous`): the same value per point, summed in another order. The plain
twin is :func:`avar.stability.uncertainty.noise_id.lag1_alpha` (NumPy), which the tests
compare. The same rule from the Haar pyramid's moments, without the phase, is
:mod:`avar._kernels.uncertainty.noise_id`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.runtime.tasks import run_tasks

#: Sums may be reassociated (vectorized): the statistic is a ratio compared with 0.25 and rounded.
FAST_MATH = {"reassoc", "contract"}
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
    contiguous = m == 1 and half_drift == 0.0
    if contiguous:
        s0, s1, s2 = projections_contiguous(x, k, half, c2)
    else:
        s0, s1, s2 = _projections(x, m, k, half, c2, half_drift)
    kf = float(k)
    a0 = s0 / kf
    a1 = s1 / (kf * (kf * kf - 1.0) / 12.0)
    a2 = s2 / (kf * (kf * kf - 1.0) * (kf * kf - 4.0) / 180.0) if QUADRATIC and k > 2 else 0.0
    stats = np.zeros((4, 5))  # per order d: sum, sum of squares, lag-1 products, first, last value
    for d in range(dmax + 1):
        if d % 2 == 0:  # orders d and d + 1 in one pass (most series stop at d = 0 or 1)
            if contiguous and d == 0 and k >= 3:
                order_pass_contiguous(x, k, half, c2, a0, a1, a2, stats)
            else:
                _order_pass(x, m, k, half, c2, a0, a1, a2, d, stats, half_drift)
            if d == 0 and not np.isnan(line):  # order 0 of the phase as given: only its mean removed
                given = np.zeros((2, 5))
                if contiguous and k >= 3:
                    order_pass_contiguous(x, k, half, c2, a0, -line * m, 0.0, given)
                else:
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


@njit(cache=True, nogil=True, fastmath=FAST_MATH)
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


@njit(cache=True, nogil=True, fastmath=FAST_MATH)
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


#: Points per piece of the contiguous passes: their work arrays stay in the L1 cache.
PIECE = 1024


@njit(cache=True, nogil=True, fastmath=FAST_MATH)
def projections_contiguous(x, k, half, c2):
    """:func:`_projections` of ``x[:k]`` (m = 1, no drift) in pieces, the index t = i - half
    read from an array (``i - half`` is exact either way), so that the sums vectorize."""
    steps = np.arange(PIECE).astype(np.float64)
    s0 = 0.0
    s1 = 0.0
    s2 = 0.0
    for start in range(0, k, PIECE):
        size = min(PIECE, k - start)
        origin = start - half
        values = x[start : start + size]
        for j in range(size):
            t = origin + steps[j]
            v = values[j]
            s0 += v
            s1 += t * v
            s2 += (t * t - c2) * v
    return s0, s1, s2


@njit(cache=True, nogil=True, fastmath=FAST_MATH)
def order_pass_contiguous(x, k, half, c2, a0, a1, a2, stats):
    """:func:`_order_pass` of orders 0 and 1 of ``x[:k]`` (m = 1, no drift, k >= 3), branch free:
    each piece's residuals ``r_i = x_i - (a0 + a1 t + a2 (t^2 - c2))`` go to an array, then the
    sums read ``r_i``, ``r_{i-1}`` and ``r_{i-2}`` from it (the first differences formed
    again, not carried), so that they vectorize. Each value is :func:`_order_pass`'s: order 0
    is ``a_i = r_i - r_0`` (i >= 0), order 1 ``b_i = (r_i - r_{i-1}) - (r_1 - r_0)`` (i >= 1),
    both 0 at their first point, and the lag-1 sums are ``sum a_{i-1} a_i`` and ``sum b_{i-1} b_i``."""
    steps = np.arange(PIECE).astype(np.float64)
    r = np.empty(PIECE + 2)  # r[0], r[1]: the last two residuals of the piece before
    t0 = -half
    t1 = 1.0 - half
    first = x[0] - (a0 + a1 * t0 + a2 * (t0 * t0 - c2))
    second = x[1] - (a0 + a1 * t1 + a2 * (t1 * t1 - c2))
    sa = first
    sb = second - first
    ta = qa = pa = tb = qb = pb = 0.0
    r[0] = first  # before the first piece (i = 2 ..): r_0, r_1
    r[1] = second
    a_first = second - sa  # the sums over i = 1 (order 0: a_1; its lag product a_0 a_1 = 0)
    ta += a_first
    qa += a_first * a_first
    for start in range(2, k, PIECE):
        size = min(PIECE, k - start)
        origin = start - half
        values = x[start : start + size]
        for j in range(size):
            t = origin + steps[j]
            r[j + 2] = values[j] - (a0 + a1 * t + a2 * (t * t - c2))
        for j in range(size):
            a = r[j + 2] - sa
            a_before = r[j + 1] - sa
            b = (r[j + 2] - r[j + 1]) - sb
            b_before = (r[j + 1] - r[j]) - sb
            ta += a
            qa += a * a
            pa += a_before * a
            tb += b
            qb += b * b
            pb += b_before * b
        r[0] = r[size]
        r[1] = r[size + 1]
    last = r[1]
    before = r[0]
    stats[0, 0], stats[0, 1], stats[0, 2], stats[0, 3], stats[0, 4] = ta, qa, pa, 0.0, last - sa
    stats[1, 0], stats[1, 1], stats[1, 2] = tb, qb, pb
    stats[1, 3], stats[1, 4] = 0.0, (last - before) - sb


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
