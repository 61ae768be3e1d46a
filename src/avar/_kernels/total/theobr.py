"""Theo1 and OAVAR at every factor at once, for ThêoH's bias removal (TheoBR).

:func:`theo1_every` gives Theo1's double sums (:func:`avar._kernels.total.windows.theo1_sum`)
at every even m <= M in O(N log N + M log^2 M + M R): the expansion of
:mod:`avar._kernels.total.theo1`, with every sum over a that depends on m
turned into a sequence over m:

* sum_{a<=h} F(m - a) / a (and the same of the square terms, and of x itself for
  the pairs of lag l <= h: sum_{q<m} x_q sum_{a<=q/2} x_{q-a} / a + sum_{a<=h} D(a) / a,
  D(a) = sum_{j<a} x_j x_{j+a}): half convolutions with 1 / a;
* sum_{c<=h} x_{m-c} Φ(c): a half convolution (FFT, :mod:`avar._kernels.total.fft`);
* the two families whose weight 1 / (m - l) moves with m: the pairs of lag
  l >= h (1 <= m - l <= h: each pair (p, q) enters at m = q + 1 and leaves after
  m = 2 (q - p), the leaving ones summing to D(m / 2)) and the pairs p <= q < h
  of even lag (h < m - l <= m; they enter and never leave).

The last two and the half convolutions with 1 / a use 1 / s = sum_r w_r exp(-t_r s)
(:func:`exp_sum`, relative error below 1e-15 for 1 <= s <= M): each term is then a
running sum that decays by exp(-t_r) per step, updated in O(1). No validation;
gap-free, detrended x.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numba import njit
from scipy import fft

from avar._kernels.runtime.tasks import run_concurrently
from avar._kernels.total.fft import HALF_KERNELS, half_convolution, hankel_lower, phi_sums
from avar._kernels.total.split import ExpandedSums

#: Step (in log t) of the exponential sum: its relative error is below 5e-16 at 0.25.
_STEP = 0.25


class ExpSum(NamedTuple):
    """Nodes ``t`` and weights ``w`` of an exponential sum (:func:`exp_sum`)."""

    t: np.ndarray
    w: np.ndarray


def exp_sum(largest: float) -> ExpSum:
    """(t, w) with 1 / s = sum_r w_r exp(-t_r s) to ~5e-16 relative for 1 <= s <= ``largest``.

    The trapezoidal rule on 1 / s = integral of exp(u - s e^u) du, nodes u = ln t from
    ln(1e-8 / largest) to ln 40, the nodes below (where exp(-s t) = 1 to 1e-16) summed
    into one term at t = 0."""
    low = np.log(1e-8 / max(float(largest), 1.0))
    u = np.arange(low, np.log(40.0) + _STEP, _STEP)
    t = np.exp(u)
    below = _STEP * np.exp(low - _STEP) / (1.0 - np.exp(-_STEP))
    return ExpSum(np.concatenate(([0.0], t)), np.concatenate(([below], _STEP * t)))


@njit(cache=True, nogil=True)
def _running_sums(x, reverse, autocorr, rest, diag, diag_reverse, count, t, w):
    """For m = 0 .. count - 1: sum_{a<=m/2} F(m-a)/a, the same of ``rest``, sum_{q<m} z_q
    sum_{a<=q/2} z_{q-a}/a, the lag >= h pairs / (m - l), and at even m the even-lag
    pairs p <= q < m/2 times 2 / (m - l); both ends z = x, reverse summed."""
    n_terms = t.shape[0]
    decay = np.exp(-t)
    decay2 = decay * decay
    # states per term: half convolutions of F, rest, x, reverse; lag >= h pairs of x, reverse;
    # their cumulative sums sum_{p<=k} z_p e^{-tp}; even-lag pairs of x, reverse
    half = np.zeros((4, n_terms))
    long = np.zeros((2, n_terms))
    cumulative = np.zeros((2, n_terms))
    parity = np.zeros((2, 2, n_terms))
    corner = np.zeros((2, n_terms))
    next_p = np.ones(n_terms)  # e^{-t p} for the next p into ``cumulative``
    at_h = np.ones(n_terms)  # e^{-t h}
    at_half = np.ones(n_terms)  # e^{-t m/2} at even m
    out = np.zeros((5, count))
    pairs = 0.0
    ends = (x, reverse)
    diagonals = (diag, diag_reverse)
    for m in range(count):
        lag_half = 0.0
        rest_half = 0.0
        long_sum = 0.0
        for r in range(n_terms):
            lag_half += w[r] * half[0, r]
            rest_half += w[r] * half[1, r]
            long_sum += w[r] * (long[0, r] + long[1, r])
        out[0, m] = lag_half
        out[1, m] = rest_half
        out[2, m] = pairs
        out[3, m] = long_sum
        for e in range(2):  # sum_{q<m+1} z_q V(q), V the half convolution of z with 1/a
            v = 0.0
            for r in range(n_terms):
                v += w[r] * half[2 + e, r]
            pairs += ends[e][m] * v
        even = m % 2 == 0
        h = m // 2
        if even:
            acc = 0.0
            for r in range(n_terms):
                acc += w[r] * (corner[0, r] + corner[1, r])
            out[4, m] = acc
            for e in range(2):  # the pairs (p, h), p <= h of h's parity, enter
                zh = ends[e][h]
                for r in range(n_terms):
                    parity[e, h % 2, r] += zh * at_h[r]
                    corner[e, r] = decay2[r] * (corner[e, r] + 2.0 * zh * at_h[r] * parity[e, h % 2, r])
            for r in range(n_terms):
                at_h[r] *= decay[r]
        else:  # p = (m - 1) / 2 joins the pairs that can enter
            for e in range(2):
                zp = ends[e][h]
                for r in range(n_terms):
                    cumulative[e, r] += zp * next_p[r]
            for r in range(n_terms):
                next_p[r] *= decay[r]
        inputs = (autocorr[m], rest[m], x[m], reverse[m])
        halves = (autocorr[h], rest[h], x[h], reverse[h])
        for k in range(4):
            for r in range(n_terms):
                leaving = halves[k] * at_half[r] if even else 0.0  # a = m / 2 leaves (m = 0: V(1) = 0)
                half[k, r] = decay[r] * (half[k, r] + inputs[k] - leaving)
        for e in range(2):
            zm = ends[e][m]
            dh = diagonals[e][h] if even and m > 0 else 0.0
            for r in range(n_terms):
                long[e, r] = decay[r] * (long[e, r] - at_half[r] * dh + zm * cumulative[e, r])
        if not even:
            for r in range(n_terms):
                at_half[r] *= decay[r]
    return out


class LagDiagonals(NamedTuple):
    """D(a) = sum_{j<a} x_j x_{j+a} of a record and of its reverse (:func:`lag_diagonals`)."""

    forward: np.ndarray
    reverse: np.ndarray


def lag_diagonals(x: np.ndarray, reverse: np.ndarray, count: int) -> LagDiagonals:
    """D(a) = sum_{j<a} x_j x_{j+a} of x and of its reverse, a = 0 .. count - 1 (FFT; the two at once)."""
    return LagDiagonals(*run_concurrently(lambda: hankel_lower(x, x, count),
                                          lambda: hankel_lower(reverse, reverse, count)))


def theo1_every(x: np.ndarray, largest: int, autocorr: np.ndarray, diagonals: LagDiagonals) -> ExpandedSums:
    """Theo1's double sums at m = 0 .. ``largest`` (meaningful at even m >= 2, ``largest`` <= N - 1)
    and each one's ratio of the expansion's largest terms to it (about its relative error over eps).

    ``autocorr``: :func:`avar._kernels.total.fft.autocorrelation` of x; ``diagonals``:
    :func:`lag_diagonals` with count > ``largest`` / 2."""
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
    def corner_of(z: np.ndarray) -> Callable[[], np.ndarray]:
        return lambda: half_convolution(phi_sums(z, h[-1] + 1), z, count)

    # the running sums and the two ends' corner products at the same time
    (hc_lags, hc_rest, pairs, long, corners), corner_x, corner_reverse = run_concurrently(
        lambda: _running_sums(x, reverse, lags, rest, diag, diag_reverse, count, t, w), corner_of(x), corner_of(reverse))
    upsampled = np.zeros(count)  # sum_{a<=h} F(m - 2a) / a: a convolution
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


#: The kernels :func:`theo1_every` compiles on a first call (the Hankel leaves have a NumPy twin of their own).
THEO1_EVERY_KERNELS = (_running_sums, *HALF_KERNELS)


@njit(cache=True, nogil=True)
def oavar_sums(x: np.ndarray, factors: np.ndarray) -> np.ndarray:
    """sum_{i=0}^{N-2m-1} (x_{i+2m} - 2 x_{i+m} + x_i)**2 at every factor m."""
    out = np.zeros(factors.shape[0])
    n = x.shape[0]
    for level in range(factors.shape[0]):
        m = factors[level]
        acc = 0.0
        for i in range(n - 2 * m):
            d = x[i + 2 * m] - 2.0 * x[i + m] + x[i]
            acc += d * d
        out[level] = acc
    return out


def oavar_expanded(x: np.ndarray, factors: np.ndarray, autocorr: np.ndarray,
                   diagonals: LagDiagonals) -> ExpandedSums:
    """:func:`oavar_sums` in O(1) per level and each sum's conditioning (its square terms
    over it): the sum of x_i^2 + 4 x_{i+m}^2 + x_{i+2m}^2, less 4 (2 F[m] - D(m) - D~(m)),
    plus 2 F[2m], with D, D~ the :func:`lag_diagonals` (count > max factor)."""
    n_points = x.shape[0]
    squares = np.concatenate(([0.0], np.cumsum(x * x)))
    m = np.asarray(factors, dtype=np.int64)
    n = n_points - 2 * m
    square = squares[n] + 4.0 * (squares[n + m] - squares[m]) + (squares[n_points] - squares[2 * m])
    out = square - 4.0 * (2.0 * autocorr[m] - diagonals.forward[m] - diagonals.reverse[m]) + 2.0 * autocorr[2 * m]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(out != 0, (square + 8.0 * squares[-1]) / np.abs(out), np.inf)
    return ExpandedSums(out, ratio)
