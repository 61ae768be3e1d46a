"""The total family's short records in NumPy: nothing to compile, as exact as the kernels.

A first call of MTOTDEV, TTOTDEV, HTOTDEV or Theo1 would wait 1 to 3 s for numba to compile the
blocked expansion (:mod:`avar._kernels.total.blocks`), the direct loops
(:mod:`avar._kernels.total.windows`), Theo1's expansion (:mod:`avar._kernels.total.theo1`) and
the compensated phase (:func:`avar._kernels.classic.phase.detrended_phase`). While those kernels
are cold and the record is short (:func:`avar._kernels.runtime.paths.numpy_path`, called by
:mod:`avar.stability.total.deviations`), the twins here answer:

* :func:`twin_phase`: the phase the kernels read, ``hi`` of the compensated running sum. Within
  each block of :data:`avar._kernels.classic.sums.CUMSUM_BLOCK` increments the kernel's ``hi``
  is the plain sequential float64 sum of the increments' high parts, started from the
  sequential sum of the earlier blocks' totals, which :func:`numpy.cumsum` reproduces bit for
  bit from the same exact pairs (:func:`avar.stability.classic.small.detrended_phase`).
* :func:`level_sums`: MTOTDEV's and HTOTDEV's levels by the blocked expansion, the same blocks,
  tables and local detrending as the kernel (see :mod:`avar._kernels.total.blocks` for the
  formulas), vectorized over the blocks of one window count. Only the sliding moments are
  formed differently: f_p(n) = sum_{u<m} u^p x[n + u] from running sums of (t - c)^p x[t] (c
  the block's centre, |t - c| <= 3m) instead of the kernel's recurrences. Each level's rounding
  is estimated as eps times the sum of the magnitudes of its products, times a safety factor
  for the sums' lengths (:data:`SAFETY`); :func:`level_sums` returns ``None`` when that
  exceeds :data:`TOL` of a level's sum, and the kernels run. On noise of every power law
  (white PM to random-walk FM, also on a large offset) the estimates stay below ~1e-10 (they
  are ~1e3 times the errors seen) and the twin agrees with the kernels to ~1e-13, the
  kernels' own distance to the direct loop. Levels the kernels sum by the direct O(N m) loop
  (small ones) are summed here by the same expansion.
* :func:`theo1_level_sums`: Theo1's levels directly, one dot product per lag, each term
  rounded as in the kernel's direct loop (O(N m / 2) per level; ~1e-15 from the kernels).

Gaps: the blocks are laid over the runs of windows that avoid them, and Theo1 skips the outer
terms that touch one, as the kernels do. The tests force each path on the same data
(``AVAR_KERNEL_PATH``) and compare them at 1e-12.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from avar._kernels.classic.sums import CUMSUM_BLOCK
from avar._kernels.runtime.paths import numpy_path
from avar._kernels.total.blocks import BLOCK_KERNELS, block_size, blocks, level_tables
from avar._kernels.total.windows import DIRECT_KERNELS, FAST_WORK, THEO1_DIRECT_KERNELS, theo1_sum
from avar.stability.classic.small import detrended_phase

#: Unit roundoff of float64.
EPS = 2.0**-53
#: Largest relative rounding estimate a level may have (else the kernels run). The estimate is
#: about 1e3 times the errors measured (random-walk FM at N = 1e4: estimates up to 7e-11, errors
#: against the kernels up to 1.3e-13).
TOL = 1e-10
#: Work units (:data:`avar._kernels.runtime.paths.HOT_WORK`) charged per value and level: a whole
#: call on the twins spends 0.4 to 0.8 us per value and level (CPU, loaded machine: 0.08 s at N =
#: 1e4, 12 octave levels; 0.66 s at N = 1e5, 16 levels; the warm kernels 8 and 60 ms), 16 units
#: of ~25 ns (the per-value cost falls as N grows: NumPy's per-operation overhead is amortized).
TWIN_WORK = 16
#: Largest record whose phase :func:`twin_phase` forms while the phase kernels are cold (a few
#: NumPy passes: ~10 ms per 1e6 values; the kernels' compilation ~0.5 s).
PHASE_LIMIT = 1 << 21
#: Largest work a call sends to the twin (N ~ 1.3e5 at octave taus: under a second, against 2.5
#: to 5 s of compilation at N = 1e5).
TWIN_LIMIT = 1 << 25
#: A bound's safety factor over eps * (sum of magnitudes): the sums' lengths enter as their
#: logarithm (NumPy's pairwise sums) or as a few units (dot products of block rows).
SAFETY = 64.0


class TwinLevelSums(NamedTuple):
    """Every level's double sum and the number of windows in it (as :class:`avar._kernels.total.windows.LevelSums`)."""

    sums: np.ndarray
    n_terms: np.ndarray


def twin_phase(data: np.ndarray, kind: int, centre: float, slope: float, scale: float,
               block: int = CUMSUM_BLOCK) -> np.ndarray:
    """The compiled ``hi`` of :func:`avar._kernels.classic.phase.detrended_phase`, bit for bit:
    0, then the running sum of the high parts of the increments less ``centre + slope i``, times
    ``scale``. ``kind`` 0: ``data`` is the frequency, 1: the phase. The kernel sums ``block``
    increments at a time: block b's ``hi`` is the sequential float64 sum of its high parts
    started from the sequential sum of the earlier blocks' totals (each block's own sum from 0),
    which :func:`numpy.cumsum` reproduces: :func:`avar.stability.classic.small.detrended_phase`
    without its ``lo``, which the total family does not read.

    >>> twin_phase(np.array([1.0, 3.0, 2.0]), 0, 2.0, 0.0, 1.0).tolist()
    [0.0, -1.0, 0.0, 0.0]
    """
    return detrended_phase(data, None, kind, centre, slope, scale, block, low=False).hi


def _trapezoids(same: np.ndarray, m: int, count: int, nx: int) -> np.ndarray:
    """The kernel's integer weights[lag, t], t < ``nx``: four spikes per ``same`` row, summed twice."""
    spikes = np.zeros((3, nx))
    for lag, lo, weight in same.tolist():
        for at, sign in ((lo, 1.0), (lo + m, -1.0), (lo + count, -1.0), (lo + count + m, 1.0)):
            if at < nx:
                spikes[lag, at] += sign * weight
    return np.cumsum(np.cumsum(spikes, axis=1), axis=1)


def _windowed(running: np.ndarray, m: int, stop: int) -> np.ndarray:
    """sum_{u<m} v[n + u], n < ``stop``, from the running sums (leading 0) of each row's v."""
    return running[:, m : m + stop] - running[:, :stop]


def _running(values: np.ndarray) -> np.ndarray:
    out = np.zeros((values.shape[0], values.shape[1] + 1))
    np.cumsum(values, axis=1, out=out[:, 1:])
    return out


def _block_sums(values: np.ndarray, m: int, starts: np.ndarray, count: int, tables: tuple) -> tuple[np.ndarray, np.ndarray]:
    """Each block's sum of Q(n) / (6 m^3) (blocks of ``count`` windows from ``starts``) and a
    bound on its rounding error."""
    same, pairs, cross, points, square = tables
    span = 3 * m
    nx = count + span
    npts = nx - 1
    t = np.arange(npts, dtype=np.float64)
    centred = t - 0.5 * (npts - 1)
    rows = values[starts[:, None] + np.arange(npts)]
    level = rows.sum(axis=1) / npts
    tilt = (rows @ centred) / (npts * (npts * npts - 1.0) / 12.0)
    x = _running((rows - level[:, None]) - tilt[:, None] * centred)  # (blocks, nx)
    size = np.abs(x).max(axis=1)
    # 1. same-direction pairs
    weights = _trapezoids(same, m, count, nx)
    total = np.zeros(starts.shape[0])
    magnitude = np.zeros(starts.shape[0])
    for lag in range(3):
        width = nx - lag * m
        products = x[:, :width] * x[:, lag * m : lag * m + width]
        total += products @ weights[lag, :width]
        magnitude += np.abs(products) @ np.abs(weights[lag, :width])
    # 2. opposite-direction pairs, from the running sums over each parity
    parity = np.zeros((starts.shape[0], nx + 2))
    parity[:, 2::2] = np.cumsum(x[:, 0::2], axis=1)[:, : parity[:, 2::2].shape[1]]
    parity[:, 3::2] = np.cumsum(x[:, 1::2], axis=1)[:, : parity[:, 3::2].shape[1]]
    run = np.arange(count + m - 1)
    jlo = np.maximum(0, run - count + 1)
    jhi = np.minimum(m - 1, run)
    hi = run - 2 * jlo + 2
    lo = run - 2 * jhi
    sums = [parity[:, k * m + hi] - parity[:, k * m + lo] for k in (1, 2, 3)]
    for b in range(3):
        partner = pairs[b, 0] * sums[0] + pairs[b, 1] * sums[1] + pairs[b, 2] * sums[2]
        products = x[:, b * m + run] * partner
        total += products.sum(axis=1)
        magnitude += np.abs(products).sum(axis=1)
    magnitude += np.abs(parity).max(axis=1) * size * np.abs(pairs).sum() * (count + m)
    # 3. and 4.: the windows, from the pieces' moments (running sums of (t - c)^p x[t])
    stop = count + 2 * m
    tx = np.arange(nx, dtype=np.float64) - 0.5 * (nx - 1)
    w0 = _windowed(_running(x), m, stop)
    g1 = _windowed(_running(x * tx), m, stop)
    g2 = _windowed(_running(x * (tx * tx)), m, stop)
    first = tx[:stop]  # t - c at u = 0: sum u^p x = sum (tau - first)^p x, tau = t - c
    moments = (w0, g1 - first * w0, g2 - 2.0 * first * g1 + first * first * w0)
    reach = 0.5 * nx + m
    moment_error = EPS * 8.0 * nx * reach * reach * size  # of the running sums of tau^2 x, and their use
    half = span // 2
    gap = span - half
    x0, x1, x2, x3 = tuple(x[:, k * m : k * m + count] for k in range(3)) + (x[:, span : span + count],)
    s = ((x3 - x[:, gap : gap + count]) - (x[:, half : half + count] - x0)) / half / gap
    mu = ((x3 - x0) - s * (span * (span - 1) / 2.0)) / span
    f0 = [moments[0][:, i * m : i * m + count] for i in range(3)]
    k0 = points[0, 0] * x0 + points[0, 1] * x1 + points[0, 2] * x2 + points[0, 3] * x3
    k1 = points[1, 0] * x0 + points[1, 1] * x1 + points[1, 2] * x2 + points[1, 3] * x3
    k2 = points[2, 0] * x0 + points[2, 1] * x1 + points[2, 2] * x2 + points[2, 3] * x3
    for i in range(3):
        k0 = k0 + cross[0, i, 0] * f0[i]
        k1 = k1 + cross[1, i, 0] * f0[i]
        for p in range(3):
            k2 = k2 + cross[2, i, p] * moments[p][:, i * m : i * m + count]
    terms = (2.0 * (x0 * k0 + mu * k1 + s * k2) + x0 * (square[0, 0] * x0 + 2.0 * square[0, 1] * mu
                                                         + 2.0 * square[0, 2] * s)
             + mu * (square[1, 1] * mu + 2.0 * square[1, 2] * s) + square[2, 2] * s * s)
    total += terms.sum(axis=1)
    magnitude += np.abs(terms).sum(axis=1) + 2.0 * count * (
        np.abs(s).max(axis=1) * np.abs(cross[2]).sum() * moment_error
        + (size + np.abs(mu).max(axis=1)) * np.abs(cross[:2]).sum() * EPS * nx * size)
    scale = 6.0 * m * m * m
    return total / scale, SAFETY * EPS * magnitude / scale


class TwinLevelSum(NamedTuple):
    """One level's sum by a twin and a bound on its rounding error (:func:`blocked_level_sum`)."""

    total: float
    bound: float


def blocked_level_sum(values: np.ndarray, m: int, n_terms: int, clean: np.ndarray | None,
                      block_sums: Callable, tables: object) -> TwinLevelSum:
    """A blocked expansion's level sum in NumPy (this module's and :mod:`avar.stability.total.small_mhtot`'):
    the kernels' blocks over the ``n_terms`` windows (those where ``clean`` is set), the blocks of
    each window count at once by ``block_sums(values, m, starts, count, tables)`` (their sums and
    rounding bounds), added up."""
    if n_terms <= 0:
        return TwinLevelSum(0.0, 0.0)
    starts, counts = blocks(n_terms, block_size(m), clean)
    out = np.zeros(starts.size)
    bound = np.zeros(starts.size)
    for count in np.unique(counts).tolist():
        which = np.flatnonzero(counts == count)
        out[which], bound[which] = block_sums(values, m, starts[which], count, tables)
    return TwinLevelSum(float(np.sum(out)), float(np.sum(bound)))


def level_sum(values: np.ndarray, m: int, clean: np.ndarray | None = None) -> TwinLevelSum:
    """:func:`avar._kernels.total.blocks.level_sum` in NumPy, and a bound on its rounding error."""
    n_terms = values.shape[0] - 3 * m + 1
    return blocked_level_sum(values, m, n_terms, clean, _block_sums, level_tables(m) if n_terms > 0 else None)


def level_sums(kind: int, x: np.ndarray, factors: np.ndarray, bad: np.ndarray, shift: int) -> TwinLevelSums | None:
    """:func:`avar._kernels.total.windows.level_sums` of MTOTDEV (``kind`` 0, on the phase ``x``)
    or HTOTDEV (1, on its differences) in NumPy; ``None`` where a level's rounding bound exceeds
    :data:`TOL` of its sum (the kernels then run).

    >>> x = np.cumsum(np.random.default_rng(0).standard_normal(300))
    >>> twin = level_sums(0, x, np.array([1, 8]), np.zeros(0, dtype=np.int64), 0)
    >>> twin.n_terms.tolist()
    [298, 277]
    """
    values = np.ascontiguousarray(np.diff(x)) if kind == 1 else x
    sums = np.zeros(factors.shape[0])
    counts = np.zeros(factors.shape[0], dtype=np.int64)
    for level, m in enumerate(factors.tolist()):
        n_terms = max(0, values.shape[0] - 3 * m + 1)
        clean = None
        used = n_terms
        if bad.shape[0] and n_terms:  # the windows n whose points n .. n + 3m - 1 + kind avoid every gap
            stop = 3 * m + kind - shift
            clean = bad[stop : stop + n_terms] == bad[:n_terms]
            used = int(np.count_nonzero(clean))
        if used == 0:
            continue
        total, bound = level_sum(values, m, clean)
        if not bound <= TOL * abs(total):
            return None
        sums[level], counts[level] = total, used
    return TwinLevelSums(sums, counts)


def compiled_kernels(kind: int, n_values: int, factors: np.ndarray, gaps: bool) -> tuple:
    """The compiled kernels :func:`avar._kernels.total.windows.level_sums` would run on ``n_values``
    values (the blocked expansion for the levels above its ``FAST_WORK``, the direct loop for the
    rest; with gaps both may run)."""
    blocked = direct = False
    for m in factors.tolist():
        if max(0, n_values - 3 * m + 1) * (m + 10) > FAST_WORK:
            blocked = True
            direct = direct or gaps
        else:
            direct = True
    return (BLOCK_KERNELS if blocked else ()) + (DIRECT_KERNELS if direct else ())


def theo1_level_sums(x: np.ndarray, factors: np.ndarray, bad: np.ndarray, shift: int) -> TwinLevelSums:
    """Theo1's double sums (:func:`avar._kernels.total.windows.theo1_sum`) at the even ``factors``,
    directly in NumPy: sum_{a=1}^{m/2} (1 / a) sum_i ((x_i - x_{i+a}) + (x_{i+m} - x_{i+m-a}))^2 over
    the outer terms i = 0 .. N - m - 1 whose points i .. i + m avoid the gaps, each difference
    rounded as in the kernel's direct loop (the sums' order differs: ~1e-15). O(N m / 2) per
    level, one dot product per lag a.

    >>> x = np.array([0.0, 1.0, 0.0, 2.0, 0.0, 1.0])
    >>> theo1_level_sums(x, np.array([2, 4]), np.zeros(0, dtype=np.int64), 0).sums.tolist()
    [38.0, 15.0]
    """
    n_points = x.shape[0]
    sums = np.zeros(factors.shape[0])
    counts = np.zeros(factors.shape[0], dtype=np.int64)
    for level, m in enumerate(factors.tolist()):
        n_terms = n_points - m
        if n_terms <= 0:
            continue
        clean = None
        if bad.shape[0]:
            clean = (bad[m + 1 - shift : m + 1 - shift + n_terms] == bad[:n_terms]).astype(np.float64)
        head = x[:n_terms]
        tail = x[m : m + n_terms]
        total = 0.0
        for a in range(1, m // 2 + 1):
            d = (head - x[a : a + n_terms]) + (tail - x[m - a : m - a + n_terms])
            if clean is not None:
                d *= clean
            total += float(d @ d) / a
        sums[level] = total
        counts[level] = n_terms if clean is None else int(clean.sum())
    return TwinLevelSums(sums, counts)


#: The route of :func:`avar._kernels.runtime.paths.numpy_path` for Theo1's direct levels.
_THEO1_DIRECT_ROUTE = "total.theo1_direct"
#: Theo1's terms per work unit of :func:`avar._kernels.runtime.paths.numpy_path`: the twin
#: spends ~3.5 ns per term (0.13 s at N = 1e4, octave levels), a unit stands for ~25 ns.
THEO1_UNITS = 8
#: Largest charged work a call sends to Theo1's twin (~0.5 s: N ~ 2e4 at octave taus).
THEO1_LIMIT = 1 << 24


def theo1_direct(bad: np.ndarray, shift: int) -> Callable[[np.ndarray, int], float]:
    """Theo1's direct double sum of one level, ``direct(x, m)`` for
    :func:`avar._kernels.total.theo1.theo1_sums`: by :func:`theo1_level_sums` while the direct
    kernel is cold and the level small (:data:`THEO1_LIMIT`), else by
    :func:`avar._kernels.total.windows.theo1_sum`.

    >>> x = np.array([0.0, 1.0, 0.0, 2.0, 0.0, 1.0])
    >>> theo1_direct(np.zeros(0, dtype=np.int64), 0)(x, 2)
    38.0
    """

    def direct(x: np.ndarray, m: int) -> float:
        if numpy_path(lambda: theo1_work(x.shape[0], np.array([m])) // THEO1_UNITS, THEO1_LIMIT, THEO1_DIRECT_KERNELS,
                      route=_THEO1_DIRECT_ROUTE):
            return float(theo1_level_sums(x, np.array([m]), bad, shift).sums[0])
        return theo1_sum(x, m, bad, shift).total

    return direct


def theo1_work(n_points: int, factors: np.ndarray) -> int:
    """Theo1's terms over the levels, sum (N - m) m / 2: the twin's work."""
    m = factors.astype(np.int64)
    return int(np.sum(np.maximum(n_points - m, 0) * (m // 2)))


def oavar_sums(x: np.ndarray, factors: np.ndarray) -> np.ndarray:
    """:func:`avar._kernels.total.theobr.oavar_sums` in NumPy: sum_i (x_{i+2m} - 2 x_{i+m} + x_i)^2
    at every factor m, each term rounded as in the kernel.

    >>> oavar_sums(np.array([0.0, 1.0, 0.0, 2.0, 0.0]), np.array([1, 2])).tolist()
    [29.0, 0.0]
    """
    n_points = x.shape[0]
    out = np.zeros(factors.shape[0])
    for level, m in enumerate(factors.tolist()):
        if n_points > 2 * m:
            d = x[2 * m :] - 2.0 * x[m : n_points - m] + x[: n_points - 2 * m]
            out[level] = float(d @ d)
    return out
