"""MTOTDEV's and HTOTDEV's level sums in O(N) per level, exact up to rounding (numba).

The direct kernels of :mod:`avar._kernels.total.windows` cost O(m) per window. Here a level's
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
3. sum_j' U P: the polynomial-weighted sums f_{i,p}(n) = sum_{u<m} u^p X(n + i m + u)
   (p <= 2) of the window's three pieces, slid from n to n + 1 by exact recurrences,
   times integer tables;
4. sum_j' P^2: a 3 x 3 table times (X(n), mu_n, s_n).

Each part costs O(B + L) per block of B windows, so a level costs O(N) (30-50 ns per
window on one core, against ~30 m ns for the direct loop).

Gaps: a run of windows n = a .. b - 1 that all avoid the gaps is every window of the
gap-free slice ``values[a : b + L - 1]``, so the blocks are laid over those runs
(:func:`blocks`) and never read a gap.

Conditioning: the statistic is unchanged by adding a + b t to a window's values (the
detrending removes it), so each block (its B windows, B + L - 1 values) first removes
its own line and works in its own time t = 0 .. B + L - 1: the sums then stay on the
scale of the block's wander, not of the record's. With B = 3m (at least 12) the result
agrees with the direct loop to ~1e-13 on white PM, flicker PM, flicker FM and random-walk
FM phase and frequency (measured up to N = 1e6); the loss grows about as (B / m)^3 on
random-walk FM (1e-10 at B = 12 m, 1e-6 at B = 256 and m = 1), so one expansion over the
whole record would be useless there; hence :data:`BLOCK`. The tables (exact integers, built in Python per level) come from
:func:`level_tables`; the tests check the expansion against the direct kernel and the
exact formula.
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np
from numba import njit

from avar._kernels.runtime.tasks import run_ranges, run_tasks, threads

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
    """sum_{j=0}^{m-1} j^p, p = 0 .. 4, exactly (Faulhaber)."""
    n = m - 1
    return [m, n * m // 2, n * m * (2 * n + 1) // 6, (n * m // 2) ** 2,
            n * m * (2 * n + 1) * (3 * n * n + 3 * n - 1) // 30]


class LevelTables(NamedTuple):
    """The exact tables of one level's expansion (:func:`level_tables`), in the order :func:`_blocks` takes them."""

    same: np.ndarray
    pairs: np.ndarray
    cross: np.ndarray
    points: np.ndarray
    square: np.ndarray


class Blocks(NamedTuple):
    """First windows and window counts of the blocks of one level (:func:`blocks`)."""

    starts: np.ndarray
    counts: np.ndarray


@lru_cache(maxsize=1024)
def level_tables(m: int) -> LevelTables:
    """The expansion of one level (see the module docstring), from exact integers:

    ``same`` rows (lag / m, first position, weight): sum_n sum_{u<m} X(n + lo + u) X(n + lo + u + lag);
    ``pairs[b / m, b' / m - 1]``: the weight of sum_n sum_{j'<m} X(n + b + j') X(n + b' - j');
    ``cross[xi, i, p]`` and ``points[xi, q]``: sum_j' U pi_xi (xi = X(n), mu, s) is
    sum_{i,p} cross[xi, i, p] sum_{u<m} u^p X(n + i m + u) + sum_q points[xi, q] X(n + q m);
    ``square[xi, xi']`` = sum_{sixths} sum_j' pi_xi pi_xi'.
    """
    same: dict[tuple[int, int], int] = {}
    pairs = np.zeros((3, 3))
    forward = np.zeros((3, 3, 3), dtype=object)  # 2 x the weights of u^p, u = 0 .. m - 1
    backward = np.zeros((3, 3, 3), dtype=object)  # 2 x the weights of u^p, u = 1 .. m
    square = np.zeros((3, 3), dtype=object)  # 4 x
    power = _power_sums(m)
    for sixth in range(6):
        terms = _terms(sixth, m)
        for ga, ba, da in terms:
            for gb, bb, db in terms:
                if da == db:
                    lo_a, lo_b = (ba, bb) if da == 1 else (ba - m + 1, bb - m + 1)
                    key = ((abs(lo_b - lo_a)) // m, min(lo_a, lo_b))
                    same[key] = same.get(key, 0) + ga * gb
                else:
                    b, c = (ba, bb) if da == 1 else (bb, ba)
                    pairs[b // m, c // m - 1] += ga * gb
        # 2 P_j = X(n) pi_X + mu pi_mu(j') + s pi_s(j'), coefficients of 1, j', j'^2 (doubled)
        pis = [(-2 * sum(g for g, _, _ in terms), 0, 0),
               (-2 * sum(g * b for g, b, _ in terms), -2 * sum(g * d for g, _, d in terms), 0),
               (-sum(g * (b * b - b) for g, b, _ in terms), -sum(g * (2 * b - 1) * d for g, b, d in terms),
                -sum(g for g, _, _ in terms))]
        for g, b, d in terms:
            for xi, (q0, q1, q2) in enumerate(pis):
                if d == 1:  # positions b + u, u = j'
                    forward[xi, b // m] += (g * q0, g * q1, g * q2)
                else:  # positions b - j' = (b - m) + u, u = m - j' = 1 .. m
                    backward[xi, b // m - 1] += (g * (q0 + q1 * m + q2 * m * m), -g * (q1 + 2 * q2 * m), g * q2)
        for a in range(3):
            for c in range(3):
                square[a, c] += sum(pis[a][p] * pis[c][q] * power[p + q] for p in range(3) for q in range(3))
    same_rows = np.array([(lag, lo, w) for (lag, lo), w in sorted(same.items()) if w], dtype=np.int64)
    assert same_rows[:, 0].max() <= 2
    # sum_{u=1}^{m} u^p X(o + u) = sum_{u=0}^{m-1} u^p X(o + u) + m^p X(o + m) - [p = 0] X(o)
    cross = (forward + backward).astype(np.float64) / 2.0
    points = np.zeros((3, 4))
    for xi in range(3):
        for i in range(3):
            q0, q1, q2 = backward[xi, i]
            points[xi, i] -= q0 / 2
            points[xi, i + 1] += (q0 + q1 * m + q2 * m * m) / 2
    assert not cross[:2, :, 1:].any()  # pi_X and pi_mu do not depend on j'
    return LevelTables(same_rows, pairs, cross, points, square.astype(np.float64) / 4.0)


@njit(cache=True, nogil=True)
def _trapezoids(same, m, count, weights, stop):
    """weights[lag, t] (t < ``stop``) = the sum over the ``same`` rows (lag, lo, w) of w times the
    number of (n, u), n < count, u < m, with n + lo + u = t: a double running sum of four spikes
    per row."""
    weights[:, :stop] = 0.0
    for r in range(same.shape[0]):
        lag, lo, w = same[r, 0], same[r, 1], float(same[r, 2])
        for at, sign in ((lo, 1.0), (lo + m, -1.0), (lo + count, -1.0), (lo + count + m, 1.0)):
            if at < stop:
                weights[lag, at] += sign * w
    for lag in range(3):
        run = 0.0
        acc = 0.0
        for t in range(stop):
            run += weights[lag, t]
            acc += run
            weights[lag, t] = acc


@njit(cache=True, nogil=True)
def prepare_block(values, n0, npts, x, parity):
    """The block's local running sum x (its values less a line; any line would do, this one is
    close to the least-squares line in local time t) and its running sums over each parity,
    parity[t + 2] = x[t] + parity[t]."""
    centre = 0.5 * (npts - 1)
    level = 0.0
    tilt = 0.0
    for t in range(npts):
        v = values[n0 + t]
        level += v
        tilt += (t - centre) * v
    level /= npts
    tilt /= npts * (npts * npts - 1.0) / 12.0
    parity[0] = 0.0
    parity[1] = 0.0
    acc = 0.0
    for t in range(npts + 1):
        x[t] = acc
        parity[t + 2] = acc + parity[t]
        if t < npts:
            acc += (values[n0 + t] - level) - tilt * (t - centre)


@njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _same(x, weights, nx, m):
    """1. sum_lag sum_t weights[lag, t] x[t] x[t + lag m] (the pairs lie in the block: t + lag m < nx)."""
    total = 0.0
    for lag in range(3):
        w = weights[lag]
        acc = 0.0
        for t in range(nx - lag * m):
            acc += w[t] * x[t] * x[t + lag * m]
        total += acc
    return total


@njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _opposite(x, parity, pairs, count, m):
    """2. sum_{b, b'} pairs[b, b'] sum_n sum_j' x[n + b m + j'] x[n + (b' + 1) m - j']: for
    run = n + j' the partners x[(b' + 1) m + run - 2 j'], j' = jlo .. jhi, are read from ``parity``."""
    o00, o01, o02 = pairs[0, 0], pairs[0, 1], pairs[0, 2]
    o10, o11, o12 = pairs[1, 0], pairs[1, 1], pairs[1, 2]
    o20, o21, o22 = pairs[2, 0], pairs[2, 1], pairs[2, 2]
    total = 0.0
    for run in range(count + m - 1):
        jlo = max(0, run - count + 1)
        jhi = min(m - 1, run)
        hi = run - 2 * jlo + 2
        lo = run - 2 * jhi
        s1 = parity[m + hi] - parity[m + lo]
        s2 = parity[2 * m + hi] - parity[2 * m + lo]
        s3 = parity[3 * m + hi] - parity[3 * m + lo]
        total += (x[run] * (o00 * s1 + o01 * s2 + o02 * s3) + x[m + run] * (o10 * s1 + o11 * s2 + o12 * s3)
                  + x[2 * m + run] * (o20 * s1 + o21 * s2 + o22 * s3))
    return total


@njit(cache=True, nogil=True)
def sliding_moments(x, stop, m, moments):
    """moments[p, n] = sum_{u<m} u^p x[n + u] for n < ``stop``, slid from n to n + 1 by exact
    recurrences (the new term x[n + m] in, the old x[n] out)."""
    f0 = 0.0
    f1 = 0.0
    f2 = 0.0
    for u in range(m):
        f0 += x[u]
        f1 += u * x[u]
        f2 += (u * u) * x[u]
    last = m - 1.0
    last2 = last * last
    for n in range(stop):
        moments[0, n] = f0
        moments[1, n] = f1
        moments[2, n] = f2
        old = x[n]
        new = x[n + m]
        f2 = f2 - 2.0 * f1 + f0 + last2 * new - old
        f1 = f1 - f0 + last * new + old
        f0 = f0 + new - old


@njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _windows(x, moments, cross, points, square, count, m):
    """3. and 4.: sum_n 2 sum_j' U P + sum_j' P^2, from the scalars and the pieces' moments
    f_{i,p}(n) = moments[p, n + i m]."""
    span = 3 * m
    half = span // 2
    gap = span - half
    tail = span * (span - 1) / 2.0
    a00, a01, a02 = cross[0, 0, 0], cross[0, 1, 0], cross[0, 2, 0]
    a10, a11, a12 = cross[1, 0, 0], cross[1, 1, 0], cross[1, 2, 0]
    b00, b01, b02 = cross[2, 0, 0], cross[2, 0, 1], cross[2, 0, 2]
    b10, b11, b12 = cross[2, 1, 0], cross[2, 1, 1], cross[2, 1, 2]
    b20, b21, b22 = cross[2, 2, 0], cross[2, 2, 1], cross[2, 2, 2]
    p00, p01, p02, p03 = points[0, 0], points[0, 1], points[0, 2], points[0, 3]
    p10, p11, p12, p13 = points[1, 0], points[1, 1], points[1, 2], points[1, 3]
    p20, p21, p22, p23 = points[2, 0], points[2, 1], points[2, 2], points[2, 3]
    q00, q01, q02 = square[0, 0], 2.0 * square[0, 1], 2.0 * square[0, 2]
    q11, q12, q22 = square[1, 1], 2.0 * square[1, 2], square[2, 2]
    m0 = moments[0]
    m1 = moments[1]
    m2 = moments[2]
    total = 0.0
    for n in range(count):
        x0 = x[n]
        x1 = x[n + m]
        x2 = x[n + 2 * m]
        x3 = x[n + span]
        s = ((x3 - x[n + gap]) - (x[n + half] - x0)) / half / gap
        mu = ((x3 - x0) - s * tail) / span
        f00, f10, f20 = m0[n], m0[n + m], m0[n + 2 * m]
        k0 = p00 * x0 + p01 * x1 + p02 * x2 + p03 * x3 + a00 * f00 + a01 * f10 + a02 * f20
        k1 = p10 * x0 + p11 * x1 + p12 * x2 + p13 * x3 + a10 * f00 + a11 * f10 + a12 * f20
        k2 = (p20 * x0 + p21 * x1 + p22 * x2 + p23 * x3
              + b00 * f00 + b01 * m1[n] + b02 * m2[n]
              + b10 * f10 + b11 * m1[n + m] + b12 * m2[n + m]
              + b20 * f20 + b21 * m1[n + 2 * m] + b22 * m2[n + 2 * m])
        total += (2.0 * (x0 * k0 + mu * k1 + s * k2)
                  + x0 * (q00 * x0 + q01 * mu + q02 * s) + mu * (q11 * mu + q12 * s) + q22 * s * s)
    return total


@njit(cache=True, nogil=True)
def _blocks(values, m, starts, counts, first, stop, same, opposite, cross, points, square, out):
    """out[b] = the sum of Q(n) / (6 m^3) over the windows starts[b] .. starts[b] + counts[b] - 1,
    for b = first .. stop - 1."""
    span = 3 * m
    length = counts[first:stop].max() + span + 2
    x = np.empty(length)
    weights = np.empty((3, length))
    parity = np.empty(length + 2)
    moments = np.empty((3, length))
    scale = 6.0 * m * m * m
    made = -1
    for b in range(first, stop):
        count = counts[b]
        nx = count + span
        if count != made:
            _trapezoids(same, m, count, weights, nx)
            made = count
        prepare_block(values, starts[b], nx - 1, x, parity)
        sliding_moments(x, count + 2 * m, m, moments)
        out[b] = (_same(x, weights, nx, m) + _opposite(x, parity, opposite, count, m)
                  + _windows(x, moments, cross, points, square, count, m)) / scale


#: The compiled kernels a blocked level runs (a NumPy twin stands in while they are cold:
#: :mod:`avar.stability.total.small`).
BLOCK_KERNELS = (_blocks,)


#: Windows per block, in units of m: each block reads (BLOCK + 3) m values. Larger blocks
#: spend less on each block's set-up but lose accuracy as (BLOCK / 3)^3 (module docstring).
BLOCK = 3
#: At least this many windows per block: at m = 1 and 2 a block of 3m windows costs more in
#: set-up than in sums (95 -> 40 ms at N = 1e6), and 12 windows still agree with the direct
#: loop to ~5e-14 there, even on the running sum of random-walk FM phase.
MIN_BLOCK = 12


#: Blocks of at least this many windows (m >= 2^14) are not cut into more ranges than threads:
#: fresh work arrays of ~50 MB cost more than the balance saves.
LARGE_BLOCK = 1 << 16


def block_size(m: int) -> int:
    """The windows of a block at factor m."""
    return max(BLOCK * m, MIN_BLOCK)


def blocks(n_terms: int, size: int, clean: np.ndarray | None = None) -> Blocks:
    """First windows and window counts of the blocks: runs of at most ``size`` windows covering
    the windows 0 .. n_terms - 1, or only those where ``clean`` (one flag per window) is set."""
    if clean is None:
        starts = np.arange(0, n_terms, size, dtype=np.int64)
        return Blocks(starts, np.minimum(size, n_terms - starts))
    edges = np.diff(np.concatenate(([0], clean.astype(np.int8), [0])))
    first, stop = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)  # runs of clean windows
    per_run = (stop - first + size - 1) // size
    run = np.repeat(np.arange(first.size), per_run)
    index = np.arange(run.size) - np.repeat(np.cumsum(per_run) - per_run, per_run)
    starts = (first[run] + index * size).astype(np.int64)
    return Blocks(starts, np.minimum(size, stop[run] - starts).astype(np.int64))


def level_sum(values: np.ndarray, m: int, clean: np.ndarray | None = None) -> float:
    """sum over the windows n = 0 .. M - 3m of Q(n) / (6 m^3) on ``values`` (M points), or over
    the windows where ``clean`` is set (a window's values must then be real wherever it is set):
    the direct kernel's level sum, in blocks of at most :func:`block_size` windows summed in order.
    A run of clean windows n = a .. b - 1 is every window of ``values[a : b + 3m - 1]``."""
    m = int(m)
    n_terms = values.shape[0] - 3 * m + 1
    return run_blocks(values, m, n_terms, clean, _blocks, level_tables(m)) if n_terms > 0 else 0.0


def run_blocks(values: np.ndarray, m: int, n_terms: int, clean: np.ndarray | None, kernel, tables: tuple) -> float:
    """A blocked level sum (this module's and :mod:`avar._kernels.total.mhtot_blocks`'): the
    ``n_terms`` windows (those where ``clean`` is set) in blocks of at most :func:`block_size`
    windows, ``kernel(values, m, starts, counts, first, stop, *tables, out)`` over ranges of
    blocks on the threads, the blocks' sums added in order (the bits do not depend on the threads)."""
    size = block_size(m)
    starts, counts = blocks(n_terms, size, clean)
    n_blocks = starts.size
    out = np.zeros(n_blocks)

    def work(first: int, stop: int) -> None:
        if stop > first:
            kernel(values, m, starts, counts, first, stop, *tables, out)

    if size < LARGE_BLOCK:
        run_ranges(n_blocks, work)
    else:  # one range per thread: each range allocates and first touches its block's arrays
        parts = min(n_blocks, threads())
        bounds = [n_blocks * p // parts for p in range(parts + 1)]
        run_tasks(parts, lambda p: work(bounds[p], bounds[p + 1]))
    return float(np.sum(out))
