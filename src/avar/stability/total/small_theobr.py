"""NumPy twin of TheoBR's expanded sums (:mod:`avar._kernels.total.theobr`), for short records while the kernels are cold.

The same expansion as :func:`avar._kernels.total.theobr.theo1_every` and the same FFT
recursions as :mod:`avar._kernels.total.fft` (with smaller leaves, summed by vectorized NumPy
instead of numba): Theo1's double sums at every m in O(N log^2 N + M R) with R ~ 135 terms.
The kernel's running sums over m (:func:`running_sums`) have no loop over m here: the half
convolutions with 1 / a are FFT recursions, and the two families weighted 1 / (m - l) keep the
exponential sum, each term's recurrence over m formed by cumulative sums
(:func:`decayed_sums`), a loop over the R terms instead of the M steps (N = 1e5: ~0.3 s of CPU
for all of kf, against ~1.4 s with a loop over m, 0.1 s for the warm kernels and ~2 s to compile
them). The results
agree with the kernels' to rounding (the order of the sums differs: ~1e-14 of each sum's
largest terms), and carry the same conditioning ratios, so
:func:`avar.stability.total.theobr.theobr_factor` can decide as the kernels do which sums need
summing again (then it runs the kernels).
"""

from __future__ import annotations

import numpy as np
from scipy import fft

from avar._kernels.total.fft import leaf_blocks, padded
from avar._kernels.total.split import ExpandedSums
from avar._kernels.total.theobr import LagDiagonals, exp_sum

#: Most phase points the twin takes while the kernels are cold (2**17: ~0.4 s of CPU, against
#: ~2 s to compile the kernels of :func:`avar._kernels.total.theobr.theo1_every`).
THEOBR_TWIN_LIMIT = 1 << 17
#: Work units (:data:`avar._kernels.runtime.paths.HOT_WORK`, ~25 ns each) charged per phase point:
#: what the twin loses to the warm kernels (measured at N = 1e5 on a loaded machine: wall 0.47 s
#: against 0.16 s, CPU 0.30 s against 0.10 s: ~0.3 s or 120 units per point): a process calling at
#: N = 1e5 takes the twin twice, then compiles.
THEOBR_UNITS = 128
#: Most terms of the direct sums (points per Allan level, (N - m) m / 2 per Theo1 level) the twin
#: adds for the levels its expansion leaves too ill-conditioned for kf (10 to 20 ns a term: at most
#: ~0.5 s, against 2 to 4 s to compile the kernels' split expansion; more: the kernels).
TWIN_DIRECT_TERMS = 1 << 25
#: Leaf sizes of the twin's FFT recursions (5-smooth: every FFT size is fast). Smaller than the
#: kernels' :data:`avar._kernels.total.fft.LEAVES`: NumPy sums the leaves one lag at a time (L
#: passes over the data), and the batched FFTs of the few extra levels cost less (measured at
#: 6.7e4 outputs: leaves of 8 to 15 twice as fast as 32 to 60, four times as 64 to 128).
TWIN_LEAVES = (8, 9, 10, 12, 15)
#: Largest exponent t m a decayed sum (:func:`decayed_sums`) scales its terms by (e^256 ~ 1e111:
#: within float64 for products of data up to ~1e90 in magnitude; theoh passes its phase scaled to
#: about 1 (by a power of two), and a sum that overflows all the same is not finite: summed again).
SPAN = 256.0


def hankel_lower(y: np.ndarray, kappa: np.ndarray, count: int) -> np.ndarray:
    """out[g] = sum_{i<g} y[i] kappa[g + i], g = 0 .. count - 1 (:func:`avar._kernels.total.fft.hankel_lower`).

    >>> hankel_lower(np.ones(4), np.arange(8.0), 4).tolist()
    [0.0, 1.0, 5.0, 12.0]
    """
    leaf, length = leaf_blocks(count, TWIN_LEAVES)
    yy = padded(y, length)
    kk = padded(kappa, 3 * length)
    out = np.zeros(length)
    y_leaves = yy.reshape(-1, leaf)
    out_leaves = out.reshape(-1, leaf)
    kappa_leaves = kk[: 2 * length].reshape(-1, 2 * leaf)  # kappa[2 s .. 2 s + 2 leaf - 1] of each leaf
    for lag in range(1, leaf):  # g = i + lag within each leaf: kappa[2 (s + i) + lag]
        out_leaves[:, lag:] += y_leaves[:, : leaf - lag] * kappa_leaves[:, lag : 2 * leaf - lag : 2]
    size = 2 * leaf
    while size <= length:
        half = size // 2
        nodes = length // size
        low = yy.reshape(nodes, size)[:, :half][:, ::-1]
        window = kk[half : half + 2 * size * nodes].reshape(nodes, 2 * size)[:, :size]
        product = fft.irfft(fft.rfft(low, size, axis=1) * fft.rfft(window, size, axis=1), size, axis=1)
        out.reshape(nodes, size)[:, half:] += product[:, half - 1 : size - 1]
        size *= 2
    return out[:count]


def half_convolution(f: np.ndarray, g: np.ndarray, count: int) -> np.ndarray:
    """out[..., m] = sum_{a<=b, a+b=m} f[a] g[..., b], m = 0 .. count - 1
    (:func:`avar._kernels.total.fft.half_convolution`; ``g`` may hold several rows, one ``f``).

    >>> half_convolution(np.ones(3), np.ones(3), 5).tolist()
    [1.0, 1.0, 2.0, 1.0, 1.0]
    """
    leaf, length = leaf_blocks(count, TWIN_LEAVES)
    ff = padded(f, length)
    gg = np.zeros(g.shape[:-1] + (length,))
    gg[..., : min(length, g.shape[-1])] = g[..., :length]
    out = np.zeros(g.shape[:-1] + (3 * length,))
    f_leaves = ff.reshape(-1, leaf)
    g_leaves = gg.reshape(g.shape[:-1] + (-1, leaf))
    pairs = out[..., : 2 * length].reshape(g.shape[:-1] + (-1, 2 * leaf))  # a leaf's outputs 2 s .. 2 s + 2 leaf - 1
    for lag in range(leaf):  # b = a + lag within each leaf
        pairs[..., lag : 2 * leaf - lag : 2] += f_leaves[:, : leaf - lag] * g_leaves[..., lag:]
    size = 2 * leaf
    while size <= length:
        half = size // 2
        nodes = length // size
        low = fft.rfft(ff.reshape(nodes, size)[:, :half], size, axis=-1)
        high = fft.rfft(gg.reshape(g.shape[:-1] + (nodes, size))[..., half:], size, axis=-1)
        product = fft.irfft(low * high, size, axis=-1)
        out[..., half : half + 2 * size * nodes].reshape(g.shape[:-1] + (nodes, 2 * size))[..., :size] += product
        size *= 2
    return out[..., :count]


def phi_sums(z: np.ndarray, count: int) -> np.ndarray:
    """Φ(c) = sum_{j<c, j = c mod 2} 2 z_j / (c + j), c = 0 .. count - 1 (:func:`avar._kernels.total.fft.phi_sums`)."""
    out = np.zeros(count)
    for parity in (0, 1):
        n = (count - parity + 1) // 2
        if n <= 0:
            continue
        t = np.arange(2 * n + 1, dtype=np.float64) + parity
        kappa = np.divide(1.0, t, out=np.zeros_like(t), where=t > 0)
        out[parity::2] = hankel_lower(z[parity::2], kappa, n)
    return out


def lag_diagonals(x: np.ndarray, count: int) -> LagDiagonals:
    """D(a) = sum_{j<a} x_j x_{j+a} of x and of its reverse, a = 0 .. count - 1."""
    reverse = np.ascontiguousarray(x[::-1])
    return LagDiagonals(hankel_lower(x, x, count), hankel_lower(reverse, reverse, count))


def decayed_sums(u: np.ndarray, t: float, powers: np.ndarray | None = None) -> np.ndarray:
    """y[..., m] = sum_{j<m} exp(-t (m - j)) u[..., j] along the last axis: the running sum that decays by
    exp(-t) per step, y[m + 1] = exp(-t) (y[m] + u[m]), y[0] = 0, with no loop over m. ``powers``:
    exp(-t k), k = 0, 1, ..., if at hand (as far as the block below).

    In blocks of B steps with t B <= :data:`SPAN` (the whole range when it fits): within a block,
    y[b + k] = exp(-t k) (y[b] + sum_{j<k} exp(t j) u[b + j]), one cumulative sum of the scaled
    terms; a block's start takes the earlier blocks' totals times exp(-t B) per block (at most
    a few: exp(-2 SPAN) is below any float64 ratio of two such sums). Each value errs by a few
    eps times the sum of its terms' magnitudes, as the sequential loop's.

    >>> decayed_sums(np.ones(4), np.log(2.0)).tolist()
    [0.0, 0.5, 0.75, 0.875]
    """
    n = u.shape[-1]
    block = n if t * n <= SPAN else max(1, int(SPAN / t))
    fall = np.exp(-t * np.arange(block)) if powers is None or powers.shape[0] < block else powers[:block]
    grow = 1.0 / fall  # exp(t k) <= exp(SPAN)
    if block == n:
        inner = u * grow
        np.cumsum(inner, axis=-1, out=inner)
        out = np.empty_like(inner)
        out[..., 0] = 0.0
        np.multiply(inner[..., :-1], fall[1:], out=out[..., 1:])
        return out
    n_blocks = -(-n // block)
    padded_u = np.zeros(u.shape[:-1] + (n_blocks * block,))
    padded_u[..., :n] = u
    scaled = padded_u.reshape(u.shape[:-1] + (n_blocks, block)) * grow
    inner = np.zeros_like(scaled)
    np.cumsum(scaled[..., :-1], axis=-1, out=inner[..., 1:])
    totals = inner[..., -1] + scaled[..., -1]
    carry = np.zeros(totals.shape)
    step = float(np.exp(-t * block))
    power, back = step, 1
    while power > 0.0 and back < n_blocks:
        carry[..., back:] += power * totals[..., :-back]
        power *= step
        back += 1
    inner += carry[..., None]
    return (inner * fall).reshape(padded_u.shape)[..., :n]


def running_sums(x: np.ndarray, reverse: np.ndarray, autocorr: np.ndarray, rest: np.ndarray, diag: np.ndarray,
                 diag_reverse: np.ndarray, count: int, t: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The kernel ``_running_sums`` of :mod:`avar._kernels.total.theobr` without its loop over m.

    Rows 0, 1 (sum_{a<=m/2} F(m-a) / a and the same of ``rest``) and the half convolutions of the
    ends with 1 / a behind row 2 (the pairs) are :func:`half_convolution` with the exact 1 / a;
    the kernel's exponential sum 1 / a = sum_r w_r exp(-t_r a) (``t``, ``w``) agrees to ~5e-16.
    Rows 3 (the lag >= m/2 pairs, sum_{l>=m/2} sum_{p+l<m} z_p z_{p+l} / (m - l)) and 4 (at even
    m, the even-lag pairs p <= q < m/2, 2 z_p z_q / (m - l)) keep the exponential sum: for each
    term r, the kernel's recurrences over m as cumulative sums and :func:`decayed_sums`."""
    out = np.zeros((5, count))
    inverse = np.zeros(count)
    inverse[1:] = 1.0 / np.arange(1, count)
    ends = np.stack((x[:count], reverse[:count]))
    halves = half_convolution(inverse, np.stack((autocorr[:count], rest[:count], ends[0], ends[1])), count)
    out[:2] = halves[:2]
    out[2, 1:] = np.cumsum(np.einsum("ij,ij->j", ends[:, : count - 1], halves[2:, : count - 1]))
    n_even = (count - 1) // 2 + 1  # the even m = 2h, h < n_even
    leaving = diag[:n_even] + diag_reverse[:n_even]  # D(h), the pairs of lag h, leave at m = 2h
    odd, even = ends[:, 1::2], ends[:, 2::2]
    steps = np.arange(count, dtype=np.float64)
    for r in range(t.shape[0]):
        powers = np.exp(-t[r] * steps[: count if t[r] * count <= SPAN else n_even])  # exp(-t k)
        at = powers[:n_even]
        weighted = ends[:, :n_even] * at  # z_p exp(-t p)
        parity = np.empty_like(weighted)  # sum_{p<=h, p = h mod 2} z_p exp(-t p)
        parity[:, 0::2] = np.cumsum(weighted[:, 0::2], axis=1)
        parity[:, 1::2] = np.cumsum(weighted[:, 1::2], axis=1)
        cumulative = parity.copy()  # sum_{p<=h}: the pairs (p, m) of lag > m/2 that entered by m
        cumulative[:, 1:] += parity[:, :-1]
        entering = np.empty(count)
        entering[0] = 0.0
        entering[1::2] = np.einsum("ij,ij->j", odd, cumulative[:, : odd.shape[1]])
        entering[2::2] = np.einsum("ij,ij->j", even, cumulative[:, : even.shape[1]]) - at[1:] * leaving[1:]
        out[3] += w[r] * decayed_sums(entering, t[r], powers)
        out[4, 0::2] += w[r] * decayed_sums(2.0 * np.einsum("ij,ij->j", weighted, parity), 2.0 * t[r], at * at)
    return out


def theo1_every(x: np.ndarray, largest: int, autocorr: np.ndarray, diagonals: LagDiagonals) -> ExpandedSums:
    """:func:`avar._kernels.total.theobr.theo1_every` in NumPy: Theo1's double sums at m = 0 .. ``largest``
    (meaningful at even m >= 2) and their conditioning ratios."""
    n_points = x.shape[0]
    count = largest + 1
    reverse = np.ascontiguousarray(x[::-1])
    squares = np.concatenate(([0.0], np.cumsum(x * x)))
    k = np.arange(count)
    h = k // 2
    inverse = np.zeros(count)
    inverse[1:] = 1.0 / k[1:]
    weight = np.cumsum(inverse)[h]
    rest = squares[n_points - k] - squares[k]
    lags = np.ascontiguousarray(autocorr[:count])
    t, w = exp_sum(max(largest, 2))
    diag, diag_reverse = (np.ascontiguousarray(d[: h[-1] + 1]) for d in diagonals)
    hc_lags, hc_rest, pairs, long, corners = running_sums(x, reverse, lags, rest, diag, diag_reverse, count, t, w)
    corner_x = half_convolution(phi_sums(x, h[-1] + 1), x, count)
    corner_reverse = half_convolution(phi_sums(reverse, h[-1] + 1), reverse, count)
    upsampled = np.zeros(count)
    upsampled[2::2] = inverse[1 : (count + 1) // 2]
    size = fft.next_fast_len(2 * count, real=True)
    double = fft.irfft(fft.rfft(upsampled, size) * fft.rfft(lags, size), size)[:count]
    square = weight * (squares[n_points - k] + squares[n_points] - squares[k]) + np.cumsum(inverse * rest)[h] + hc_rest
    cross = weight * lags + double - 2.0 * np.cumsum(inverse * lags)[h] - 2.0 * hc_lags
    pairs = pairs + np.cumsum(inverse[: h[-1] + 1] * (diag + diag_reverse))[h]
    corners = corners[2 * h] + corner_x + corner_reverse
    total = square + 2.0 * cross + 2.0 * (pairs + long) - 2.0 * corners
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(total > 0, np.maximum(square, weight * squares[-1]) / total, np.inf)
    return ExpandedSums(total, ratio)
