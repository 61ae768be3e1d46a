"""NumPy twin of TheoBR's expanded sums (:mod:`avar._kernels.total.theobr`), for short records while the kernels are cold.

The same expansion as :func:`avar._kernels.total.theobr.theo1_every` and the same FFT
recursions as :mod:`avar._kernels.total.fft` (their leaves summed by vectorized NumPy
instead of numba, the running sums as a loop over m vectorized over the exponential
terms): Theo1's double sums at every m in O(N log^2 N + M R) with R ~ 120 terms. The
results agree with the kernels' to rounding (the order of a few sums differs), and carry
the same conditioning ratios, so :func:`avar.stability.total.theobr.theobr_factor` can
decide as the kernels do which sums need summing again (then it runs the kernels).
"""

from __future__ import annotations

import numpy as np
from scipy import fft

from avar._kernels.total.fft import leaf_blocks, padded
from avar._kernels.total.split import ExpandedSums
from avar._kernels.total.theobr import LagDiagonals, exp_sum

#: Most phase points the twin takes while the kernels are cold (2**15: about a second of work).
THEOBR_TWIN_LIMIT = 1 << 15


def hankel_lower(y: np.ndarray, kappa: np.ndarray, count: int) -> np.ndarray:
    """out[g] = sum_{i<g} y[i] kappa[g + i], g = 0 .. count - 1 (:func:`avar._kernels.total.fft.hankel_lower`).

    >>> hankel_lower(np.ones(4), np.arange(8.0), 4).tolist()
    [0.0, 1.0, 5.0, 12.0]
    """
    leaf, length = leaf_blocks(count)
    yy = padded(y, length)
    kk = padded(kappa, 3 * length)
    local = np.arange(leaf)
    starts = np.arange(0, length, leaf)
    index = 2 * starts[:, None, None] + local[None, :, None] + local[None, None, :]  # (block, g, i)
    lower = local[None, :] < local[:, None]  # i < g
    out = np.einsum("bgi,bi->bg", np.where(lower, kk[index], 0.0), yy.reshape(-1, leaf)).ravel()
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
    """out[m] = sum_{a<=b, a+b=m} f[a] g[b], m = 0 .. count - 1 (:func:`avar._kernels.total.fft.half_convolution`).

    >>> half_convolution(np.ones(3), np.ones(3), 5).tolist()
    [1.0, 1.0, 2.0, 1.0, 1.0]
    """
    leaf, length = leaf_blocks(count)
    ff = padded(f, length)
    gg = padded(g, length)
    local = np.arange(leaf)
    upper = local[None, :] >= local[:, None]  # b >= a
    products = np.where(upper, ff.reshape(-1, leaf)[:, :, None] * gg.reshape(-1, leaf)[:, None, :], 0.0)
    index = 2 * np.arange(0, length, leaf)[:, None, None] + local[None, :, None] + local[None, None, :]
    out = np.bincount(index.ravel(), weights=products.ravel(), minlength=3 * length)
    size = 2 * leaf
    while size <= length:
        half = size // 2
        nodes = length // size
        low = ff.reshape(nodes, size)[:, :half]
        high = gg.reshape(nodes, size)[:, half:]
        product = fft.irfft(fft.rfft(low, size, axis=1) * fft.rfft(high, size, axis=1), size, axis=1)
        out[half : half + 2 * size * nodes].reshape(nodes, 2 * size)[:, :size] += product
        size *= 2
    return out[:count]


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


def running_sums(x: np.ndarray, reverse: np.ndarray, autocorr: np.ndarray, rest: np.ndarray, diag: np.ndarray,
                 diag_reverse: np.ndarray, count: int, t: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The kernel ``_running_sums`` of :mod:`avar._kernels.total.theobr` (same recurrences, vectorized over the terms r)."""
    decay = np.exp(-t)
    decay2 = decay * decay
    n_terms = t.shape[0]
    half = np.zeros((4, n_terms))
    long = np.zeros((2, n_terms))
    cumulative = np.zeros((2, n_terms))
    parity = np.zeros((2, 2, n_terms))
    corner = np.zeros((2, n_terms))
    next_p = np.ones(n_terms)
    at_h = np.ones(n_terms)
    at_half = np.ones(n_terms)
    out = np.zeros((5, count))
    pairs = 0.0
    ends = np.stack((x[:count], reverse[:count]))
    diagonals = np.stack((diag, diag_reverse))
    inputs_all = np.stack((autocorr[:count], rest[:count], x[:count], reverse[:count]))
    for m in range(count):
        sums = half @ w
        out[0, m] = sums[0]
        out[1, m] = sums[1]
        out[2, m] = pairs
        out[3, m] = (long[0] + long[1]) @ w
        pairs += ends[0, m] * sums[2]
        pairs += ends[1, m] * sums[3]
        h = m // 2
        if m % 2 == 0:
            out[4, m] = (corner[0] + corner[1]) @ w
            zh = ends[:, h, None]
            p = h % 2
            parity[:, p] += zh * at_h
            corner = decay2 * (corner + 2.0 * zh * at_h * parity[:, p])
            at_h = at_h * decay
            half = decay * (half + inputs_all[:, m, None] - inputs_all[:, h, None] * at_half)
            dh = diagonals[:, h, None] if m > 0 else np.zeros((2, 1))
            long = decay * (long - at_half * dh + ends[:, m, None] * cumulative)
        else:
            cumulative += ends[:, h, None] * next_p
            next_p = next_p * decay
            half = decay * (half + inputs_all[:, m, None])
            long = decay * (long + ends[:, m, None] * cumulative)
            at_half = at_half * decay
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
