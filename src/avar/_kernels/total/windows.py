"""Kernels of the total and Theo statistics (numba): MTOTDEV, HTOTDEV and Theo1.

Nothing here validates input: :mod:`avar.stability.total.deviations` and
:mod:`avar.stability.total.theoh` do that once and call these kernels on clean,
gap-filled, detrended phase ``x`` (0-based, N points). The tests check every
kernel against a plain loop over the NIST SP 1065 formula.

Gaps: ``bad`` is the prefix count of missing values of the input (length of
the input + 1; empty when there is none) and ``shift`` is 0 for phase data
(phase points are missing) and 1 for frequency data (the increment
``x[k + 1] - x[k]`` is missing). A term whose phase points ``start .. stop - 1``
touch a gap is skipped; the kernels return the sum and the number of terms used.

Which path runs: an MTOTDEV or HTOTDEV level whose work, (windows avoiding the
gaps) x (m + 10), exceeds :data:`FAST_WORK` (every octave level from N ~ 3000 on)
is summed in O(N) by the blocked expansion of :mod:`avar._kernels.total.blocks`
(exact up to rounding, ~1e-13 from the direct loop), over each run of windows
that avoid the gaps. Smaller levels (where the expansion's ~1 ms of tables per
level costs more) take the direct loop here: each window is detrended and
summed through the running sum of its 9m-point reflected extension, read from
the window's own running sum (one pass, no extension is built), so a window
costs O(m) and a level O(N m). Theo1 always takes the direct loop here (its own
kernels, :func:`_theo1_serial`, so that Theo1 compiles none of MTOTDEV's loops),
O(N m / 2) per level (:mod:`avar.stability.total.deviations` sends its long gap-free levels
to :mod:`avar._kernels.total.theo1`). A level's terms run in tasks of
:data:`CHUNK` terms whose sums are added in task order; large levels run the
tasks on every thread (:func:`avar._kernels.runtime.tasks.run_ranges`) with the same result
as the serial loop.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from avar._kernels.runtime.tasks import run_ranges
from avar._kernels.total.blocks import level_sum


class LevelSum(NamedTuple):
    """One level's double sum and the number of terms (windows, or Theo1's outer terms) in it."""

    total: float
    n_terms: int


class LevelSums(NamedTuple):
    """Every level's double sum and the number of terms in it."""

    sums: np.ndarray
    n_terms: np.ndarray


@njit(cache=True)
def _clean(bad: np.ndarray, shift: int, start: int, stop: int) -> bool:
    """Whether phase points ``start .. stop - 1`` avoid every gap."""
    if bad.shape[0] == 0:
        return True
    return bad[stop - shift] - bad[start] == 0


@njit(cache=True)
def _detrended_running_sum(values: np.ndarray, start: int, m: int, run: np.ndarray) -> None:
    """run[k] = sum_{i<k} w_i, k = 0 .. 3m, of the 3m values from ``start`` less the line
    through the means of their first and last halves (floor(3m / 2) points each, the middle
    point left out when 3m is odd), centred (run[3m] = 0 up to rounding)."""
    span = 3 * m
    half = span // 2
    gap = span - half  # distance between the two halves' centres
    first = 0.0
    last = 0.0
    for k in range(half):
        first += values[start + k]
        last += values[start + gap + k]
    total = first + last + (values[start + half] if gap > half else 0.0)
    slope = (last - first) / half / gap
    mean = (total - slope * (span * (span - 1) / 2.0)) / span
    acc = 0.0
    run[0] = 0.0
    for k in range(span):
        acc += (values[start + k] - mean) - slope * k
        run[k + 1] = acc


@njit(cache=True)
def _sixth(a0, o0, c0, a1, o1, c1, a2, o2, c2, a3, o3, c3, constant, first, stop):
    """sum_j (constant + sum_k c_k a_k[j + o_k])**2 over j = first .. stop - 1."""
    acc = 0.0
    for j in range(first, stop):
        d = (constant + c3 * a3[j + o3] + c2 * a2[j + o2]) + (c1 * a1[j + o1] + c0 * a0[j + o0])
        acc += d * d
    return acc


@njit(cache=True)
def _part(run: np.ndarray, back: np.ndarray, span: int, part: int, shift: int) -> tuple:
    """The array, offset and sign reading the extension's running sum at j + ``shift`` in ``part``."""
    if part == 1:
        return run, shift - span, 1.0
    return back, shift - 2 * span * (part // 2), -1.0


@njit(cache=True)
def _reflected_terms(run: np.ndarray, back: np.ndarray, m: int) -> float:
    """sum_{j=0}^{6m-1} (A_j - 2 B_j + C_j)**2 over the 9m-point extension (rev w, w, rev w)
    of a 3m-point window w with running sum ``run`` (A_j, B_j, C_j: sums of m consecutive
    points from j, j + m, j + 2m). The extension's running sum at i is read from ``run`` and
    ``back`` (``run`` reversed): S - back[i] (i <= 3m), S + run[i - 3m] (i <= 6m), 3 S -
    back[i - 6m], S = run[3m]. Over each sixth of the j range every index j + k m (k = 0 .. 3)
    stays in one part, so the loop reads four arrays forward at fixed offsets:
    A_j - 2 B_j + C_j = E(j + 3m) - 3 E(j + 2m) + 3 E(j + m) - E(j)."""
    span = 3 * m
    total = run[span]
    acc = 0.0
    for sixth in range(6):
        p0, p1, p2, p3 = sixth // 3, (sixth + 1) // 3, (sixth + 2) // 3, (sixth + 3) // 3
        constant = total * ((1.0 if p3 < 2 else 3.0) - 3.0 * (1.0 if p2 < 2 else 3.0)
                            + 3.0 * (1.0 if p1 < 2 else 3.0) - (1.0 if p0 < 2 else 3.0))
        a0, o0, s0 = _part(run, back, span, p0, 0)
        a1, o1, s1 = _part(run, back, span, p1, m)
        a2, o2, s2 = _part(run, back, span, p2, 2 * m)
        a3, o3, s3 = _part(run, back, span, p3, 3 * m)
        acc += _sixth(a0, o0, -s0, a1, o1, 3.0 * s1, a2, o2, -3.0 * s2, a3, o3, s3, constant,
                      sixth * m, (sixth + 1) * m)
    return acc


#: Terms per task: fixed, so the sums do not depend on the number of threads.
CHUNK = 512


@njit(cache=True, nogil=True)
def _window_range(kind: int, values: np.ndarray, m: int, bad: np.ndarray, shift: int, first: int,
                  last: int) -> tuple[float, int]:
    """The windows ``first .. last - 1`` of one level (``kind`` 0 MTOTDEV on phase, 1 HTOTDEV on
    frequency): their sum and how many avoid the gaps."""
    total = 0.0
    count = 0
    span = 3 * m
    run = np.empty(span + 1)
    back = np.empty(span + 1)
    for start in range(first, last):
        if not _clean(bad, shift, start, start + span + kind):
            continue
        _detrended_running_sum(values, start, m, run)
        for k in range(span + 1):
            back[k] = run[span - k]
        total += _reflected_terms(run, back, m) / (6.0 * m * m * m)
        count += 1
    return total, count


@njit(cache=True, nogil=True)
def _theo1_range(values: np.ndarray, m: int, bad: np.ndarray, shift: int, first: int, last: int) -> tuple[float, int]:
    """Theo1's outer terms ``first .. last - 1`` at factor ``m``: their sum and how many avoid the
    gaps. Its own kernel (not a branch of :func:`_window_range`): a Theo1 call compiles only this
    loop, not MTOTDEV's reflected windows."""
    total = 0.0
    count = 0
    half = m // 2
    for start in range(first, last):
        if not _clean(bad, shift, start, start + m + 1):
            continue
        acc = 0.0
        for d in range(half):
            t = (values[start] - values[start - d + half]) + (values[start + m] - values[start + d + half])
            acc += t * t / (half - d)
        total += acc
        count += 1
    return total, count


@njit(cache=True, nogil=True)
def _level_serial(kind: int, values: np.ndarray, m: int, bad: np.ndarray, shift: int,
                  n_terms: int) -> tuple[float, int]:
    n_tasks = (n_terms + CHUNK - 1) // CHUNK
    total = 0.0
    count = 0
    for task in range(n_tasks):
        first = task * CHUNK
        part, used = _window_range(kind, values, m, bad, shift, first, min(n_terms, first + CHUNK))
        total += part
        count += used
    return total, count


def _level_threaded(kind: int, values: np.ndarray, m: int, bad: np.ndarray, shift: int,
                    n_terms: int) -> tuple[float, int]:
    """:func:`_level_serial` with its tasks spread over the threads (:mod:`avar._kernels.runtime.tasks`);
    their sums are added in task order, so the result is the same on any number of threads."""
    n_tasks = (n_terms + CHUNK - 1) // CHUNK
    sums = np.zeros(n_tasks)
    counts = np.zeros(n_tasks, dtype=np.int64)

    def tasks(first_task: int, stop_task: int) -> None:
        if kind == 2:
            sums[first_task:stop_task], counts[first_task:stop_task] = _theo1_tasks(
                values, m, bad, shift, n_terms, first_task, stop_task)
        else:
            sums[first_task:stop_task], counts[first_task:stop_task] = _task_range(
                kind, values, m, bad, shift, n_terms, first_task, stop_task)

    run_ranges(n_tasks, tasks)
    total = 0.0
    for part in sums.tolist():  # in task order, as the serial loop adds them
        total += part
    return total, int(counts.sum())


@njit(cache=True, nogil=True)
def _task_range(kind: int, values: np.ndarray, m: int, bad: np.ndarray, shift: int, n_terms: int,
                first_task: int, stop_task: int) -> tuple[np.ndarray, np.ndarray]:
    """The sums and counts of tasks ``first_task .. stop_task - 1`` (of :data:`CHUNK` terms each)."""
    sums = np.zeros(stop_task - first_task)
    counts = np.zeros(stop_task - first_task, dtype=np.int64)
    for task in range(first_task, stop_task):
        first = task * CHUNK
        sums[task - first_task], counts[task - first_task] = _window_range(
            kind, values, m, bad, shift, first, min(n_terms, first + CHUNK))
    return sums, counts


@njit(cache=True, nogil=True)
def _theo1_serial(values: np.ndarray, m: int, bad: np.ndarray, shift: int, n_terms: int) -> tuple[float, int]:
    """:func:`_level_serial` of Theo1 (its own kernel: compiles :func:`_theo1_range` only)."""
    n_tasks = (n_terms + CHUNK - 1) // CHUNK
    total = 0.0
    count = 0
    for task in range(n_tasks):
        first = task * CHUNK
        part, used = _theo1_range(values, m, bad, shift, first, min(n_terms, first + CHUNK))
        total += part
        count += used
    return total, count


@njit(cache=True, nogil=True)
def _theo1_tasks(values: np.ndarray, m: int, bad: np.ndarray, shift: int, n_terms: int,
                 first_task: int, stop_task: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_task_range` of Theo1."""
    sums = np.zeros(stop_task - first_task)
    counts = np.zeros(stop_task - first_task, dtype=np.int64)
    for task in range(first_task, stop_task):
        first = task * CHUNK
        sums[task - first_task], counts[task - first_task] = _theo1_range(
            values, m, bad, shift, first, min(n_terms, first + CHUNK))
    return sums, counts


#: The compiled kernels a direct MTOTDEV or HTOTDEV level runs (serially: small levels).
DIRECT_KERNELS = (_level_serial,)
#: The compiled kernels a direct Theo1 level runs (serially: small levels).
THEO1_DIRECT_KERNELS = (_theo1_serial,)


#: Levels with more window points than this (terms x window length) run on every thread.
PARALLEL_WORK = 1 << 24


#: MTOTDEV and HTOTDEV levels with (windows avoiding the gaps) x (m + 10) above this take the
#: blocked O(N) expansion of :mod:`avar._kernels.total.blocks`; smaller ones the direct loop,
#: which is cheaper there (the expansion costs ~1 ms of tables per level).
FAST_WORK = 1 << 15


def _level(kind: int, values: np.ndarray, m: int, bad: np.ndarray, shift: int, n_terms: int) -> tuple[float, int]:
    """One level's sum over its ``n_terms`` terms, in tasks of :data:`CHUNK` summed in order
    (serially for small levels: threads cost more than they save there)."""
    if kind < 2 and n_terms > 0:
        clean = None
        used = n_terms
        if bad.shape[0]:  # the windows n whose points n .. n + 3m - 1 + kind avoid every gap
            stop = 3 * m + kind - shift
            clean = bad[stop : stop + n_terms] == bad[:n_terms]
            used = int(np.count_nonzero(clean))
        if used * (m + 10) > FAST_WORK:
            return level_sum(values, m, clean), used
    work = n_terms * m * (1 if kind == 2 else 3)
    if work > PARALLEL_WORK and n_terms > CHUNK:
        return _level_threaded(kind, values, m, bad, shift, n_terms)
    if kind == 2:
        return _theo1_serial(values, m, bad, shift, n_terms)
    return _level_serial(kind, values, m, bad, shift, n_terms)


def mtot_sum(x: np.ndarray, m: int, bad: np.ndarray, shift: int) -> LevelSum:
    """MTOTDEV's double sum at factor m: sum over the windows n = 0 .. N - 3m of
    (1 / (6 m)) sum_j ((A_j - 2 B_j + C_j) / m)**2 on the phase window x[n .. n + 3m - 1]
    (detrended, reflected); and the number of windows used."""
    return LevelSum(*_level(0, x, int(m), bad, shift, max(0, x.shape[0] - 3 * int(m) + 1)))


def htot_sum(x: np.ndarray, m: int, bad: np.ndarray, shift: int) -> LevelSum:
    """HTOTDEV's double sum at factor m on the frequency y_k = x[k + 1] - x[k]: sum over the
    windows n = 0 .. M - 3m (M = N - 1) of (1 / (6 m)) sum_j ((A_j - 2 B_j + C_j) / m)**2
    on y[n .. n + 3m - 1] (detrended, reflected); and the number of windows used."""
    y = np.ascontiguousarray(np.diff(x))
    return LevelSum(*_level(1, y, int(m), bad, shift, max(0, y.shape[0] - 3 * int(m) + 1)))


def theo1_sum(x: np.ndarray, m: int, bad: np.ndarray, shift: int) -> LevelSum:
    """Theo1's double sum at even factor m::

        sum_{i=0}^{N-m-1} sum_{d=0}^{m/2-1} ((x_i - x_{i-d+m/2}) + (x_{i+m} - x_{i+d+m/2}))**2 / (m/2 - d)

    and the number of outer terms i used."""
    return LevelSum(*_level(2, x, int(m), bad, shift, max(0, x.shape[0] - int(m))))


def level_sums(kind: int, x: np.ndarray, factors: np.ndarray, bad: np.ndarray, shift: int) -> LevelSums:
    """``kind`` 0: :func:`mtot_sum`, 1: :func:`htot_sum`, 2: :func:`theo1_sum` at every factor."""
    values = np.ascontiguousarray(np.diff(x)) if kind == 1 else x
    sums = np.zeros(factors.shape[0])
    counts = np.zeros(factors.shape[0], dtype=np.int64)
    for level, m in enumerate(factors.tolist()):
        n_terms = values.shape[0] - (3 * m - 1 if kind < 2 else m)
        sums[level], counts[level] = _level(kind, values, m, bad, shift, max(0, n_terms))
    return LevelSums(sums, counts)
