"""MHTOTDEV's level sums in O(N) per level, exact up to rounding (numba).

The direct loop of :mod:`avar._kernels.total.mhtot` costs O(m) per window. Here, as
:mod:`avar._kernels.total.blocks` does for MTOTDEV and HTOTDEV (read its docstring first),
a level's windows are summed in blocks, and each block's sum is expanded into a few sliding
sums of the prefix sum X of the phase.

Window n holds the L = 3m + 1 phase points x_n .. x_{n+3m}, less the line through the means
of its halves (h = floor(L / 2) points and g = L - h: slope s_n = (mean_2 - mean_1) / (L / 2))
and its mean mu_n (which changes nothing: the differences below remove it). Its running sum is::

    S_n(i) = X(n + i) - X(n) - mu_n i - s_n i (i - 1) / 2,   i = 0 .. L,   S_n(L) = 0,

and the running sum of the extension (rev w, w, rev w) is E(i) = -S(L - i), S(i - L),
-S(3L - i) on its thirds. The window's m-point sums of third differences are fourth
differences of E::

    A_j = -E(j) + 4 E(j + m) - 6 E(j + 2m) + 4 E(j + 3m) - E(j + 4m),   j = 0 .. 5m + 3,

and its term is T(n) = sum_j A_j^2. The points L - q m and 2L - q m (q = 0 .. 4) cut the j
range into nine segments (lengths 1, m, m, 1, m - 1, 1, m, m, 2) on each of which every
E(j + q m) sits in one third: A_j = sum_q gamma_q S(b_q + d_q j') (j = first + j', d = +1 in
the middle third, -1 in the reflected ones). So A_j = U_j + P_j with U_j = sum_q gamma_q
X(n + b_q + d_q j') and P_j = X(n) pi_X + mu_n pi_mu(j') + s_n pi_s(j') (quadratics in j'),
and T(n) = sum U^2 + 2 sum U P + sum P^2, summed over a block's windows:

1. pairs of X read in the same direction: sum_t w(t) X(t) X(t + lag) per lag, with integer
   trapezoid weights w (a double running sum of four spikes per pair and segment);
2. pairs read in opposite directions, sum_n sum_j' X(n + b + j') X(n + c - j'): the partners
   of each n + j' form a run of step 2, read from a running sum over each parity;
3. sum_j' U P: the sliding moments sum_{u<m} u^p X(n + lo + u) (p <= 2) at a few offsets lo,
   and a few single points (the segments of length 1, 2 and m - 1), times exact tables;
4. sum_j' P^2: a 3 x 3 table times (X(n), mu_n, s_n).

Each part costs O(B + L) per block of B windows, so a level costs O(N). The blocks, their
local detrending (conditioning: each block removes its own line first) and their size are
those of :mod:`avar._kernels.total.blocks` (:func:`~avar._kernels.total.blocks.blocks`,
:func:`~avar._kernels.total.blocks.block_size`, :func:`~avar._kernels.total.blocks.prepare_block`,
:func:`~avar._kernels.total.blocks.sliding_moments`); gaps: the blocks are laid over the runs
of windows that avoid them. The tests check the expansion against the direct loop (~1e-13 on
every power-law noise, phase and frequency data, with gaps; measured up to N = 1e6, at most
1.4e-13) and exact rationals. A block costs 25 to 75 ns per window on one core (m = 1 .. 1e4;
the direct loop ~20 + 18 m ns).
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numba import njit

from avar._kernels.total.blocks import prepare_block, run_blocks, sliding_moments

#: The weights of A_j = sum_q WEIGHTS[q] E(j + q m): minus the fourth difference of E.
WEIGHTS = (-1, 4, -6, 4, -1)


class MhtotTables(NamedTuple):
    """The exact tables of one level's expansion (:func:`level_tables`), in the order the kernel takes them."""

    #: The distinct lags of the same-direction pairs.
    lags: np.ndarray
    #: Rows (lag index, first position, length, weight): sum_n sum_{u<length} X(n + lo + u) X(n + lo + u + lag).
    same: np.ndarray
    #: Rows (b, c, length, weight): sum_n sum_{j'<length} X(n + b + j') X(n + c - j'), sorted by (c, length).
    opposite: np.ndarray
    #: Offsets lo and weights [row, xi, p]: sum_j' U pi_xi holds weights times sum_{u<m} u^p X(n + lo + u).
    moment_at: np.ndarray
    moment_weights: np.ndarray
    #: Positions q and weights [row, xi]: sum_j' U pi_xi also holds weights times X(n + q).
    point_at: np.ndarray
    point_weights: np.ndarray
    #: square[xi, xi'] = sum_j pi_xi pi_xi' (xi = X(n), mu, s).
    square: np.ndarray


class Segment(NamedTuple):
    """A run of j = first .. first + length - 1 (:func:`segments`)."""

    first: int
    length: int


def segments(m: int) -> list[Segment]:
    """The segments of j = 0 .. 5m + 3 on which each E(j + q m) stays in one third.

    >>> [tuple(segment) for segment in segments(2)]
    [(0, 1), (1, 2), (3, 2), (5, 1), (6, 1), (7, 1), (8, 2), (10, 2), (12, 2)]
    """
    span = 3 * m + 1
    n_sums = 5 * m + 4
    cuts = {0, n_sums}
    for q in range(5):
        cuts.update(edge for edge in (span - q * m, 2 * span - q * m) if 0 < edge < n_sums)
    edges = sorted(cuts)
    return [Segment(a, b - a) for a, b in zip(edges[:-1], edges[1:])]


def _segment_terms(first: int, length: int, m: int) -> list[tuple[int, int, int]]:
    """(gamma, b, d) of the five E values of a segment: WEIGHTS[q] E(first + j' + q m) = gamma S(b + d j')."""
    span = 3 * m + 1
    terms = []
    for q, weight in enumerate(WEIGHTS):
        start = first + q * m
        if start < span:
            terms.append((-weight, span - start, -1))
        elif start < 2 * span:
            terms.append((weight, start - span, 1))
        else:
            terms.append((-weight, 3 * span - start, -1))
        assert 0 <= min(terms[-1][1], terms[-1][1] + terms[-1][2] * (length - 1)) and terms[-1][1] <= span
    return terms


def _power_sums(length: int) -> list[int]:
    """sum_{j<length} j^p, p = 0 .. 4, exactly (Faulhaber)."""
    n = length - 1
    return [length, n * length // 2, n * length * (2 * n + 1) // 6, (n * length // 2) ** 2,
            n * length * (2 * n + 1) * (3 * n * n + 3 * n - 1) // 30]


def _polynomials(terms: list[tuple[int, int, int]]) -> list[tuple[int, int, int]]:
    """2 pi_X, 2 pi_mu, 2 pi_s: twice the coefficients of 1, j', j'^2 of P_j's factors of X(n), mu
    and s (integers)."""
    return [(-2 * sum(g for g, _, _ in terms), 0, 0),
            (-2 * sum(g * b for g, b, _ in terms), -2 * sum(g * d for g, _, d in terms), 0),
            (-sum(g * (b * b - b) for g, b, _ in terms), -sum(g * d * (2 * b - 1) for g, b, d in terms),
             -sum(g for g, _, _ in terms))]


def _at(weights: list[list[int]], u: int) -> list[int]:
    """sum_p weights[xi][p] u^p for each xi."""
    return [row[0] + row[1] * u + row[2] * u * u for row in weights]


def _add(table: dict, key: int, values: list[int], sign: int = 1) -> None:
    old = table.setdefault(key, [0] * len(values))
    for i, v in enumerate(values):
        old[i] += sign * v


@lru_cache(maxsize=1024)
def level_tables(m: int) -> MhtotTables:
    """The expansion of level ``m`` (see the module docstring), from exact integers (the cross and
    square tables are built doubled and quadrupled, then halved and quartered in floats: exact)."""
    same: dict[tuple[int, int, int], int] = {}
    opposite: dict[tuple[int, int, int], int] = {}
    cross: dict[tuple[int, int], list] = {}  # (lo, length) -> 2 x [xi][p] weights of sum_{u<length} u^p X(n + lo + u)
    square = [[0] * 3 for _ in range(3)]  # 4 x
    for first, length in segments(m):
        terms = _segment_terms(first, length, m)
        for ga, ba, da in terms:
            for gc, bc, dc in terms:
                if da == dc:
                    lo_a, lo_c = (ba, bc) if da == 1 else (ba - length + 1, bc - length + 1)
                    key = (abs(lo_c - lo_a), min(lo_a, lo_c), length)
                    same[key] = same.get(key, 0) + ga * gc
                else:
                    key = (ba, bc, length) if da == 1 else (bc, ba, length)
                    opposite[key] = opposite.get(key, 0) + ga * gc
        pis = _polynomials(terms)
        top = length - 1
        for g, b, d in terms:
            lo = b if d == 1 else b - top
            weights = cross.setdefault((lo, length), [[0] * 3 for _ in range(3)])
            for xi, (q0, q1, q2) in enumerate(pis):
                # in u = j' (d = +1) or u = length - 1 - j' (d = -1)
                coefficients = (q0, q1, q2) if d == 1 else (q0 + q1 * top + q2 * top * top, -q1 - 2 * q2 * top, q2)
                for p in range(3):
                    weights[xi][p] += g * coefficients[p]
        power = _power_sums(length)
        for a in range(3):
            for c in range(3):
                square[a][c] += sum(pis[a][p] * pis[c][q] * power[p + q] for p in range(3) for q in range(3))
    for (b, c, length), w in list(opposite.items()):
        # short rows are a few single products (same-direction rows of length 1); rows of length
        # m - 1 are rows of length m less their product at j' = m - 1: fewer, longer rows
        if length <= 2 or (length == m - 1 and c >= length and b + length <= 3 * m + 1):
            del opposite[(b, c, length)]
            if length == m - 1 and length > 2:
                opposite[(b, c, m)] = opposite.get((b, c, m), 0) + w
                singles = [(length, -w)]
            else:
                singles = [(j, w) for j in range(length)]
            for j, weight in singles:
                key = (abs(c - b - 2 * j), min(b + j, c - j), 1)
                same[key] = same.get(key, 0) + weight
    moments: dict[int, list] = {}  # 2 x [xi][p], flattened
    points: dict[int, list] = {}  # 2 x [xi]
    for (lo, length), weights in cross.items():
        if 2 * length > m:  # the m-point moment at lo - e (within the window), less its points outside u + e
            e = max(0, lo + m - 1 - 3 * m - 1)  # c(u) = c(v - e), v = u + e
            shifted = [[c0 - c1 * e + c2 * e * e, c1 - 2 * c2 * e, c2] for c0, c1, c2 in weights]
            _add(moments, lo - e, [w for row in shifted for w in row])
            for v in list(range(e)) + list(range(e + length, m)):
                _add(points, lo - e + v, _at(shifted, v), -1)
        else:  # a few single points
            for u in range(length):
                _add(points, lo + u, _at(weights, u))
    lags = sorted({lag for lag, _, _ in same})
    same_rows = [(lags.index(lag), lo, length, w) for (lag, lo, length), w in sorted(same.items()) if w]
    opposite_rows = sorted((b, c, length, w) for (b, c, length), w in opposite.items() if w)
    opposite_rows.sort(key=lambda row: (row[1], row[2], row[0]))  # by partner series (c, length)
    moment_at = sorted(moments)
    point_at = sorted(q for q in points if any(points[q]))
    assert max(moment_at) + m <= 3 * m + 2  # a moment reads X(n + lo) .. X(n + lo + m - 1): in the window
    return MhtotTables(np.array(lags, dtype=np.int64), np.array(same_rows, dtype=np.int64).reshape(-1, 4),
                       np.array(opposite_rows, dtype=np.int64).reshape(-1, 4), np.array(moment_at, dtype=np.int64),
                       np.array([moments[lo] for lo in moment_at], dtype=np.float64).reshape(-1, 3, 3) / 2.0,
                       np.array(point_at, dtype=np.int64),
                       np.array([points[q] for q in point_at], dtype=np.float64).reshape(-1, 3) / 2.0,
                       np.array(square, dtype=np.float64) / 4.0)


@njit(cache=True, nogil=True)
def _trapezoids(same, n_lags, count, weights, stop):
    """weights[k, t] (t < ``stop``) = the sum over the ``same`` rows (k, lo, length, w) of w times
    the number of (n, u), n < count, u < length, with n + lo + u = t."""
    weights[:n_lags, :stop] = 0.0
    for r in range(same.shape[0]):
        k, lo, length, w = same[r, 0], same[r, 1], same[r, 2], float(same[r, 3])
        for at, sign in ((lo, 1.0), (lo + length, -1.0), (lo + count, -1.0), (lo + count + length, 1.0)):
            if at < stop:
                weights[k, at] += sign * w
    for k in range(n_lags):
        run = 0.0
        acc = 0.0
        for t in range(stop):
            run += weights[k, t]
            acc += run
            weights[k, t] = acc


@njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _same(x, weights, lags, nx):
    """1. sum_k sum_t weights[k, t] x[t] x[t + lags[k]]."""
    total = 0.0
    for k in range(lags.shape[0]):
        lag = lags[k]
        w = weights[k]
        acc = 0.0
        for t in range(nx - lag):
            acc += w[t] * x[t] * x[t + lag]
        total += acc
    return total


@njit(cache=True, nogil=True)
def _partner_sums(parity, c, length, count, partner):
    """partner[run] = sum_{j'=jlo}^{jhi} x[c + run - 2 j'] for run = 0 .. count + length - 2 (jlo =
    max(0, run - count + 1), jhi = min(length - 1, run)), from the running sums over each parity:
    the head (jlo = 0, jhi = run), body (0, length - 1) and tail (run - count + 1, length - 1)."""
    top = length - 1
    if count < top:  # a short last block
        for run in range(count + top):
            jlo = max(0, run - count + 1)
            jhi = min(top, run)
            partner[run] = parity[c + run - 2 * jlo + 2] - parity[c + run - 2 * jhi]
        return
    for run in range(top):
        partner[run] = parity[c + run + 2] - parity[c - run]
    for run in range(top, count):
        partner[run] = parity[c + run + 2] - parity[c + run - 2 * top]
    for run in range(count, count + top):
        partner[run] = parity[c + 2 * count - run] - parity[c + run - 2 * top]


@njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _opposite(x, parity, opposite, count, partner):
    """2. sum over the rows (b, c, length, w) of w sum_n sum_{j'<length} x[n + b + j'] x[n + c - j']
    = w sum_run x[b + run] partner[run] (run = n + j'; the rows come sorted by (c, length): each
    partner series is formed once)."""
    total = 0.0
    made_c = -1
    made_length = -1
    for r in range(opposite.shape[0]):
        b, c, length = opposite[r, 0], opposite[r, 1], opposite[r, 2]
        if c != made_c or length != made_length:
            _partner_sums(parity, c, length, count, partner)
            made_c = c
            made_length = length
        acc = 0.0
        for run in range(count + length - 1):
            acc += x[b + run] * partner[run]
        total += opposite[r, 3] * acc
    return total


@njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _windows(x, moments, moment_at, moment_weights, point_at, point_weights, square, count, m, scalars):
    """3. and 4.: sum_n 2 sum_j' U P + sum_j' P^2, from the window's scalars (X(n), mu_n, s_n,
    kept in ``scalars``), moments and points: one dot product per table column."""
    span = 3 * m + 1
    half = span // 2
    rest = span - half
    tail = span * (span - 1) / 2.0
    q00, q01, q02 = square[0, 0], 2.0 * square[0, 1], 2.0 * square[0, 2]
    q11, q12, q22 = square[1, 1], 2.0 * square[1, 2], square[2, 2]
    total = 0.0
    for n in range(count):
        x0 = x[n]
        xl = x[n + span]
        xh = x[n + half]
        s = ((xl - xh) / rest - (xh - x0) / half) / (span / 2.0)
        mu = ((xl - x0) - s * tail) / span
        scalars[0, n] = x0
        scalars[1, n] = mu
        scalars[2, n] = s
        total += x0 * (q00 * x0 + q01 * mu + q02 * s) + mu * (q11 * mu + q12 * s) + q22 * s * s
    f0 = scalars[0]
    f1 = scalars[1]
    f2 = scalars[2]
    cross = 0.0
    for r in range(moment_at.shape[0] + point_at.shape[0]):
        for p in range(3 if r < moment_at.shape[0] else 1):
            if r < moment_at.shape[0]:
                piece = moments[p, moment_at[r] : moment_at[r] + count]
                w0, w1, w2 = moment_weights[r, 0, p], moment_weights[r, 1, p], moment_weights[r, 2, p]
            else:
                q = r - moment_at.shape[0]
                piece = x[point_at[q] : point_at[q] + count]
                w0, w1, w2 = point_weights[q, 0], point_weights[q, 1], point_weights[q, 2]
            d0 = 0.0
            d1 = 0.0
            d2 = 0.0
            for n in range(count):
                v = piece[n]
                d0 += f0[n] * v
                d1 += f1[n] * v
                d2 += f2[n] * v
            cross += w0 * d0 + w1 * d1 + w2 * d2
    return total + 2.0 * cross


@njit(cache=True, nogil=True)
def _blocks(values, m, starts, counts, first, stop, lags, same, opposite, moment_at, moment_weights, point_at,
            point_weights, square, out):
    """out[b] = the sum of T(n) over the windows starts[b] .. starts[b] + counts[b] - 1, b = first .. stop - 1."""
    span = 3 * m + 1
    length = counts[first:stop].max() + span + 2
    x = np.zeros(length)
    weights = np.empty((lags.shape[0], length))
    parity = np.empty(length + 2)
    moments = np.empty((3, length))
    scalars = np.empty((3, length))
    partner = np.empty(length)
    reach = moment_at.max() + 1 if moment_at.shape[0] else 0
    made = -1
    for b in range(first, stop):
        count = counts[b]
        nx = count + span
        if count != made:
            _trapezoids(same, lags.shape[0], count, weights, nx)
            made = count
        prepare_block(values, starts[b], nx - 1, x, parity)
        sliding_moments(x, count + reach - 1, m, moments)
        out[b] = (_same(x, weights, lags, nx) + _opposite(x, parity, opposite, count, partner)
                  + _windows(x, moments, moment_at, moment_weights, point_at, point_weights, square, count, m,
                             scalars))


#: The compiled kernels a blocked level runs (a NumPy twin stands in while they are cold:
#: :mod:`avar.stability.total.small_mhtot`).
BLOCK_KERNELS = (_blocks,)


def level_sum(x: np.ndarray, m: int, clean: np.ndarray | None = None) -> float:
    """sum of T(n) over the windows n = 0 .. N - 4m of the phase ``x`` (N points), or over those
    where ``clean`` is set (their points must then be real): the direct loop's level sum, in
    blocks of at most :func:`~avar._kernels.total.blocks.block_size` windows summed in order. A
    run of clean windows n = a .. b - 1 is every window of ``x[a : b + 3m]``.

    >>> round(level_sum(np.array([0.0, 1.0, 0.0, 2.0, 0.0, 1.0, 3.0, 1.0]), 1), 9)  # 5 windows
    910.0
    """
    m = int(m)
    n_terms = x.shape[0] - 4 * m + 1
    return run_blocks(x, m, n_terms, clean, _blocks, level_tables(m)) if n_terms > 0 else 0.0
