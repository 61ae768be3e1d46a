"""The modified Hadamard total deviation's level sums (numba), window by window.

Nothing here validates input: :mod:`avar.stability.total.mhtot` does that once and calls
:func:`level_sums` on clean, gap-filled phase ``x`` (0-based, N points; scaled, its mean
frequency removed: the statistic is blind to both). The tests check it against a plain
loop over the definition.

Window n = 0 .. N - 4m of level m holds the L = 3m + 1 phase points x_n .. x_{n+3m}, less
the line through the means of their halves (the first floor(L / 2) points and the rest:
slope = (mean_2 - mean_1) / (L / 2)), extended by uninverted even reflection to the 3L
points (rev w, w, rev w). Its term is::

    T(n) = sum_{j=0}^{5m+3} A_j^2,   A_j = sum_{i=j}^{j+m-1} (e_i - 3 e_{i+m} + 3 e_{i+2m} - e_{i+3m}),

the 5m + 4 m-point sums of the 6m + 3 third differences of the extension e, formed as
differences of the running sum of those third differences. Each window is read less its first
point x_n (a constant changes no difference; without it, on smooth data, the values would carry
the record's size and lose digits to it). A window costs O(m), a level
O(N m); the windows run in tasks of :data:`CHUNK` on every thread, their sums added in task
order (the result does not depend on the number of threads). That direct loop sums the small
levels; a level whose work, (windows avoiding the gaps) x (m + 4), exceeds :data:`FAST_WORK`
is summed in O(N) by the blocked expansion of
:mod:`avar._kernels.total.mhtot_blocks` (exact up to rounding: ~1e-13 from this loop).

Gaps: ``bad`` is the prefix count of missing values of the input (empty when there is none),
``shift`` 0 for phase data, 1 for frequency data (as :mod:`avar._kernels.total.windows`): a
window whose points touch a gap is skipped.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.runtime.tasks import run_ranges
from avar._kernels.total.mhtot_blocks import BLOCK_KERNELS
from avar._kernels.total.mhtot_blocks import level_sum as blocked_level_sum
from avar._kernels.total.windows import LevelSum, LevelSums

#: Windows per task: fixed, so the sums do not depend on the number of threads.
CHUNK = 256


def terms_per_window(m: int) -> int:
    """The number of m-point sums A_j of one window: 5m + 4."""
    return 5 * int(m) + 4


@njit(cache=True, nogil=True)
def _task_range(x, m, bad, shift, n_windows, first_task, stop_task, sums, counts):
    """Tasks ``first_task .. stop_task - 1``: each sums :data:`CHUNK` windows' terms."""
    span = 3 * m + 1
    half = span // 2
    n_third = 3 * span - 3 * m
    n_sums = n_third - m + 1
    ext = np.empty(3 * span)
    run = np.empty(n_third + 1)
    for task in range(first_task, stop_task):
        total = 0.0
        used = 0
        for n in range(task * CHUNK, min(n_windows, (task + 1) * CHUNK)):
            if bad.shape[0] and bad[n + span - shift] - bad[n] != 0:
                continue
            base = x[n]  # (a constant changes nothing; without it the values carry the record's size)
            first = 0.0
            last = 0.0
            for k in range(half):
                first += x[n + k] - base
            for k in range(half, span):
                last += x[n + k] - base
            slope = (last / (span - half) - first / half) / (span / 2.0)
            for k in range(span):
                value = (x[n + k] - base) - slope * k
                ext[span - 1 - k] = value
                ext[span + k] = value
                ext[3 * span - 1 - k] = value
            acc = 0.0
            run[0] = 0.0
            for i in range(n_third):
                acc += (ext[i] - 3.0 * ext[i + m]) + (3.0 * ext[i + 2 * m] - ext[i + 3 * m])
                run[i + 1] = acc
            window = 0.0
            for j in range(n_sums):
                a = run[j + m] - run[j]
                window += a * a
            total += window
            used += 1
        sums[task - first_task] = total
        counts[task - first_task] = used


def level_sum(x: np.ndarray, m: int, bad: np.ndarray, shift: int) -> LevelSum:
    """Sum of the terms T(n) of the windows of level ``m`` that avoid the gaps, and their number."""
    n_windows = max(0, x.shape[0] - 4 * int(m) + 1)
    n_tasks = (n_windows + CHUNK - 1) // CHUNK
    sums = np.zeros(n_tasks)
    counts = np.zeros(n_tasks, dtype=np.int64)

    def tasks(first_task: int, stop_task: int) -> None:
        _task_range(x, int(m), bad, shift, n_windows, first_task, stop_task, sums[first_task:stop_task],
                    counts[first_task:stop_task])

    run_ranges(n_tasks, tasks)
    total = 0.0
    for part in sums.tolist():  # in task order
        total += part
    return LevelSum(total, int(counts.sum()))


#: The compiled kernel of the direct loop.
DIRECT_KERNELS = (_task_range,)
#: Levels whose (clean windows) x (m + 4) exceeds this take the blocked expansion (25 to 75 ns
#: per window, and ~0.6 ms of tables per level); the others the direct loop (~20 + 18 m ns per window).
FAST_WORK = 1 << 15


def clean_windows(n_points: int, m: int, bad: np.ndarray, shift: int) -> np.ndarray | None:
    """One flag per window of level ``m``: whether its points n .. n + 3m avoid every gap (``None``
    without gaps)."""
    n_windows = max(0, n_points - 4 * int(m) + 1)
    if not bad.shape[0]:
        return None
    stop = 3 * int(m) + 1 - shift
    return bad[stop : stop + n_windows] == bad[:n_windows]


def blocked(m: int, used: int) -> bool:
    """Whether a level of factor ``m`` with ``used`` clean windows takes the blocked expansion."""
    return used * (m + 4) > FAST_WORK


def level_kernels(n_points: int, factors: np.ndarray, gaps: bool) -> tuple:
    """The compiled kernels :func:`level_sums` would run on ``n_points`` phase points (with gaps,
    a level may have fewer clean windows than its size says: both may run)."""
    fast = direct = False
    for m in factors.tolist():
        if blocked(m, max(0, n_points - 4 * m + 1)):
            fast = True
            direct = direct or gaps
        else:
            direct = True
    return (BLOCK_KERNELS if fast else ()) + (DIRECT_KERNELS if direct else ())


def level_sums(x: np.ndarray, factors: np.ndarray, bad: np.ndarray, shift: int) -> LevelSums:
    """:func:`level_sum` at every factor (the large levels by the blocked expansion): the sums
    and the windows used."""
    sums = np.zeros(factors.shape[0])
    counts = np.zeros(factors.shape[0], dtype=np.int64)
    for level, m in enumerate(factors.tolist()):
        clean = clean_windows(x.shape[0], m, bad, shift)
        used = max(0, x.shape[0] - 4 * m + 1) if clean is None else int(np.count_nonzero(clean))
        if blocked(m, used):
            sums[level], counts[level] = blocked_level_sum(x, m, clean), used
        else:
            sums[level], counts[level] = level_sum(x, m, bad, shift)
    return LevelSums(sums, counts)
