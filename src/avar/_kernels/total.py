"""Kernels of the total and Theo statistics (numba): MTOTDEV, HTOTDEV and Theo1.

Nothing here validates input: :mod:`avar.stability.total` and
:mod:`avar.stability.theo` do that once and call these kernels on clean,
gap-filled, detrended phase ``x`` (0-based, N points). The tests check every
kernel against a plain loop over the NIST SP 1065 formula.

Gaps: ``bad`` is the prefix count of missing values of the input (length of
the input + 1; empty when there is none) and ``shift`` is 0 for phase data
(phase points are missing) and 1 for frequency data (the increment
``x[k + 1] - x[k]`` is missing). A term whose phase points ``start .. stop - 1``
touch a gap is skipped; the kernels return the sum and the number of terms used.

Each window of the total statistics is detrended, extended by reflection and
summed through the running sum of its 9m-point extension, so a window costs
O(m) and a level O(N m); Theo1 costs O(N m / 2) per level. The sums run in one
fixed order: the result does not depend on the machine's threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _clean(bad: np.ndarray, shift: int, start: int, stop: int) -> bool:
    """Whether phase points ``start .. stop - 1`` avoid every gap."""
    if bad.shape[0] == 0:
        return True
    return bad[stop - shift] - bad[start] == 0


@njit(cache=True)
def _reflected_terms(w: np.ndarray, m: int, ext: np.ndarray) -> float:
    """sum_{j=0}^{6m-1} (A_j - 2 B_j + C_j)**2 of the 9m-point extension (rev w, w, rev w)
    of the 3m-point window ``w``, where A_j, B_j, C_j are the sums of m consecutive
    points of the extension starting at j, j + m, j + 2m (through its running sum ``ext``)."""
    span = 3 * m
    ext[0] = 0.0
    for k in range(span):
        ext[k + 1] = ext[k] + w[span - 1 - k]
    for k in range(span):
        ext[span + k + 1] = ext[span + k] + w[k]
    for k in range(span):
        ext[2 * span + k + 1] = ext[2 * span + k] + w[span - 1 - k]
    acc = 0.0
    for j in range(6 * m):
        d = (ext[j + 3 * m] - 3.0 * ext[j + 2 * m]) + (3.0 * ext[j + m] - ext[j])
        acc += d * d
    return acc


@njit(cache=True)
def _detrended_window(values: np.ndarray, start: int, m: int, w: np.ndarray) -> None:
    """The 3m values from ``start`` less the line through the means of their first and last
    halves (floor(3m / 2) points each, the middle point left out when 3m is odd), centred."""
    span = 3 * m
    half = span // 2
    gap = span - half  # distance between the two halves' centres
    first = 0.0
    last = 0.0
    for k in range(half):
        first += values[start + k]
        last += values[start + gap + k]
    slope = (last - first) / half / gap
    mean = 0.0
    for k in range(span):
        w[k] = values[start + k] - slope * k
        mean += w[k]
    mean /= span
    for k in range(span):
        w[k] -= mean


@njit(cache=True)
def mtot_sum(x: np.ndarray, m: int, bad: np.ndarray, shift: int) -> tuple[float, int]:
    """MTOTDEV's double sum at factor m: sum over the windows n = 0 .. N - 3m of
    (1 / (6 m)) sum_j ((A_j - 2 B_j + C_j) / m)**2 on the phase window x[n .. n + 3m - 1]
    (detrended, reflected); and the number of windows used."""
    n_points = x.shape[0]
    span = 3 * m
    w = np.empty(span)
    ext = np.empty(3 * span + 1)
    total = 0.0
    count = 0
    for start in range(n_points - span + 1):
        if not _clean(bad, shift, start, start + span):
            continue
        _detrended_window(x, start, m, w)
        total += _reflected_terms(w, m, ext) / (6.0 * m * m * m)
        count += 1
    return total, count


@njit(cache=True)
def htot_sum(x: np.ndarray, m: int, bad: np.ndarray, shift: int) -> tuple[float, int]:
    """HTOTDEV's double sum at factor m on the frequency y_k = x[k + 1] - x[k]: sum over the
    windows n = 0 .. M - 3m (M = N - 1) of (1 / (6 m)) sum_j ((A_j - 2 B_j + C_j) / m)**2
    on y[n .. n + 3m - 1] (detrended, reflected); and the number of windows used."""
    n_freq = x.shape[0] - 1
    span = 3 * m
    y = np.empty(n_freq)
    for k in range(n_freq):
        y[k] = x[k + 1] - x[k]
    w = np.empty(span)
    ext = np.empty(3 * span + 1)
    total = 0.0
    count = 0
    for start in range(n_freq - span + 1):
        if not _clean(bad, shift, start, start + span + 1):
            continue
        _detrended_window(y, start, m, w)
        total += _reflected_terms(w, m, ext) / (6.0 * m * m * m)
        count += 1
    return total, count


@njit(cache=True)
def theo1_sum(x: np.ndarray, m: int, bad: np.ndarray, shift: int) -> tuple[float, int]:
    """Theo1's double sum at even factor m::

        sum_{i=0}^{N-m-1} sum_{d=0}^{m/2-1} ((x_i - x_{i-d+m/2}) + (x_{i+m} - x_{i+d+m/2}))**2 / (m/2 - d)

    and the number of outer terms i used."""
    n_points = x.shape[0]
    half = m // 2
    total = 0.0
    count = 0
    for i in range(n_points - m):
        if not _clean(bad, shift, i, i + m + 1):
            continue
        acc = 0.0
        for d in range(half):
            t = (x[i] - x[i - d + half]) + (x[i + m] - x[i + d + half])
            acc += t * t / (half - d)
        total += acc
        count += 1
    return total, count


@njit(cache=True)
def level_sums(kind: int, x: np.ndarray, factors: np.ndarray, bad: np.ndarray, shift: int):
    """``kind`` 0: :func:`mtot_sum`, 1: :func:`htot_sum`, 2: :func:`theo1_sum` at every factor."""
    sums = np.zeros(factors.shape[0])
    counts = np.zeros(factors.shape[0], dtype=np.int64)
    for level in range(factors.shape[0]):
        m = factors[level]
        if kind == 0:
            sums[level], counts[level] = mtot_sum(x, m, bad, shift)
        elif kind == 1:
            sums[level], counts[level] = htot_sum(x, m, bad, shift)
        else:
            sums[level], counts[level] = theo1_sum(x, m, bad, shift)
    return sums, counts
