"""MHTOTDEV's level sums in NumPy: nothing to compile, as exact as the kernels.

A first call of :func:`avar.mhtotdev` would wait for numba to compile the blocked expansion
(:mod:`avar._kernels.total.mhtot_blocks`) and the direct loop (:mod:`avar._kernels.total.mhtot`).
While those are cold and the record is small (:func:`avar._kernels.runtime.paths.numpy_path`,
called by :mod:`avar.stability.total.mhtot`), :func:`level_sums` answers instead: every level
by the blocked expansion (the same blocks and exact tables as the kernel, see
:mod:`avar._kernels.total.mhtot_blocks` for the formulas), vectorized over the blocks of one
window count. Each block removes its own line first, as the kernel's; the sliding moments are
formed from running sums of (t - c)^p x[t] (c the block's centre) instead of the kernel's
recurrences. Each level's rounding is estimated as eps times the sum of the magnitudes of its
products (bounded by Cauchy-Schwarz where the products are summed by matrix products), times a
safety factor (:data:`SAFETY`); :func:`level_sums` returns ``None`` when that exceeds
:data:`TOL` of a level's sum, and the kernels run. On white PM to random-walk FM the
estimates stay within 5e-12 to 5e-11 of the sums (~1e3 times the errors seen: the twin
agrees with the kernels to ~5e-14, their own distance to the direct loop); on data smoother
than random-walk FM phase the shortest levels may exceed :data:`TOL`, and the kernels run.
The tests force each path on the same data (white PM to random-walk FM, phase and frequency,
gaps) and compare them at 1e-12.
"""

from __future__ import annotations

import numpy as np

from avar._kernels.total.mhtot import clean_windows
from avar._kernels.total.mhtot_blocks import MhtotTables, level_tables
from avar._kernels.total.windows import LevelSums
from avar.stability.total.small import TwinLevelSum, blocked_level_sum

#: Unit roundoff of float64.
EPS = 2.0**-53
#: Largest relative rounding estimate a level may have (else the kernels run).
TOL = 1e-10
#: A bound's safety factor over eps * (sum of magnitudes).
SAFETY = 64.0
#: Work units (:data:`avar._kernels.runtime.paths.HOT_WORK`, ~25 ns each) charged per phase
#: point and level: the twin spends 0.3 to 0.45 us there (CPU, loaded machine: 0.04 s at N =
#: 1e4, 12 octave levels; 0.46 to 0.68 s at N = 1e5, 16 levels; the warm kernels 9 and 110 ms).
TWIN_WORK = 16
#: Largest work a call sends to the twin (N ~ 1.3e5 at octave taus: under a second, where the
#: kernels' compilation costs ~2 to 3 s of CPU).
TWIN_LIMIT = 1 << 25


def _running(values: np.ndarray) -> np.ndarray:
    """Running sums along the rows, with a leading 0."""
    out = np.zeros((values.shape[0], values.shape[1] + 1))
    np.cumsum(values, axis=1, out=out[:, 1:])
    return out


def _trapezoids(tables: MhtotTables, count: int, nx: int) -> np.ndarray:
    """The kernel's integer weights[k, t], t < ``nx``: four spikes per ``same`` row, summed twice."""
    spikes = np.zeros((tables.lags.size, nx + 2))  # the last spike, lo + count + length <= nx + 1, is cut
    k, lo, length, weight = tables.same.T
    for at, sign in ((lo, 1.0), (lo + length, -1.0), (lo + count, -1.0), (lo + count + length, 1.0)):
        np.add.at(spikes, (k, at), sign * weight)
    return np.cumsum(np.cumsum(spikes[:, :nx], axis=1), axis=1)


def _partners(parity: np.ndarray, c: int, length: int, count: int) -> np.ndarray:
    """sum_{j'=jlo}^{jhi} x[c + run - 2 j'] for run = 0 .. count + length - 2 (jlo = max(0, run -
    count + 1), jhi = min(length - 1, run)), from the running sums over each parity: slices for
    the head (jlo = 0, jhi = run), body (0, length - 1) and tail (run - count + 1, length - 1)."""
    top = length - 1
    if count < top:  # a short last block: gathers
        run = np.arange(count + top)
        jlo = np.maximum(0, run - count + 1)
        jhi = np.minimum(top, run)
        return parity[:, c + run - 2 * jlo + 2] - parity[:, c + run - 2 * jhi]
    out = np.empty((parity.shape[0], count + top))
    out[:, :top] = parity[:, c + 2 : c + top + 2] - parity[:, c - top + 1 : c + 1][:, ::-1]
    out[:, top:count] = parity[:, c + top + 2 : c + count + 2] - parity[:, c - top : c + count - 2 * top]
    out[:, count:] = (parity[:, c + count - top + 1 : c + count + 1][:, ::-1]
                      - parity[:, c + count - 2 * top : c + count - top])
    return out


def _opposite(x: np.ndarray, tables: MhtotTables, count: int) -> tuple[np.ndarray, np.ndarray]:
    """2. per block: sum over the ``opposite`` rows (b, c, length, w) of w sum_n sum_{j'<length}
    x[n + b + j'] x[n + c - j'], and a bound on the magnitude of its products (Cauchy-Schwarz:
    sum_r |x_b[r] p_c[r]| <= |x_b| |p_c|); per length, one batched matrix product of the rows
    x[n + b + j'] and the partner sums p_c."""
    nb, nx = x.shape
    parity = np.zeros((nb, nx + 2))
    parity[:, 2::2] = np.cumsum(x[:, 0::2], axis=1)[:, : parity[:, 2::2].shape[1]]
    parity[:, 3::2] = np.cumsum(x[:, 1::2], axis=1)[:, : parity[:, 3::2].shape[1]]
    total = np.zeros(nb)
    magnitude = np.zeros(nb)
    rows = tables.opposite
    for length in np.unique(rows[:, 2]).tolist():
        group = rows[rows[:, 2] == length]
        firsts, b_index = np.unique(group[:, 0], return_inverse=True)
        partners, c_index = np.unique(group[:, 1], return_inverse=True)
        weights = np.zeros((firsts.size, partners.size))
        np.add.at(weights, (b_index, c_index), group[:, 3].astype(np.float64))
        run = np.arange(count + length - 1)
        sums = np.stack([_partners(parity, c, length, count) for c in partners.tolist()], axis=1)  # (blocks, c, runs)
        reads = np.stack([x[:, b : b + run.size] for b in firsts.tolist()], axis=1)  # (blocks, firsts, runs)
        gram = np.einsum("kfr,kcr->kfc", reads, sums)  # (blocks, firsts, partners)
        total += (gram * weights).sum(axis=(1, 2))
        norms = np.sqrt(np.einsum("kfr,kfr->kf", reads, reads)) @ np.abs(weights)
        magnitude += (norms * np.sqrt(np.einsum("kcr,kcr->kc", sums, sums))).sum(axis=1)
        magnitude += np.abs(parity).max(axis=1) * np.abs(x).max(axis=1) * np.abs(weights).sum() * 4.0 * run.size
    return total, magnitude


def _windows(x: np.ndarray, tables: MhtotTables, count: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    """3. and 4. per block: sum_n (2 sum_j' U P + sum_j' P^2), and a bound on the magnitude of its
    products. sum_n f_xi(n) k_xi(n) (f = X(n), mu_n, s_n) is formed as the dot products of f with
    each moment and point column, batched over the blocks; their magnitudes are bounded by
    Cauchy-Schwarz."""
    nb, nx = x.shape
    span = 3 * m + 1
    size = np.abs(x).max(axis=1)
    stop = count + int(tables.moment_at.max())
    tx = np.arange(nx, dtype=np.float64) - 0.5 * (nx - 1)
    moments = np.empty((nb, 3, stop))
    w0 = _running(x)
    moments[:, 0] = w0[:, m : m + stop] - w0[:, :stop]
    g1 = _running(x * tx)
    g1 = g1[:, m : m + stop] - g1[:, :stop]
    g2 = _running(x * (tx * tx))
    first = tx[:stop]  # t - c at u = 0: sum u^p x = sum (tau - first)^p x, tau = t - c
    moments[:, 2] = (g2[:, m : m + stop] - g2[:, :stop]) - 2.0 * first * g1 + first * first * moments[:, 0]
    moments[:, 1] = g1 - first * moments[:, 0]
    reach = 0.5 * nx + m
    moment_error = EPS * 8.0 * nx * reach * reach * size
    half = span // 2
    x0, xh, xl = x[:, :count], x[:, half : half + count], x[:, span : span + count]
    s = ((xl - xh) / (span - half) - (xh - x0) / half) / (span / 2.0)
    mu = ((xl - x0) - s * (span * (span - 1) / 2.0)) / span
    scalars = np.stack([x0, mu, s], axis=1)  # (blocks, xi, n)
    scalar_norms = np.sqrt(np.einsum("kxn,kxn->kx", scalars, scalars))
    cross = np.zeros(nb)
    cross_size = np.zeros(nb)
    norms = np.sqrt(np.einsum("kpt,kpt->kp", moments, moments))  # (blocks, p): at least each piece's
    for r, lo in enumerate(tables.moment_at.tolist()):
        dots = np.einsum("kxn,kpn->kxp", scalars, moments[:, :, lo : lo + count])  # (blocks, xi, p)
        cross += (dots * tables.moment_weights[r]).sum(axis=(1, 2))
    cross_size += np.einsum("kx,kp,xp->k", scalar_norms, norms, np.abs(tables.moment_weights).sum(axis=0))
    if tables.point_at.size:
        points = np.lib.stride_tricks.sliding_window_view(x, count, axis=1)[:, tables.point_at]  # (blocks, q, n)
        dots = np.einsum("kxn,kqn->kxq", scalars, points)  # (blocks, xi, q)
        cross += (dots * tables.point_weights.T).sum(axis=(1, 2))
        cross_size += np.einsum("kx,k,x->k", scalar_norms, np.sqrt(np.einsum("kt,kt->k", x, x)),
                                np.abs(tables.point_weights).sum(axis=0))
    square = tables.square
    terms = (x0 * (square[0, 0] * x0 + 2.0 * square[0, 1] * mu + 2.0 * square[0, 2] * s)
             + mu * (square[1, 1] * mu + 2.0 * square[1, 2] * s) + square[2, 2] * s * s)
    # the errors of the moments (moment_error each) and of the points (eps nx size) times their factors
    factors = np.stack([np.abs(x0).max(axis=1), np.abs(mu).max(axis=1), np.abs(s).max(axis=1)], axis=1)
    k_error = (np.abs(tables.moment_weights).sum(axis=(0, 2))[None, :] * moment_error[:, None]
               + np.abs(tables.point_weights).sum(axis=0)[None, :] * (EPS * nx * size)[:, None])  # (blocks, xi)
    magnitude = np.abs(terms).sum(axis=1) + 2.0 * cross_size + 2.0 * count * (factors * k_error).sum(axis=1)
    return terms.sum(axis=1) + 2.0 * cross, magnitude


def _block_sums(values: np.ndarray, m: int, starts: np.ndarray, count: int,
                tables: MhtotTables) -> tuple[np.ndarray, np.ndarray]:
    """Each block's sum of T(n) (blocks of ``count`` windows from ``starts``) and a bound on its rounding."""
    nx = count + 3 * m + 1
    npts = nx - 1
    centred = np.arange(npts, dtype=np.float64) - 0.5 * (npts - 1)
    rows = values[starts[:, None] + np.arange(npts)]
    level = rows.sum(axis=1) / npts
    tilt = np.einsum("kt,t->k", rows, centred) / (npts * (npts * npts - 1.0) / 12.0)
    x = _running((rows - level[:, None]) - tilt[:, None] * centred)  # (blocks, nx)
    weights = _trapezoids(tables, count, nx)
    total = np.zeros(starts.shape[0])
    magnitude = np.zeros(starts.shape[0])
    squares = x * x
    for k, lag in enumerate(tables.lags.tolist()):  # 1. same-direction pairs; |x x'| <= (x^2 + x'^2) / 2
        width = nx - lag
        total += np.einsum("kt,kt,t->k", x[:, :width], x[:, lag : lag + width], weights[k, :width])
        size = np.abs(weights[k, :width])
        magnitude += 0.5 * np.einsum("kt,t->k", squares[:, :width] + squares[:, lag : lag + width], size)
    for part in (_opposite(x, tables, count), _windows(x, tables, count, m)):
        total += part[0]
        magnitude += part[1]
    return total, SAFETY * EPS * magnitude


def level_sum(x: np.ndarray, m: int, clean: np.ndarray | None = None) -> TwinLevelSum:
    """:func:`avar._kernels.total.mhtot_blocks.level_sum` in NumPy, and a bound on its rounding error."""
    n_terms = x.shape[0] - 4 * m + 1
    return blocked_level_sum(x, m, n_terms, clean, _block_sums, level_tables(m) if n_terms > 0 else None)


def level_sums(x: np.ndarray, factors: np.ndarray, bad: np.ndarray, shift: int) -> LevelSums | None:
    """:func:`avar._kernels.total.mhtot.level_sums` in NumPy; ``None`` where a level's rounding
    bound exceeds :data:`TOL` of its sum (the kernels then run).

    >>> x = np.cumsum(np.random.default_rng(0).standard_normal(300))
    >>> twin = level_sums(x, np.array([1, 8]), np.zeros(0, dtype=np.int64), 0)
    >>> twin.n_terms.tolist()
    [297, 269]
    """
    sums = np.zeros(factors.shape[0])
    counts = np.zeros(factors.shape[0], dtype=np.int64)
    for level, m in enumerate(factors.tolist()):
        clean = clean_windows(x.shape[0], m, bad, shift)
        used = max(0, x.shape[0] - 4 * m + 1) if clean is None else int(np.count_nonzero(clean))
        if used == 0:
            continue
        total, bound = level_sum(x, m, clean)
        if not bound <= TOL * abs(total):
            return None
        sums[level], counts[level] = total, used
    return LevelSums(sums, counts)
