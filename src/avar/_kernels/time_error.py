"""Compiled loops of MTIE, TIE rms, PDEV and the Groslambert codeviation, O(N) per level.

No validation and no Python objects: clean float64 phase ``x`` (gaps filled
with finite values), int64 averaging factors ``m`` and ``gaps``, the running
count of missing values (``gaps[j]`` missing before index j, length N + 1; a
term spanning phase points i .. i + s is skipped when ``gaps[i + s + extra] -
gaps[i] > 0``, ``extra`` = 1 for phase data, 0 for frequency data whose
missing value j lies between phase points j and j + 1). Every kernel returns
the sum over the valid terms and their count per level (:class:`TermSums`; MTIE
the largest range, :class:`LargestRanges`); the callers divide. numba builds
these named tuples in compiled code.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit


class TermSums(NamedTuple):
    """The sum over the valid terms of every level and their count."""

    sums: np.ndarray
    n_terms: np.ndarray


class LargestRanges(NamedTuple):
    """MTIE's largest range of every level (0 where no window is valid) and the windows counted."""

    ranges: np.ndarray
    n_terms: np.ndarray


@njit(cache=True)
def _window_count(gaps, i, span, extra):
    return gaps[i + span + extra] - gaps[i]


@njit(cache=True)
def mtie_levels(x, m, gaps, extra):
    """Largest range max - min over every window of m + 1 consecutive phase points.

    The van Herk / Gil-Werman sliding extremum: with blocks of w = m + 1
    points, the prefix extremum ``g`` within each block and the suffix one
    ``h``, the window starting at i has max(h[i], g[i + w - 1]); three
    comparisons per point and level. Windows with a gap are skipped (the
    filled values inside them reach no result). Returns (mtie, count) per
    level (mtie NaN where count is 0).
    """
    n = x.size
    out = np.full(m.size, np.nan)
    counts = np.zeros(m.size, dtype=np.int64)
    gmax = np.empty(n)
    hmax = np.empty(n)
    gmin = np.empty(n)
    hmin = np.empty(n)
    for level in range(m.size):
        w = m[level] + 1
        for start in range(0, n, w):
            stop = min(start + w, n)
            gmax[start] = x[start]
            gmin[start] = x[start]
            for i in range(start + 1, stop):
                gmax[i] = max(gmax[i - 1], x[i])
                gmin[i] = min(gmin[i - 1], x[i])
            hmax[stop - 1] = x[stop - 1]
            hmin[stop - 1] = x[stop - 1]
            for i in range(stop - 2, start - 1, -1):
                hmax[i] = max(hmax[i + 1], x[i])
                hmin[i] = min(hmin[i + 1], x[i])
        best = -np.inf
        count = 0
        for i in range(n - w + 1):
            if gaps[gaps.size - 1] > 0 and _window_count(gaps, i, w - 1, extra) > 0:
                continue
            j = i + w - 1
            span = max(hmax[i], gmax[j]) - min(hmin[i], gmin[j])
            if span > best:
                best = span
            count += 1
        counts[level] = count
        if count:
            out[level] = best
    return LargestRanges(out, counts)


@njit(cache=True)
def tierms_levels(x, m, gaps, extra):
    """Sum of (x_{i+m} - x_i)**2 over i = 0 .. N - m - 1, and the count of terms.

    Phase data (``extra`` = 1) need only the two end points; frequency data
    the whole span (the phase difference sums the m values between them).
    Summed in blocks of 256 terms, the block sums compensated (Kahan).
    """
    n = x.size
    sums = np.zeros(m.size)
    counts = np.zeros(m.size, dtype=np.int64)
    clean = gaps[gaps.size - 1] == 0
    for level in range(m.size):
        k = m[level]
        total = 0.0
        comp = 0.0
        count = 0
        for start in range(0, n - k, 256):
            block = 0.0
            for i in range(start, min(start + 256, n - k)):
                if not clean:
                    if extra == 1:
                        if gaps[i + 1] - gaps[i] + gaps[i + k + 1] - gaps[i + k] > 0:
                            continue
                    elif gaps[i + k] - gaps[i] > 0:
                        continue
                d = x[i + k] - x[i]
                block += d * d
                count += 1
            y = block - comp
            t = total + y
            comp = (t - total) - y
            total = t
        sums[level] = total
        counts[level] = count
    return TermSums(sums, counts)


@njit(cache=True)
def _pdev_exact(x, i, k, c0):
    """S_i = sum_{j<k} (c0 - j) (x_{i+j} - x_{i+j+k}) and W_i = sum_{j<k} (x_{i+j} - x_{i+j+k})."""
    s = 0.0
    w = 0.0
    for j in range(k):
        d = x[i + j] - x[i + j + k]
        s += (c0 - j) * d
        w += d
    return s, w


@njit(cache=True)
def pdev_levels(x, m, gaps, extra):
    """Sum of S_i**2 (PDEV's parabolic terms, NIST / Vernotte 2016) and their count per level.

    S_i = sum_{j=0}^{m-1} ((m - 1) / 2 - j) (x_{i+j} - x_{i+j+m}), i = 0 .. N - 2m - 1,
    by the recurrence S_{i+1} = S_i - c_0 D_i + c_m D_{i+m} + W_{i+1} (D_j =
    x_j - x_{j+m}, W_i = sum of m consecutive D, c_j = (m - 1) / 2 - j),
    recomputed exactly every m steps so that rounding cannot accumulate: O(N)
    per level. At m = 1 (all weights 0) the terms are OADEV's second
    differences, x_{i+2} - 2 x_{i+1} + x_i, as ``allantools.pdev``.
    """
    n = x.size
    sums = np.zeros(m.size)
    counts = np.zeros(m.size, dtype=np.int64)
    for level in range(m.size):
        k = m[level]
        total = 0.0
        comp = 0.0
        count = 0
        if k == 1:
            for i in range(n - 2):
                if _window_count(gaps, i, 2, extra) > 0:
                    continue
                d = x[i + 2] - 2.0 * x[i + 1] + x[i]
                y = d * d - comp
                t = total + y
                comp = (t - total) - y
                total = t
                count += 1
            sums[level] = total
            counts[level] = count
            continue
        c0 = (k - 1) / 2.0
        cm = c0 - k
        s = 0.0
        w = 0.0
        for i in range(n - 2 * k):
            if i % k == 0:
                s, w = _pdev_exact(x, i, k, c0)
            else:
                d_old = x[i - 1] - x[i - 1 + k]
                d_new = x[i - 1 + k] - x[i - 1 + 2 * k]
                w = w - d_old + d_new
                s = s - c0 * d_old + cm * d_new + w
            if gaps[gaps.size - 1] > 0 and _window_count(gaps, i, 2 * k - 1, extra) > 0:
                continue
            y = s * s - comp
            t = total + y
            comp = (t - total) - y
            total = t
            count += 1
        sums[level] = total
        counts[level] = count
    return TermSums(sums, counts)


@njit(cache=True)
def codev_levels(x1, x2, m, gaps, extra):
    """Sum of the products of the two series' overlapping second differences per level.

    sum_i (x1_{i+2m} - 2 x1_{i+m} + x1_i)(x2_{i+2m} - 2 x2_{i+m} + x2_i), i = 0 .. N - 2m - 1.
    """
    n = min(x1.size, x2.size)
    sums = np.zeros(m.size)
    counts = np.zeros(m.size, dtype=np.int64)
    for level in range(m.size):
        k = m[level]
        total = 0.0
        comp = 0.0
        count = 0
        for i in range(n - 2 * k):
            if extra == 1:  # phase: the three points used
                if gaps[i + 1] - gaps[i] + gaps[i + k + 1] - gaps[i + k] + gaps[i + 2 * k + 1] - gaps[i + 2 * k] > 0:
                    continue
            elif _window_count(gaps, i, 2 * k, extra) > 0:
                continue
            a = x1[i + 2 * k] - 2.0 * x1[i + k] + x1[i]
            b = x2[i + 2 * k] - 2.0 * x2[i + k] + x2[i]
            y = a * b - comp
            t = total + y
            comp = (t - total) - y
            total = t
            count += 1
        sums[level] = total
        counts[level] = count
    return TermSums(sums, counts)
