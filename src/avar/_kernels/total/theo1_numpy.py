"""NumPy twins of Theo1's expansion kernels, bit for bit: nothing to compile on a cold first call.

Theo1's long levels (:func:`avar._kernels.total.theo1.theo1_expanded`) run three small compiled
loops: :func:`avar._kernels.total.theo1._plain_parts`, :func:`avar._kernels.total.theo1._weighted_lags`
and the leaves of :func:`avar._kernels.total.fft.hankel_lower`. Their first call in a process
without numba's cache waits ~1 s for the compiler, for O(m) work per level. While they are cold
(:func:`avar._kernels.runtime.paths.numpy_path`) the functions here answer instead: every term is
formed with the kernel's operations in its order, and each running sum with
:func:`numpy.cumsum`, which adds in sequence as the kernel's loop does, so the results are the
kernel's to the last bit (the tests compare them with ``==``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: Largest level (m) whose expansion sums :func:`plain_parts` and :func:`weighted_lags` take while
#: the kernels are cold (O(m) each: any level of a record NumPy holds).
PARTS_LIMIT = 1 << 30
#: Largest leaf work (output length times leaf size) :func:`hankel_leaves` takes while the kernel
#: is cold (~1e7 products: ~0.1 s; the kernel's compilation ~0.4 s).
HANKEL_LIMIT = 1 << 23
#: Products formed per pass of :func:`hankel_leaves` (its arrays stay within a few MB).
LEAF_CHUNK = 1 << 18


class PlainParts(NamedTuple):
    """A level's square terms, F terms and ends' Φ sum (as the kernel's tuple)."""

    square: float
    lags: float
    ends: float


class WeightedLags(NamedTuple):
    """The ends' weighted lag sums: the pairs and the corners (as the kernel's tuple)."""

    pairs: float
    corners: float


def _sequential(first: float, terms: np.ndarray) -> float:
    """``first`` plus ``terms`` added one by one in order (the kernel's ``acc +=`` loop)."""
    if terms.shape[0] == 0:
        return float(first)
    return float(np.cumsum(np.concatenate(([first], terms)))[-1])


def plain_parts(x: np.ndarray, reverse: np.ndarray, squares: np.ndarray, autocorr: np.ndarray,
                phi: np.ndarray, phi_reverse: np.ndarray, m: int) -> PlainParts:
    """:func:`avar._kernels.total.theo1._plain_parts` in NumPy, bit for bit: level ``m``'s square
    terms, its F terms and sum_{c<=h} x_{m-c} Φ(c) of both ends.

    >>> x = np.array([1.0, -2.0, 0.5, 3.0, -1.0, 2.0])
    >>> squares = np.concatenate(([0.0], np.cumsum(x * x)))
    >>> autocorr = np.array([np.dot(x[: x.size - k], x[k:]) for k in range(x.size)])
    >>> plain_parts(x, x[::-1].copy(), squares, autocorr, np.ones(4), np.ones(4), 4)
    PlainParts(square=38.5, lags=3.125, ends=7.0)
    """
    n_points = x.shape[0]
    n = n_points - m
    h = m // 2
    a = np.arange(1, h + 1)
    w = 1.0 / a.astype(np.float64)
    b = m - a
    weight = _sequential(0.0, w)
    square = _sequential(0.0, w * (squares[n + a] - squares[a] + squares[n + b] - squares[b]))
    lags = _sequential(0.0, w * (autocorr[m - 2 * a] - 2.0 * autocorr[a] - 2.0 * autocorr[b]))
    ends = _sequential(0.0, x[b] * phi[a] + reverse[b] * phi_reverse[a])
    square += float(weight * (squares[n] + squares[n_points] - squares[m]))
    lags += float(weight * autocorr[m])
    return PlainParts(square, lags, ends)


def weighted_lags(long: np.ndarray, short: np.ndarray, m: int) -> WeightedLags:
    """:func:`avar._kernels.total.theo1._weighted_lags` in NumPy, bit for bit: sum_{0<l<m} long[l] /
    min(l, m - l) (l = h twice) and sum_{l even < h} 2 short[l] / (m - l).

    >>> [round(v, 6) for v in weighted_lags(np.arange(8.0), np.ones(8), 8)]
    [16.666667, 0.583333]
    """
    h = m // 2
    lag = np.arange(1, h)
    first = _sequential(2.0 * long[h] / h, (long[lag] + long[m - lag]) / lag.astype(np.float64))
    even = np.arange(0, h, 2)
    second = _sequential(0.0, 2.0 * short[even] / (m - even).astype(np.float64))
    return WeightedLags(first, second)


def hankel_leaves(y: np.ndarray, kappa: np.ndarray, out: np.ndarray, leaf: int) -> None:
    """:func:`avar._kernels.total.fft._hankel_leaves` in NumPy, bit for bit: within every leaf of
    ``leaf`` indices from ``start``, ``out[g] += sum_{start <= i < g} y[i] kappa[g + i]``, the
    products added in order of i (``out``'s length a multiple of ``leaf``).

    >>> out = np.zeros(4)
    >>> hankel_leaves(np.arange(1.0, 5.0), np.ones(12), out, 2)
    >>> out.tolist()
    [0.0, 1.0, 0.0, 3.0]
    """
    n_leaves = out.shape[0] // leaf
    k = np.arange(leaf)
    lower = k[None, :] < k[:, None]  # (g, i): i < g
    step = max(1, LEAF_CHUNK // (leaf * leaf))  # leaves per pass: bounded memory
    for first in range(0, n_leaves, step):
        starts = np.arange(first, min(n_leaves, first + step)) * leaf
        g = starts[:, None, None] + k[None, :, None]  # (leaves, g, i)
        i = starts[:, None, None] + k[None, None, :]
        products = np.where(lower, y[i] * kappa[g + i], 0.0)
        out[starts[0] : starts[-1] + leaf] += np.cumsum(products, axis=2)[:, :, -1].reshape(-1)
