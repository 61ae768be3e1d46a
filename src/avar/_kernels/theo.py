"""Theo1 at every even factor at once (numba), for ThêoH's bias removal.

:func:`theo1_all` gives the raw Theo1 double sums of :func:`avar._kernels.total.theo1_sum`
at m = 2, 4, ..., 2K in O(N K) (B. Lewis, "A fast algorithm for calculation
of Theo1", 2020): expanding the square of each term turns the double sum at
m = 2k into running sums of squares (``squares``), lagged products at lags 2k
and 2k - 1 over the whole record, and two tables of lagged products over
ranges (``even`` at lags 2v, ``mixed`` at lags v) that shrink by a few
products at each k. No validation; the data must be gap-free (and detrended,
so that the products stay small).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def theo1_all(x: np.ndarray, k_max: int, autocorr: np.ndarray) -> np.ndarray:
    """Raw Theo1 double sums at m = 2k, k = 1 .. ``k_max`` (index k - 1); 2 k_max <= N - 1.

    ``autocorr``: the record's autocorrelation (lag products over the whole record), or
    an empty array to sum the lag products here; it turns the O(N) lag sums of each k into look-ups (O(k) per k); the
    expansion then errs by about eps * sum(x^2) * sum_{v<=k} 1/v, see :func:`theo1_ratio`."""
    n = x.shape[0]
    squares = np.empty(n)
    acc = 0.0
    for i in range(n):
        acc += x[i] * x[i]
        squares[i] = acc
    even = np.empty(k_max + 1)  # even[v]: sum of x_j x_{j+2v} over the range still in use
    mixed = np.empty(2 * k_max)  # mixed[v - 1]: lag-v products over the range still in use
    out = np.empty(k_max)
    even[0] = squares[n - 1]
    for k in range(1, k_max + 1):
        lag_even = 0.0
        lag_odd = 0.0
        if autocorr.shape[0] > 0:
            lag_even = autocorr[2 * k]
            lag_odd = autocorr[2 * k - 1]
        else:
            for j in range(n - 2 * k):
                lag_even += x[j] * x[j + 2 * k]
                lag_odd += x[j] * x[j + 2 * k - 1]
            lag_odd += x[n - 2 * k] * x[n - 1]
        for v in range(k):
            even[v] -= x[k - 1 - v] * x[k - 1 + v] + x[n - k + v] * x[n - k - v]
        for v in range(1, 2 * k - 1):
            mixed[v - 1] -= (x[2 * k - 1 - v] * x[2 * k - 1] + x[2 * k - 2 - v] * x[2 * k - 2]
                             + x[n - 2 * k] * x[n - 2 * k + v] + x[n - 2 * k + 1] * x[n - 2 * k + 1 + v])
        even[k] = lag_even
        mixed[2 * k - 2] = 2.0 * lag_odd - x[0] * x[2 * k - 1] - x[n - 2 * k] * x[n - 1]
        mixed[2 * k - 1] = 2.0 * lag_even
        base = squares[n - 1] - squares[2 * k - 1] + squares[n - 2 * k - 1] + 2.0 * lag_even
        total = 0.0
        for v in range(1, k + 1):
            first = base - squares[v - 1] + squares[n - 1 - v] - squares[2 * k - v - 1] + squares[n - 1 - 2 * k + v]
            second = even[k - v] - mixed[v - 1] - mixed[2 * k - v - 1]
            total += (first + 2.0 * second) / v
        out[k - 1] = total
    return out


@njit(cache=True)
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


def theo1_ratio(x: np.ndarray, sums: np.ndarray) -> np.ndarray:
    """sum(x^2) * sum_{v<=k} 1/v over each of :func:`theo1_all`'s sums: about its relative
    error over eps (the expansion's conditioning)."""
    k = np.arange(1, sums.shape[0] + 1)
    with np.errstate(divide="ignore"):
        return float(x @ x) * np.cumsum(1.0 / k) / np.abs(sums)


def oavar_expanded(x: np.ndarray, factors: np.ndarray, autocorr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`oavar_sums` from the record's autocorrelation (O(m) per level) and each sum's
    conditioning (its square terms over it): the sum of x_i^2 + 4 x_{i+m}^2 + x_{i+2m}^2,
    less 4 (F[m] - tail) + 4 (F[m] - head), plus 2 F[2m], tail and head m products each."""
    n_points = x.shape[0]
    squares = np.concatenate(([0.0], np.cumsum(x * x)))
    out = np.empty(factors.shape[0])
    ratio = np.empty(factors.shape[0])
    for level, m in enumerate(factors.tolist()):
        n = n_points - 2 * m
        square = squares[n] + 4.0 * (squares[n + m] - squares[m]) + (squares[n_points] - squares[2 * m])
        tail = float(x[n : n_points - m] @ x[n + m :])
        head = float(x[:m] @ x[m : 2 * m])
        out[level] = square - 4.0 * (2.0 * autocorr[m] - tail - head) + 2.0 * autocorr[2 * m]
        ratio[level] = (square + float(x @ x) * 8.0) / abs(out[level]) if out[level] else np.inf
    return out, ratio
