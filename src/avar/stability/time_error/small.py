"""MTIE, TIE rms, PDEV and the Groslambert codeviation in NumPy: nothing to compile, as exact as the kernels.

A first call of :func:`avar.mtie`, :func:`avar.tierms`, :func:`avar.pdev` or :func:`avar.gcodev`
would wait 1 to 2 s for numba to compile its loop (:mod:`avar._kernels.time_error`). While that
kernel is cold and the record is short (:func:`avar._kernels.runtime.paths.numpy_path`, called
by :mod:`avar.stability.time_error.deviations` and :mod:`avar.stability.time_error.clock_pairs`),
the twins here answer, with the kernels' inputs and results (:class:`TermSums`,
:class:`LargestRanges`) and the same windows skipped at gaps:

* :func:`mtie_levels`: the same van Herk / Gil-Werman sliding extremum, vectorized over the
  blocks of m + 1 points (:func:`numpy.maximum.accumulate` forward and backward). A maximum and
  a minimum round nothing: the ranges equal the kernel's bit for bit.
* :func:`tierms_levels`: the squares (x_{i+m} - x_i)**2, rounded as in the kernel, summed by
  NumPy's pairwise sum (positive terms: ~1e-16 relative, as the kernel's blocked Kahan sum).
* :func:`pdev_levels`: the kernel's recurrence, S_{i+1} = S_i - c_0 D_i + c_m D_{i+m} + W_{i+1},
  restarted from an exact dot product every m steps, vectorized over the restarts (a running
  sum along each run of m steps); the squares summed pairwise. Each S_i carries the rounding
  of at most m steps, as in the kernel (~1e-15 relative to the terms).
* :func:`codev_levels`: the products of the two second differences, rounded as in the kernel,
  summed exactly rounded (:func:`math.fsum`): signed terms, whose sum may cancel, where the
  kernel sums with Kahan's compensation.

The tests force each path on the same data (:func:`avar._kernels.runtime.paths.forced`) and
compare them: MTIE with ``==``, the sums at 1e-12.
"""

from __future__ import annotations

import math

import numpy as np

from avar._kernels.time_error import LargestRanges, TermSums

#: Work units (:data:`avar._kernels.runtime.paths.HOT_WORK`, ~25 ns) charged per phase point and
#: level: what the twins lose to the warm kernels (CPU, a whole call at N = 1e5, 17 octave levels:
#: MTIE 82 ms against 15, GCODEV 83 against 11, PDEV 47 against 19, TIE rms 7 against 5).
TWIN_WORK = {"mtie": 2, "tierms": 1, "pdev": 1, "gcodev": 2}
#: Largest work a cold call sends to the twins: N ~ 1e5 at octave taus (under 0.1 s in them,
#: against 1.5 to 2 s of compilation).
TWIN_LIMIT = 1 << 22


def _skipped(gaps: np.ndarray, count: int, low: int, high: int) -> np.ndarray | None:
    """Whether each of ``count`` windows holds a gap: gaps[i + high] - gaps[i + low] > 0 (None: no gap)."""
    if gaps[-1] == 0:
        return None
    return gaps[high : high + count] - gaps[low : low + count] > 0


def _mtie_level(x: np.ndarray, w: int, gaps: np.ndarray, extra: int) -> tuple[float, int]:
    """The largest range of the windows of ``w`` points that avoid the gaps, and their count."""
    n = x.size
    count = n - w + 1
    blocks = -(-n // w)
    padded = np.empty(blocks * w)
    padded[:n] = x
    padded[n:] = x[-1]  # the last, partial block: its padding repeats its last value (changes no extremum)
    rows = padded.reshape(blocks, w)
    gmax = np.maximum.accumulate(rows, axis=1).ravel()
    gmin = np.minimum.accumulate(rows, axis=1).ravel()
    hmax = np.maximum.accumulate(rows[:, ::-1], axis=1)[:, ::-1].ravel()
    hmin = np.minimum.accumulate(rows[:, ::-1], axis=1)[:, ::-1].ravel()
    spans = np.maximum(hmax[:count], gmax[w - 1 : w - 1 + count]) - np.minimum(hmin[:count], gmin[w - 1 : w - 1 + count])
    skip = _skipped(gaps, count, 0, w - 1 + extra)
    if skip is not None:
        spans = spans[~skip]
    return (float(spans.max()) if spans.size else math.nan), int(spans.size)


def mtie_levels(x: np.ndarray, m: np.ndarray, gaps: np.ndarray, extra: int) -> LargestRanges:
    """The kernel's :func:`avar._kernels.time_error.mtie_levels` in NumPy, bit for bit: the largest
    range max - min over the windows of m + 1 consecutive phase points without a gap.

    >>> mtie_levels(np.array([0.0, 1.0, 3.0, 2.0, 2.5]), np.array([1, 2, 4]), np.zeros(6, dtype=np.int64), 1)
    LargestRanges(ranges=array([2., 3., 3.]), n_terms=array([4, 3, 1]))
    """
    out = np.full(m.size, np.nan)
    counts = np.zeros(m.size, dtype=np.int64)
    for level, k in enumerate(m.tolist()):
        if k + 1 <= x.size:
            out[level], counts[level] = _mtie_level(x, k + 1, gaps, extra)
    return LargestRanges(out, counts)


def tierms_levels(x: np.ndarray, m: np.ndarray, gaps: np.ndarray, extra: int) -> TermSums:
    """The kernel's :func:`avar._kernels.time_error.tierms_levels` in NumPy: the sum of
    (x_{i+m} - x_i)**2 over the terms whose points (phase data) or span (frequency data) hold no gap.

    >>> tierms_levels(np.array([0.0, 1.0, 3.0, 2.0, 2.5]), np.array([1, 4]), np.zeros(6, dtype=np.int64), 1)
    TermSums(sums=array([6.25, 6.25]), n_terms=array([4, 1]))
    """
    sums = np.zeros(m.size)
    counts = np.zeros(m.size, dtype=np.int64)
    for level, k in enumerate(m.tolist()):
        count = x.size - k
        if count <= 0:
            continue
        d = x[k:] - x[:count]
        if gaps[-1]:
            if extra == 1:  # the two end points
                skip = (gaps[1 : count + 1] - gaps[:count]) + (gaps[k + 1 : k + 1 + count] - gaps[k : k + count]) > 0
            else:
                skip = _skipped(gaps, count, 0, k)
            d = d[~skip]
        sums[level], counts[level] = float(np.sum(d * d)), d.size
    return TermSums(sums, counts)


def _pdev_terms(x: np.ndarray, k: int, count: int) -> np.ndarray:
    """S_i = sum_{j<k} ((k - 1) / 2 - j) (x_{i+j} - x_{i+j+k}), i < ``count``, by the kernel's
    recurrence restarted exactly at every multiple of k (vectorized over the restarts)."""
    d = x[: x.size - k] - x[k:]  # D_j
    c0 = (k - 1) / 2.0
    cm = c0 - k
    blocks = -(-count // k)
    starts = np.arange(blocks) * k
    rows = d[np.minimum(starts[:, None] + np.arange(k), d.size - 1)]  # D at each restart's k points
    s_start = rows @ (c0 - np.arange(k, dtype=np.float64))
    w_start = rows.sum(axis=1)
    # step i (not a restart): W_i = W_{i-1} - D_{i-1} + D_{i-1+k}; S_i = S_{i-1} - c0 D_{i-1} + cm D_{i-1+k} + W_i
    size = blocks * k
    step = np.arange(1, size)
    old = d[np.minimum(step - 1, d.size - 1)]
    new = d[np.minimum(step - 1 + k, d.size - 1)]
    w_steps = np.empty(size)
    w_steps[1:] = new - old
    w_steps[starts] = w_start
    w = np.cumsum(w_steps.reshape(blocks, k), axis=1).ravel()
    s_steps = np.empty(size)
    s_steps[1:] = (-c0 * old + cm * new) + w[1:]
    s_steps[starts] = s_start
    return np.cumsum(s_steps.reshape(blocks, k), axis=1).ravel()[:count]


def pdev_levels(x: np.ndarray, m: np.ndarray, gaps: np.ndarray, extra: int) -> TermSums:
    """The kernel's :func:`avar._kernels.time_error.pdev_levels` in NumPy: the sum of S_i**2 (at
    m = 1 the second differences x_{i+2} - 2 x_{i+1} + x_i) over the terms without a gap.

    >>> x = np.array([0.0, 1.0, 3.0, 2.0, 2.5, 4.0])
    >>> pdev_levels(x, np.array([1, 2]), np.zeros(7, dtype=np.int64), 1).sums.tolist()
    [13.25, 1.5625]
    """
    sums = np.zeros(m.size)
    counts = np.zeros(m.size, dtype=np.int64)
    for level, k in enumerate(m.tolist()):
        if k == 1:
            count = x.size - 2
            if count <= 0:
                continue
            terms = x[2:] - 2.0 * x[1:-1] + x[:-2]
            skip = (gaps[2 + extra : 2 + extra + count] - gaps[:count]) > 0
        else:
            count = x.size - 2 * k
            if count <= 0:
                continue
            terms = _pdev_terms(x, k, count)
            skip = _skipped(gaps, count, 0, 2 * k - 1 + extra)
        if skip is not None:
            terms = terms[~skip]
        sums[level], counts[level] = float(np.sum(terms * terms)), terms.size
    return TermSums(sums, counts)


def codev_levels(x1: np.ndarray, x2: np.ndarray, m: np.ndarray, gaps: np.ndarray, extra: int) -> TermSums:
    """The kernel's :func:`avar._kernels.time_error.codev_levels` in NumPy: the sum of the products of
    the two series' second differences over the terms without a gap, exactly rounded.

    >>> x = np.array([0.0, 1.0, 3.0, 2.0, 2.5])
    >>> codev_levels(x, -x, np.array([1, 2]), np.zeros(6, dtype=np.int64), 1).sums.tolist()
    [-12.25, -12.25]
    """
    n = min(x1.size, x2.size)
    sums = np.zeros(m.size)
    counts = np.zeros(m.size, dtype=np.int64)
    for level, k in enumerate(m.tolist()):
        count = n - 2 * k
        if count <= 0:
            continue
        a = x1[2 * k : n] - 2.0 * x1[k : n - k] + x1[:count]
        b = x2[2 * k : n] - 2.0 * x2[k : n - k] + x2[:count]
        products = a * b
        if gaps[-1]:
            if extra == 1:  # phase: the three points used
                skip = ((gaps[1 : count + 1] - gaps[:count]) + (gaps[k + 1 : k + 1 + count] - gaps[k : k + count])
                        + (gaps[2 * k + 1 : 2 * k + 1 + count] - gaps[2 * k : 2 * k + count])) > 0
            else:
                skip = _skipped(gaps, count, 0, 2 * k)
            products = products[~skip]
        sums[level], counts[level] = math.fsum(products.tolist()), products.size
    return TermSums(sums, counts)
