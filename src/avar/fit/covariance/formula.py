"""The pieces of the covariance of maximal-overlap Allan variance estimates that every algorithm shares.

The maximal-overlap AV at averaging factor m of x_1..x_N, with first
differences d_t = x_t - x_{t-1}, is

    nu_hat(m) = (1 / M) sum_{s=1}^{M} W_s(m)^2,   M = N - 2 m + 1   (:func:`level_counts`),
    W_s(m) = (ybar_{s+m}(m) - ybar_s(m)) / sqrt(2) = sum_{l=1}^{2m-1} g_m(l) d_{s+l},

with the triangular Allan filter g_m(l) = min(l, 2m - l) / (m sqrt(2))
(:func:`allan_filter`; its sum is m / sqrt(2), so a ramp of slope omega gives
E W_s(m) = mu_m = omega m / sqrt(2)). With gamma_jk(h) = Cov(W_s(m_j), W_{s+h}(m_k))
and c_jk(h) = #{s : 1 <= s <= M_j, 1 <= s + h <= M_k} (:func:`pair_counts`),
for Gaussian d (Isserlis)

    Cov(nu_hat_j, nu_hat_k) = 1 / (M_j M_k) sum_h c_jk(h) [2 gamma_jk(h)^2 + 4 mu_j mu_k gamma_jk(h)]

(:func:`summand` is the bracket). Quantization noise (uniform, not Gaussian) is
treated as Gaussian with the same autocovariance: its fourth cumulant is ignored.
"""

from __future__ import annotations

import numpy as np

__all__ = ["allan_filter", "level_counts", "pair_counts", "summand"]


def allan_filter(m: int) -> np.ndarray:
    """g_m(l), l = 1..2m-1: the Allan filter on the first differences.

    >>> (allan_filter(2) * np.sqrt(2.0)).tolist()
    [0.5, 1.0, 0.5]
    """
    ell = np.arange(1, 2 * m, dtype=np.float64)
    return np.minimum(ell, 2 * m - ell) / (m * np.sqrt(2.0))


def level_counts(n: int, factors: np.ndarray) -> np.ndarray:
    """M_j = N - 2 m_j + 1, the number of terms of each maximal-overlap estimate.

    >>> level_counts(10, np.array([1, 2, 4])).tolist()
    [9, 7, 3]
    """
    return n - 2 * np.asarray(factors, dtype=np.int64) + 1


def pair_counts(count_j: int, count_k: int, h: np.ndarray) -> np.ndarray:
    """c_jk(h) = #{s : 1 <= s <= M_j, 1 <= s + h <= M_k} at lags ``h`` (0 outside the overlap).

    >>> pair_counts(3, 2, np.arange(-3, 3)).tolist()
    [0, 1, 2, 2, 1, 0]
    """
    return np.maximum(np.minimum(count_j, count_k - h) - np.maximum(1, 1 - h) + 1, 0)


def summand(gamma: np.ndarray, mean_product: np.ndarray | float) -> np.ndarray:
    """2 gamma^2 + 4 mu_j mu_k gamma: the term at each lag, before the pair counts and 1 / (M_j M_k)."""
    return 2.0 * gamma * gamma + 4.0 * mean_product * gamma
