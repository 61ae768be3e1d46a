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
O(m) and a level O(N m); Theo1 costs O(N m / 2) per level. A level's terms run
in tasks of :data:`CHUNK` terms whose sums are added in task order, so a
parallel loop over the tasks would give the same result on any number of threads.
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


#: Terms per task: fixed, so the sums would not depend on the number of threads.
CHUNK = 512


@njit(cache=True)
def _window_range(kind: int, values: np.ndarray, m: int, bad: np.ndarray, shift: int, first: int, last: int,
                  w: np.ndarray, ext: np.ndarray) -> tuple[float, int]:
    """The terms ``first .. last - 1`` of one level (``kind`` 0 MTOTDEV on phase, 1 HTOTDEV on
    frequency, 2 Theo1 on phase): their sum and how many avoid the gaps."""
    total = 0.0
    count = 0
    span = 3 * m
    half = m // 2
    for start in range(first, last):
        if kind == 2:
            if not _clean(bad, shift, start, start + m + 1):
                continue
            acc = 0.0
            for d in range(half):
                t = (values[start] - values[start - d + half]) + (values[start + m] - values[start + d + half])
                acc += t * t / (half - d)
            total += acc
        else:
            if not _clean(bad, shift, start, start + span + kind):
                continue
            _detrended_window(values, start, m, w)
            total += _reflected_terms(w, m, ext) / (6.0 * m * m * m)
        count += 1
    return total, count


@njit(cache=True, nogil=True)
def _level(kind: int, values: np.ndarray, m: int, bad: np.ndarray, shift: int, n_terms: int) -> tuple[float, int]:
    """One level's sum over its ``n_terms`` terms, in tasks of :data:`CHUNK` summed in order.

    Serial: with numba's ``prange`` over the tasks the result is the same, but on two
    shared cores it measured 1.3-1.5x slower (N = 1e4); kept ready for more cores."""
    n_tasks = (n_terms + CHUNK - 1) // CHUNK
    sums = np.zeros(n_tasks)
    counts = np.zeros(n_tasks, dtype=np.int64)
    for task in range(n_tasks):
        w = np.empty(3 * m)
        ext = np.empty(9 * m + 1)
        first = task * CHUNK
        sums[task], counts[task] = _window_range(kind, values, m, bad, shift, first,
                                                 min(n_terms, first + CHUNK), w, ext)
    total = 0.0
    count = 0
    for task in range(n_tasks):
        total += sums[task]
        count += counts[task]
    return total, count


def mtot_sum(x: np.ndarray, m: int, bad: np.ndarray, shift: int) -> tuple[float, int]:
    """MTOTDEV's double sum at factor m: sum over the windows n = 0 .. N - 3m of
    (1 / (6 m)) sum_j ((A_j - 2 B_j + C_j) / m)**2 on the phase window x[n .. n + 3m - 1]
    (detrended, reflected); and the number of windows used."""
    return _level(0, x, int(m), bad, shift, max(0, x.shape[0] - 3 * int(m) + 1))


def htot_sum(x: np.ndarray, m: int, bad: np.ndarray, shift: int) -> tuple[float, int]:
    """HTOTDEV's double sum at factor m on the frequency y_k = x[k + 1] - x[k]: sum over the
    windows n = 0 .. M - 3m (M = N - 1) of (1 / (6 m)) sum_j ((A_j - 2 B_j + C_j) / m)**2
    on y[n .. n + 3m - 1] (detrended, reflected); and the number of windows used."""
    y = np.ascontiguousarray(np.diff(x))
    return _level(1, y, int(m), bad, shift, max(0, y.shape[0] - 3 * int(m) + 1))


def theo1_sum(x: np.ndarray, m: int, bad: np.ndarray, shift: int) -> tuple[float, int]:
    """Theo1's double sum at even factor m::

        sum_{i=0}^{N-m-1} sum_{d=0}^{m/2-1} ((x_i - x_{i-d+m/2}) + (x_{i+m} - x_{i+d+m/2}))**2 / (m/2 - d)

    and the number of outer terms i used."""
    return _level(2, x, int(m), bad, shift, max(0, x.shape[0] - int(m)))


def level_sums(kind: int, x: np.ndarray, factors: np.ndarray, bad: np.ndarray, shift: int):
    """``kind`` 0: :func:`mtot_sum`, 1: :func:`htot_sum`, 2: :func:`theo1_sum` at every factor."""
    values = np.ascontiguousarray(np.diff(x)) if kind == 1 else x
    sums = np.zeros(factors.shape[0])
    counts = np.zeros(factors.shape[0], dtype=np.int64)
    for level, m in enumerate(factors.tolist()):
        n_terms = values.shape[0] - (3 * m - 1 if kind < 2 else m)
        sums[level], counts[level] = _level(kind, values, m, bad, shift, max(0, n_terms))
    return sums, counts
