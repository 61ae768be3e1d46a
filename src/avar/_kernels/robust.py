"""Outlier kernels (numba): residuals from interpolation, and a running median.

A sample's residual is its distance from the straight line through its
nearest unflagged neighbours: a linear combination of samples, hence
Gaussian for any Gaussian process (white noise, random walk, drift...), so a
threshold in robust standard deviations means a known tail probability. The
running median finds the candidates (it resists spikes and short bursts).
One pass of each is O(N).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit


class IntactSquares(NamedTuple):
    """Sum of the squared differences D_t**2 that hold no flagged sample, and their count
    (:func:`intact_squares`; numba builds it in compiled code)."""

    total: float
    n_terms: int


@njit(cache=True)
def interpolation_residuals(x, flagged, out):
    """``out[t] = x[t] - line(t)``, the line through the nearest unflagged samples a < t < b.

    ``x`` float64 and ``flagged`` bool, of one length n >= 2; ``t`` itself may
    be flagged (its residual is then its distance from the clean line). With
    no unflagged sample on one side, the line is the nearest unflagged
    sample on the other side; with none at all, ``out[t]`` is 0.
    """
    n = x.shape[0]
    previous = -1  # nearest unflagged index < t
    following = 0  # nearest unflagged index > t (n when none)
    for t in range(n):
        if following <= t:
            following = t + 1
            while following < n and flagged[following]:
                following += 1
        if previous >= 0 and following < n:
            step = (x[following] - x[previous]) / (following - previous)
            out[t] = x[t] - (x[previous] + step * (t - previous))
        elif previous >= 0:
            out[t] = x[t] - x[previous]
        elif following < n:
            out[t] = x[t] - x[following]
        else:
            out[t] = 0.0
        if not flagged[t]:
            previous = t


@njit(cache=True)
def _mirror(i, n):
    """Index i reflected about the ends (-1 -> 1, n -> n - 2), then clipped to 0..n-1."""
    if i < 0:
        i = -i
    if i >= n:
        i = 2 * (n - 1) - i
    return min(max(i, 0), n - 1)


@njit(cache=True)
def running_median(x, half, out):
    """``out[t]`` = median of ``x[mirror(t - half .. t + half)]`` (2 half + 1 values, ends reflected).

    ``x`` and ``out`` are float64 of one length n >= 1 and ``half`` >= 0.
    The ends reflect without repeating the end sample (x[-k] = x[k], as
    ``scipy.ndimage.median_filter(x, 2 half + 1, mode="mirror")`` for
    n > half), so a spike at the end is not its own median. The
    window is kept sorted and slides one sample at a time (O(half) per
    sample); the median is one of the values (exact).
    """
    n = x.shape[0]
    width = 2 * half + 1
    window = np.empty(width, dtype=np.float64)
    for k in range(width):
        window[k] = x[_mirror(k - half, n)]
    window.sort()
    out[0] = window[half]
    for t in range(1, n):
        leaving = x[_mirror(t - half - 1, n)]
        entering = x[_mirror(t + half, n)]
        if leaving != entering:
            i = 0  # remove `leaving`: find it, shift the tail left over it
            while window[i] != leaving:
                i += 1
            while i < width - 1:
                window[i] = window[i + 1]
                i += 1
            j = width - 1  # insert `entering` into the sorted first width - 1 values
            while j > 0 and window[j - 1] > entering:
                window[j] = window[j - 1]
                j -= 1
            window[j] = entering
        out[t] = window[half]


@njit(cache=True)
def release_candidates(x, flagged, residuals, limit, max_passes):
    """Unflag, pass after pass, the flagged t with |x[t] - line(t)| <= limit, until none is released.

    Each pass computes every residual from the lines through the samples
    unflagged at its start (:func:`interpolation_residuals`), then releases;
    ``flagged`` (bool) is updated in place and ``residuals`` holds the last
    pass's residuals. Returns the number of passes.
    """
    n = x.shape[0]
    passes = 0
    while passes < max_passes:
        passes += 1
        interpolation_residuals(x, flagged, residuals)
        released = 0
        for t in range(n):
            if flagged[t] and abs(residuals[t]) <= limit:
                flagged[t] = False
                released += 1
        if released == 0:
            break
    return passes


#: The intact differences' running sum is recomputed from scratch every REFRESH steps (bounds its rounding drift).
REFRESH = 1024


@njit(cache=True)
def _difference(x, t, m):
    total = 0.0
    for i in range(m):
        total += x[t + m + i] - x[t + i]
    return total


@njit(cache=True)
def intact_squares(x, flagged, m):
    """Sum of D_t**2 and their count over the t whose 2m samples t..t+2m-1 hold no flagged sample.

    D_t = sum_{i<m} (x[t+m+i] - x[t+i]) = m (ybar_{t+m}(m) - ybar_t(m)), so the
    "mo" Allan variance of those differences is sum / (2 m**2 count). ``x``
    float64 (mean removed, flagged samples replaced by finite values: they
    never enter a counted D_t), ``flagged`` bool, 1 <= m <= n // 2. D_t
    slides in O(1) per step and is recomputed every ``REFRESH`` steps.
    """
    n = x.shape[0]
    bad = 0
    for i in range(2 * m):
        bad += flagged[i]
    total = 0.0
    count = 0
    d = 0.0
    for t in range(n - 2 * m + 1):
        if t % REFRESH == 0:
            d = _difference(x, t, m)
        if bad == 0:
            total += d * d
            count += 1
        if t + 2 * m < n:
            d += (x[t + 2 * m] - x[t + m]) - (x[t + m] - x[t])
            bad += flagged[t + 2 * m] - flagged[t]
    return IntactSquares(total, count)
