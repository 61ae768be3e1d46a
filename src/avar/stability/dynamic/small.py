"""The dynamic deviations' window sums in NumPy: nothing to compile, as exact as the kernel.

A first call of :func:`avar.dynamic` (:func:`avar.dadev`, :func:`avar.dhdev`) would wait about
1.5 s for numba to compile :func:`avar._kernels.dynamic.windows.window_sums`. While that kernel
is cold and the work is small (:func:`avar._kernels.runtime.paths.numpy_path`, called by
:mod:`avar.stability.dynamic.estimator`), :func:`window_sums` here answers:

1. the terms ``d_b`` of the record, formed from ``hi`` and ``lo`` with the kernel's operations in
   the kernel's order (``lo`` differences in float32, then float64), so every term and its
   square are the kernel's, bit for bit; 0 for a term that touches a gap;
2. every window's sum of its ``count`` squares (every ``stride``-th term from its start) as a
   reduction over a strided view of the squares: the terms are non-negative, so the sum is
   accurate relative to the window's own sum (at most ``count`` eps, typically a few eps), as
   the kernel's compensated prefix sums are.

The phase the windows read (``hi`` and its float32 compensation ``lo``, as
:func:`avar.stability.classic.core.phase_parts` builds it with
:func:`avar._kernels.classic.phase.detrended_phase`) comes, while that kernel is cold too, from
:func:`twin_phase_parts` (:func:`avar.stability.classic.small.detrended_phase`): the kernel's
blocks, running sums and TwoSum compensations replayed with :func:`numpy.cumsum` (sequential, as
the kernel's loop), bit for bit.

The two paths differ in the last bits of the window sums only (the tests force each path and
compare them at 1e-12).
The work is one pass over the record's terms per level plus ``count`` per window
(:func:`twin_work`); the kernel's is one pass and O(1) per window, so the twin answers only
records whose windows hold few terms in all (:data:`TWIN_LIMIT`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.lib.stride_tricks import as_strided

from avar.stability.classic.core import MODIFIED, phase_line
from avar.stability.classic.small import detrended_phase

#: How far past its first point each code's term reaches, in units of m (as the kernel's ``REACH``).
REACH = {0: 2, 1: 3, 2: 3, 4: 4}
#: Work units (:func:`twin_work`) charged per term of the record and level: forming a term costs
#: about ten NumPy passes, a window's term one addition.
TERM_UNITS = 10
#: Largest work a call sends to the twin (N = 1e5 with the default window and step, octave taus:
#: ~2.3e7 units, ~0.1 s; the kernel's compilation ~1.5 s). Beyond
#: :data:`avar._kernels.runtime.paths.HOT_WORK` (2**25) the dispatch compiles anyway.
TWIN_LIMIT = 1 << 25


#: Largest record whose phase :func:`twin_phase_parts` forms while the phase kernel is cold
#: (a few NumPy passes, ~30 ms per 1e6 values; the kernel's compilation ~0.5 s).
PHASE_LIMIT = 1 << 21


class TwinPhaseParts(NamedTuple):
    """What :func:`avar.stability.classic.core.phase_parts` gives the window kernel: the phase
    (or its running sum) ``hi + lo``, its ``scale`` (a power of two), the gap ``mode`` and
    ``bad``, the prefix count of the gaps (None without gaps)."""

    hi: np.ndarray
    lo: np.ndarray
    scale: float
    mode: int
    bad: np.ndarray | None


def twin_phase_parts(values: np.ndarray, data_type: str, statistic: str, scanned: tuple) -> TwinPhaseParts:
    """:func:`avar.stability.classic.core.phase_parts`'s ``hi, lo, scale, mode, bad`` in NumPy, bit
    for bit (:func:`detrended_phase`; the modified statistics' running sum of the phase too)."""
    is_phase = data_type == "phase"
    line = phase_line(values, data_type, statistic, scanned)
    hi, lo = detrended_phase(line.filled, None, int(is_phase), line.centre, line.slope, line.scale)
    if statistic in MODIFIED:
        hi, lo = detrended_phase(hi, lo, 2, float(np.mean(hi)), 0.0, 1.0)
    mode = 0 if line.bad is None else (1 if is_phase else 2)
    return TwinPhaseParts(hi, lo, line.scale, mode, line.bad)


class WindowSums(NamedTuple):
    """Every window's sum of squared terms and number of terms used, at one level."""

    sums: np.ndarray
    counts: np.ndarray


def twin_work(n_points: int, factors: np.ndarray, n_windows: int, counts: np.ndarray) -> int:
    """The twin's work over the levels: :data:`TERM_UNITS` per term of the record plus one per
    term of every window (``counts``: terms per window at each level).

    >>> twin_work(100, np.array([1, 2]), 3, np.array([10, 5]))
    2045
    """
    return int(TERM_UNITS * n_points * factors.size + n_windows * int(np.sum(counts)))


def _terms(hi: np.ndarray, lo: np.ndarray, code: int, m: int, n_terms: int) -> np.ndarray:
    """Term ``b`` of every ``b < n_terms``, as :func:`avar._kernels.dynamic.windows._term` forms it."""

    def part(k: int) -> tuple[np.ndarray, np.ndarray]:  # h_k, l_k: the k-th lag-m differences of hi, lo
        h = hi[k * m : k * m + n_terms] - hi[(k - 1) * m : (k - 1) * m + n_terms]
        low = (lo[k * m : k * m + n_terms] - lo[(k - 1) * m : (k - 1) * m + n_terms]).astype(np.float64)
        return h, low

    h1, l1 = part(1)
    h2, l2 = part(2)
    if code == 0:
        return (h2 - h1) + (l2 - l1)
    h3, l3 = part(3)
    if code != 4:
        return ((h3 - h2) - (h2 - h1)) + ((l3 - l2) - (l2 - l1))
    h4, l4 = part(4)
    return ((((h4 - h3) - (h3 - h2)) - ((h3 - h2) - (h2 - h1)))
            + (((l4 - l3) - (l3 - l2)) - ((l3 - l2) - (l2 - l1))))


def _valid(code: int, mode: int, bad: np.ndarray, m: int, n_terms: int) -> np.ndarray:
    """Whether each term avoids every gap (:func:`avar._kernels.dynamic.windows._valid`)."""
    reach = REACH[code] * m
    b = np.arange(n_terms)
    if mode == 2:
        last = b + reach if code < 2 else b + reach - 1
        return bad[last] == bad[b]
    if code >= 2:
        return bad[b + reach] == bad[b]
    ok = np.ones(n_terms, dtype=bool)
    for k in range(0, reach + 1, m):
        ok &= bad[b + k + 1] == bad[b + k]
    return ok


def _window_view(values: np.ndarray, starts: np.ndarray, count: int, stride: int) -> np.ndarray:
    """(windows, count) view: row w holds ``values[starts[w] + k stride]``, k < count (regular starts)."""
    step = int(starts[1] - starts[0]) if starts.size > 1 else 0
    first = values[int(starts[0]):]
    item = values.itemsize
    return as_strided(first, shape=(starts.size, count), strides=(step * item, stride * item), writeable=False)


def window_sums(hi: np.ndarray, lo: np.ndarray, code: int, m: int, stride: int, starts: np.ndarray, count: int,
                mode: int, bad: np.ndarray) -> WindowSums:
    """:func:`avar._kernels.dynamic.windows.window_sums` in NumPy (same arguments; the results
    returned): every window's sum of squared terms and number of terms used at level ``m``.
    ``starts`` must be evenly spaced (the windows of a dynamic deviation are).

    >>> hi = np.array([0.0, 1.0, 0.0, 2.0, 0.0, 1.0])
    >>> lo = np.zeros(6, dtype=np.float32)
    >>> res = window_sums(hi, lo, 0, 1, 1, np.array([0, 1]), 3, 0, np.zeros(1, dtype=np.int64))
    >>> res.sums.tolist(), res.counts.tolist()
    ([29.0, 34.0], [3, 3])
    """
    if starts.size > 2 and np.any(np.diff(starts) != starts[1] - starts[0]):
        raise ValueError("window_sums: starts must be evenly spaced")
    n_terms = hi.shape[0] - REACH[code] * m
    if starts.size == 0 or count <= 0:
        return WindowSums(np.zeros(starts.size), np.zeros(starts.size, dtype=np.int64))
    if int(starts[-1]) + (count - 1) * stride >= n_terms:
        raise ValueError(f"window_sums: the last window's terms reach past the record's {n_terms} terms")
    d = _terms(hi, lo, code, m, n_terms)
    squares = d * d
    if mode == 0:
        counts = np.full(starts.size, count, dtype=np.int64)
    else:
        ok = _valid(code, mode, bad, m, n_terms)
        squares = np.where(ok, squares, 0.0)
        counts = _window_view(ok.astype(np.int64), starts, count, stride).sum(axis=1)
    sums = _window_view(squares, starts, count, stride).sum(axis=1)
    return WindowSums(np.ascontiguousarray(sums), np.ascontiguousarray(counts, dtype=np.int64))
