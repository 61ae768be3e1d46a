"""The outlier search in NumPy for short records: nothing to compile, the kernels' results bit for bit.

A first call of :func:`avar.robust_avar` would wait ~2 s for numba to compile the outlier
kernels (:mod:`avar._kernels.robust`: the interpolation residuals, the running median, the
release of the candidates, the differences clear of them). While they are cold and the record is
short (:func:`avar._kernels.runtime.paths.numpy_path`, :func:`outlier_kernels`,
:func:`squares_kernel`), the twins here answer,
with the kernels' arguments (the outputs written in place) and results:

* :func:`interpolation_residuals`: the nearest unflagged neighbours of every sample by running
  extrema of their indices, then the kernel's arithmetic, operation for operation (the same
  roundings: the same bits).
* :func:`running_median`: the 2 half + 1 values of each window (ends mirrored as the kernel
  does) by :func:`numpy.lib.stride_tricks.sliding_window_view`, their middle one by
  :func:`numpy.partition`: a median of an odd count is one of the values, exact.
* :func:`release_candidates`: the kernel's passes, each on the twin's residuals.
* :func:`intact_squares`: the "mo" differences that hold no flagged sample, by the kernel's own
  sequence of roundings (the same bits).

The tests force each path on the same data (:func:`avar._kernels.runtime.paths.forced`) and
compare them with ``==``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from avar import _kernels
from avar._kernels.robust import REFRESH, IntactSquares
from avar._kernels.runtime.paths import numpy_path

#: Work units (:data:`avar._kernels.runtime.paths.HOT_WORK`, ~25 ns) charged per sample: the twins
#: lose ~0.15 us per sample to the warm kernels (CPU, N = 1e5: a whole call 28 ms against 13 ms).
TWIN_WORK = 6
#: Largest work a cold call sends to the twins (N ~ 7e5: ~0.2 s in them, against ~2 s of compilation).
TWIN_LIMIT = 1 << 22


class OutlierKernels(NamedTuple):
    """The three loops of the outlier search (:func:`avar.stability.robust.estimator.flag_outliers`)."""

    interpolation_residuals: Callable
    running_median: Callable
    release_candidates: Callable


def interpolation_residuals(x: np.ndarray, flagged: np.ndarray, out: np.ndarray) -> None:
    """:func:`avar._kernels.robust.interpolation_residuals` in NumPy: ``out[t] = x[t] - line(t)``, the
    line through the nearest unflagged samples a < t < b (one of them when the other is missing, 0
    when both are).

    >>> out = np.empty(4)
    >>> interpolation_residuals(np.array([0.0, 5.0, 2.0, 3.0]), np.array([False, True, False, False]), out)
    >>> out.tolist()
    [-2.0, 4.0, 0.0, 1.0]
    """
    n = x.shape[0]
    index = np.arange(n)
    good = ~flagged
    previous = np.empty(n, dtype=np.int64)  # nearest unflagged index < t, -1 when none
    previous[0] = -1
    previous[1:] = np.maximum.accumulate(np.where(good, index, -1))[:-1]
    following = np.empty(n, dtype=np.int64)  # nearest unflagged index > t, n when none
    following[-1] = n
    following[:-1] = np.minimum.accumulate(np.where(good, index, n)[::-1])[::-1][1:]
    has_previous, has_following = previous >= 0, following < n
    p, f = np.maximum(previous, 0), np.minimum(following, n - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        step = (x[f] - x[p]) / (f - p)
        line = x[p] + step * (index - p)
    out[:] = np.where(has_previous & has_following, x - line,
                      np.where(has_previous, x - x[p], np.where(has_following, x - x[f], 0.0)))


def running_median(x: np.ndarray, half: int, out: np.ndarray) -> None:
    """:func:`avar._kernels.robust.running_median` in NumPy: ``out[t]`` = median of the 2 ``half`` + 1
    values around t, the ends reflected without repeating the end sample (then clipped, as the kernel).

    >>> out = np.empty(5)
    >>> running_median(np.array([9.0, 1.0, 2.0, 3.0, 7.0]), 1, out)
    >>> out.tolist()
    [1.0, 2.0, 2.0, 3.0, 3.0]
    """
    n = x.shape[0]
    at = np.arange(-half, n + half)
    at = np.where(at < 0, -at, at)
    at = np.where(at >= n, 2 * (n - 1) - at, at)
    windows = sliding_window_view(x[np.clip(at, 0, n - 1)], 2 * half + 1)
    out[:] = np.partition(windows, half, axis=1)[:, half]


def release_candidates(x: np.ndarray, flagged: np.ndarray, residuals: np.ndarray, limit: float,
                       max_passes: int) -> int:
    """:func:`avar._kernels.robust.release_candidates` in NumPy: unflag, pass after pass, the flagged t
    with ``|x[t] - line(t)| <= limit`` (``flagged`` and ``residuals`` updated in place); the passes made.

    >>> flagged = np.array([False, True, True, False])
    >>> release_candidates(np.array([0.0, 1.0, 9.0, 3.0]), flagged, np.empty(4), 0.5, 50), flagged.tolist()
    (2, [False, False, True, False])
    """
    passes = 0
    while passes < max_passes:
        passes += 1
        interpolation_residuals(x, flagged, residuals)
        released = flagged & (np.abs(residuals) <= limit)
        if not released.any():
            break
        flagged[released] = False
    return passes


def intact_squares(x: np.ndarray, flagged: np.ndarray, m: int) -> IntactSquares:
    """:func:`avar._kernels.robust.intact_squares` in NumPy, bit for bit: the sum of D_t**2 and their
    count over the t whose 2m samples t..t+2m-1 hold no flagged sample, D_t = sum_{i<m} (x[t+m+i] -
    x[t+i]). As the kernel, D_t is summed afresh every :data:`avar._kernels.robust.REFRESH` steps
    and slides between (sequential sums: :func:`numpy.cumsum` along each run), the squares summed
    in order.

    >>> intact_squares(np.array([0.0, 1.0, 3.0, 2.0, 9.0]), np.array([0, 0, 0, 0, 1], dtype=bool), 1)
    IntactSquares(total=6.0, n_terms=3)
    """
    n = x.shape[0]
    count = n - 2 * m + 1
    starts = np.arange(0, count, REFRESH)
    fresh = np.cumsum(x[starts[:, None] + m + np.arange(m)] - x[starts[:, None] + np.arange(m)], axis=1)[:, -1]
    steps = np.empty(starts.size * REFRESH)
    t = np.arange(1, count)
    steps[1:count] = (x[t - 1 + 2 * m] - x[t - 1 + m]) - (x[t - 1 + m] - x[t - 1])  # D_t - D_{t-1}
    steps[count:] = 0.0
    steps[starts] = fresh
    d = np.cumsum(steps.reshape(starts.size, REFRESH), axis=1).ravel()[:count]
    running = np.concatenate(([0], np.cumsum(flagged, dtype=np.int64)))
    intact = d[running[2 * m : 2 * m + count] == running[:count]]
    squares = intact * intact
    return IntactSquares(float(np.cumsum(squares)[-1]) if squares.size else 0.0, int(squares.size))


#: The kernels the twins stand in for, and the route of their dispatch (found compiled once, never asked again).
KERNELS = (_kernels.interpolation_residuals, _kernels.running_median, _kernels.release_candidates)
_ROUTE = "robust.outliers"
_SQUARES_ROUTE = "robust.squares"


def squares_kernel(values: np.ndarray) -> Callable:
    """:func:`avar._kernels.robust.intact_squares`, or its twin :func:`intact_squares` while that is
    cold and ``values`` short (as :func:`outlier_kernels`)."""
    if numpy_path(TWIN_WORK * values.size, TWIN_LIMIT, (_kernels.intact_squares,), values, route=_SQUARES_ROUTE):
        return intact_squares
    return _kernels.intact_squares


def outlier_kernels(values: np.ndarray) -> OutlierKernels:
    """The compiled loops (:mod:`avar._kernels.robust`), or their twins here while those are cold
    and ``values`` (contiguous float64) are short (:data:`TWIN_WORK` per sample within :data:`TWIN_LIMIT`)."""
    if numpy_path(TWIN_WORK * values.size, TWIN_LIMIT, KERNELS, values, route=_ROUTE):
        return OutlierKernels(interpolation_residuals, running_median, release_candidates)
    return OutlierKernels(*KERNELS)
