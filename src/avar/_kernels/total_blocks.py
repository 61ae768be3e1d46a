"""MTOTDEV's and HTOTDEV's level sums in O(N) per level, exact up to rounding (numba).

The direct kernels of :mod:`avar._kernels.total` cost O(m) per window. Here a level's
windows are summed in blocks, and each block's sum is expanded into a few sliding sums.

The window n of ``values`` (3m = L points v_n .. v_{n+L-1}) is detrended by the line
through the means of its halves and its mean: with X the prefix sum of the values,
its running sum is::

    S_n(i) = X(n + i) - X(n) - mu_n i - s_n i (i - 1) / 2,   i = 0 .. L,   S_n(L) = 0,

s_n = (last_n - first_n) / (h g) (h = floor(L / 2), g = L - h; first_n = X(n + h) - X(n),
last_n = X(n + L) - X(n + g)) and mu_n = (X(n + L) - X(n) - s_n L (L - 1) / 2) / L. The
running sum of the reflected extension (rev w, w, rev w) is E(i) = -S(L - i), S(i - L),
-S(3L - i) on its thirds, and the window's term is::

    Q(n) = sum_{j=0}^{6m-1} z_j^2,   z_j = E(j + 3m) - 3 E(j + 2m) + 3 E(j + m) - E(j).

On each sixth j = s m + j' (j' = 0 .. m - 1) every E(j + k m) sits in one third, so
z_j = sum_k gamma_k S(iota_k) with iota_k = b_k + d_k j' (d = +1 in the middle third,
-1 in the reflected ones) and gamma_k = +-(-1, 3, -3, 1)_k. Hence z_j = U_j + P_j with

    U_j = sum_k gamma_k X(n + b_k + d_k j'),
    P_j = X(n) pi_X + mu_n pi_mu(j') + s_n pi_s(j')     (pi_*: integer quadratics in j')

and Q(n) = sum U^2 + 2 sum U P + sum P^2, summed over the windows of a block:

1. pairs of X read in the same direction, sum_n sum_j' X(t) X(t + delta) with delta in
   {0, m, 2m}: one pass over the block with integer trapezoid weights (a double running
   sum of four spikes per pair);
2. pairs read in opposite directions, sum_n sum_j' X(n + b + j') X(n + b' - j'): for each
   u the partners form a run of step 2, read from a running sum over each parity;
3. sum_j' U P: the polynomial-weighted sums sum_u u^p X(n + i m + u) (p <= 2) of the
   window's three pieces, from running sums of t^p X(t), times integer tables;
4. sum_j' P^2: a 3 x 3 table times (X(n), mu_n, s_n).

The statistic is unchanged by adding a + b t to a window's values, so each block (its B
windows, B + L - 1 values) first removes its own least-squares line and works in local
time: the sums then stay on the scale of the block's wander and not of the record's, and
the result agrees with the direct loop to ~1e-12 (white PM, flicker FM, random-walk FM).
The tables (exact integers, built in Python per level) come from :func:`level_tables`;
the tests check the expansion against the direct kernel and a plain loop.
"""

from __future__ import annotations

from fractions import Fraction
from functools import lru_cache

import numpy as np
from numba import njit

from avar._kernels.tasks import run_ranges

#: The weights of z_j = E(j + 3m) - 3 E(j + 2m) + 3 E(j + m) - E(j).
_WEIGHTS = (-1, 3, -3, 1)


def _terms(sixth: int, m: int) -> list[tuple[int, int, int]]:
    """(gamma, b, d) of the four E values of one sixth: E(sixth m + j' + k m) = +- S(b + d j')."""
    terms = []
    for k, weight in enumerate(_WEIGHTS):
        third = (sixth + k) // 3
        if third == 1:
            terms.append((weight, (sixth + k - 3) * m, 1))
        elif third == 0:
            terms.append((-weight, (3 - sixth - k) * m, -1))
        else:
            terms.append((-weight, (9 - sixth - k) * m, -1))
    return terms


def _power_sums(m: int) -> list[int]:
    """sum_{j=0}^{m-1} j^p, p = 0 .. 4, exactly."""
    return [sum(j**p for j in range(m)) if m < 64 else _faulhaber(m, p) for p in range(5)]


def _faulhaber(m: int, p: int) -> int:
    n = m - 1
    return [n + 1, n * (n + 1) // 2, n * (n + 1) * (2 * n + 1) // 6, (n * (n + 1) // 2) ** 2,
            n * (n + 1) * (2 * n + 1) * (3 * n * n + 3 * n - 1) // 30][p]


@lru_cache(maxsize=256)
def level_tables(m: int) -> tuple[np.ndarray, ...]:
    """The expansion of one level (see the module docstring), all integers:

    ``same`` rows (lag / m, first position, weight): sum_n sum_{u<m} X(n + lo + u) X(n + lo + u + lag);
    ``opposite`` rows (b, b', weight): sum_n sum_{j'<m} X(n + b + j') X(n + b' - j');
    ``forward[xi, i, p]`` and ``backward[xi, i, p]``: weights of sum_u u^p X(n + i m + u) over
    u = 0 .. m - 1 and u = 1 .. m in sum_j' U pi_xi (xi = X(n), mu, s);
    ``square[xi, xi']`` = sum_{sixths} sum_j' pi_xi pi_xi'.
    """
    same: dict[tuple[int, int], int] = {}
    opposite: dict[tuple[int, int], int] = {}
    forward = [[[Fraction(0)] * 3 for _ in range(3)] for _ in range(3)]
    backward = [[[Fraction(0)] * 3 for _ in range(3)] for _ in range(3)]
    square = [[Fraction(0)] * 3 for _ in range(3)]
    power = _power_sums(m)
    for sixth in range(6):
        terms = _terms(sixth, m)
        for ga, ba, da in terms:
            for gb, bb, db in terms:
                if da == db:
                    lo_a, lo_b = (ba, bb) if da == 1 else (ba - m + 1, bb - m + 1)
                    key = ((abs(lo_b - lo_a)) // m, min(lo_a, lo_b))
                    same[key] = same.get(key, 0) + ga * gb
                elif da == 1:
                    opposite[(ba, bb)] = opposite.get((ba, bb), 0) + ga * gb
                else:
                    opposite[(bb, ba)] = opposite.get((bb, ba), 0) + ga * gb
        # P_j = X(n) pi_X + mu pi_mu(j') + s pi_s(j'), coefficients of 1, j', j'^2
        pis = [[-sum(g for g, _, _ in terms), Fraction(0), Fraction(0)],
               [-sum(g * b for g, b, _ in terms), -sum(g * d for g, _, d in terms), Fraction(0)],
               [-sum(Fraction(g * (b * b - b), 2) for g, b, _ in terms),
                -sum(Fraction(g * (2 * b - 1) * d, 2) for g, b, d in terms),
                -sum(Fraction(g, 2) for g, _, _ in terms)]]
        pis = [[Fraction(c) for c in pi] for pi in pis]
        for g, b, d in terms:
            for xi, (q0, q1, q2) in enumerate(pis):
                if d == 1:  # positions b + u, u = j'
                    row = forward[xi][b // m]
                    coefs = (q0, q1, q2)
                else:  # positions b - j' = (b - m) + u, u = m - j' = 1 .. m
                    row = backward[xi][b // m - 1]
                    coefs = (q0 + q1 * m + q2 * m * m, -q1 - 2 * q2 * m, q2)
                for p in range(3):
                    row[p] += g * coefs[p]
        for a in range(3):
            for c in range(3):
                square[a][c] += sum(pis[a][p] * pis[c][q] * power[p + q] for p in range(3) for q in range(3))
    same_rows = np.array([(lag, lo, w) for (lag, lo), w in sorted(same.items()) if w], dtype=np.int64)
    opposite_rows = np.array([(b, c, w) for (b, c), w in sorted(opposite.items()) if w], dtype=np.int64)
    assert same_rows[:, 0].max() <= 2
    return (same_rows, opposite_rows, np.array(forward, dtype=np.float64), np.array(backward, dtype=np.float64),
            np.array(square, dtype=np.float64))


@njit(cache=True, nogil=True)
def _block(values, n0, count, m, same, opposite, forward, backward, square, x, weights, parity, moments):
    """sum of Q(n) over the windows n0 .. n0 + count - 1 (see the module docstring)."""
    span = 3 * m
    npts = count + span - 1
    # least-squares line of the block's values, in local time
    centre = 0.5 * (npts - 1)
    mean = 0.0
    for t in range(npts):
        mean += values[n0 + t]
    mean /= npts
    num = 0.0
    den = 0.0
    for t in range(npts):
        dt = t - centre
        num += dt * (values[n0 + t] - mean)
        den += dt * dt
    slope = num / den if den > 0.0 else 0.0
    nx = npts + 1
    x[0] = 0.0
    for t in range(npts):
        x[t + 1] = x[t] + ((values[n0 + t] - mean) - slope * (t - centre))
    for t in range(nx, nx + 2 * m + 1):
        x[t] = 0.0
    # 1. same direction: integer trapezoid weights per lag, one pass
    for lag in range(3):
        for t in range(nx + m + 2):
            weights[lag, t] = 0.0
    for r in range(same.shape[0]):
        lag, lo, w = same[r, 0], same[r, 1], float(same[r, 2])
        weights[lag, lo] += w
        weights[lag, lo + m] -= w
        weights[lag, lo + count] -= w
        weights[lag, lo + count + m] += w
    for lag in range(3):
        run = 0.0
        acc = 0.0
        for t in range(nx + m + 2):
            run += weights[lag, t]
            acc += run
            weights[lag, t] = acc
    total = 0.0
    for t in range(nx):
        total += x[t] * (weights[0, t] * x[t] + weights[1, t] * x[t + m] + weights[2, t] * x[t + 2 * m])
    # 2. opposite directions: running sums over each parity, parity[t + 2] = x[t] + parity[t]
    parity[0] = 0.0
    parity[1] = 0.0
    for t in range(nx):
        parity[t + 2] = x[t] + parity[t]
    for r in range(opposite.shape[0]):
        bf, br, w = opposite[r, 0], opposite[r, 1], float(opposite[r, 2])
        acc = 0.0
        for run in range(count + m - 1):  # run = n + j', u = bf + run, v = br + run - 2 j'
            jlo = max(0, run - count + 1)
            jhi = min(m - 1, run)
            acc += x[bf + run] * (parity[br + run - 2 * jlo + 2] - parity[br + run - 2 * jhi])
        total += w * acc
    # 3. and 4. per window: the pieces' moments and the scalars
    for t in range(nx):
        moments[0, t + 1] = moments[0, t] + x[t]
        moments[1, t + 1] = moments[1, t] + t * x[t]
        moments[2, t + 1] = moments[2, t] + (t * t) * x[t]
    half = span // 2
    gap = span - half
    tail = span * (span - 1) / 2.0
    mm = float(m) * m
    for n in range(count):
        x0 = x[n]
        s = ((x[n + span] - x[n + gap]) - (x[n + half] - x0)) / half / gap
        mu = ((x[n + span] - x0) - s * tail) / span
        c0 = 0.0
        c1 = 0.0
        c2 = 0.0
        for i in range(3):
            o = n + i * m
            d0 = moments[0, o + m] - moments[0, o]
            d1 = moments[1, o + m] - moments[1, o]
            d2 = moments[2, o + m] - moments[2, o]
            f0 = d0
            f1 = d1 - o * d0
            f2 = d2 - o * (2.0 * d1 - o * d0)
            end = x[o + m]
            b0 = f0 - x[o] + end
            b1 = f1 + m * end
            b2 = f2 + mm * end
            c0 += (forward[0, i, 0] * f0 + forward[0, i, 1] * f1 + forward[0, i, 2] * f2
                   + backward[0, i, 0] * b0 + backward[0, i, 1] * b1 + backward[0, i, 2] * b2)
            c1 += (forward[1, i, 0] * f0 + forward[1, i, 1] * f1 + forward[1, i, 2] * f2
                   + backward[1, i, 0] * b0 + backward[1, i, 1] * b1 + backward[1, i, 2] * b2)
            c2 += (forward[2, i, 0] * f0 + forward[2, i, 1] * f1 + forward[2, i, 2] * f2
                   + backward[2, i, 0] * b0 + backward[2, i, 1] * b1 + backward[2, i, 2] * b2)
        total += 2.0 * (x0 * c0 + mu * c1 + s * c2)
        total += (x0 * (square[0, 0] * x0 + 2.0 * (square[0, 1] * mu + square[0, 2] * s))
                  + mu * (square[1, 1] * mu + 2.0 * square[1, 2] * s) + square[2, 2] * s * s)
    return total


@njit(cache=True, nogil=True)
def _blocks(values, m, n_terms, size, first, stop, same, opposite, forward, backward, square, out):
    """out[b] = the sum of Q(n) / (6 m^3) over the windows of block b, for b = first .. stop - 1."""
    span = 3 * m
    length = size + span + 2 * m + 4
    x = np.empty(length)
    weights = np.empty((3, length))
    parity = np.empty(length + 2)
    moments = np.zeros((3, length))
    scale = 6.0 * m * m * m
    for b in range(first, stop):
        n0 = b * size
        count = min(size, n_terms - n0)
        out[b] = _block(values, n0, count, m, same, opposite, forward, backward, square, x, weights, parity,
                        moments) / scale


#: Windows per block, in units of m: each block reads (BLOCK + 3) m values.
BLOCK = 3


def block_size(m: int) -> int:
    return BLOCK * m


def level_sum(values: np.ndarray, m: int) -> float:
    """sum over the windows n = 0 .. M - 3m of Q(n) / (6 m^3) on gap-free ``values`` (M points):
    the direct kernel's level sum, in blocks of :func:`block_size` windows summed in order."""
    m = int(m)
    n_terms = values.shape[0] - 3 * m + 1
    if n_terms <= 0:
        return 0.0
    size = block_size(m)
    n_blocks = (n_terms + size - 1) // size
    out = np.zeros(n_blocks)
    tables = level_tables(m)
    run_ranges(n_blocks, lambda first, stop: _blocks(values, m, n_terms, size, first, stop, *tables, out))
    return float(np.sum(out))
