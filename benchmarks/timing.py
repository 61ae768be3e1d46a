"""Timing shared by the benchmark scripts (run as ``python benchmarks/NAME.py``)."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

#: Short calls are repeated until about this many seconds (at most MAX_REPEAT times):
#: a median of three 10 ms calls on a shared machine is mostly noise.
BUDGET = 0.5
MAX_REPEAT = 25


def median_time(function: Callable[[], object], repeat: int) -> float:
    """Median wall time (s) of at least ``repeat`` calls, after one warm-up call (numba
    compilation, page cache); short calls are repeated more (same rule for every peer)."""
    function()
    start = time.perf_counter()
    function()
    first = time.perf_counter() - start
    times = [first]
    count = max(repeat, min(MAX_REPEAT, int(BUDGET / max(first, 1e-9))))
    for _ in range(count - 1):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return float(np.median(times))
