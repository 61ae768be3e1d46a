"""Timing shared by the benchmark scripts (run as ``python benchmarks/NAME.py``)."""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np


def median_time(function: Callable[[], object], repeat: int) -> float:
    """Median wall time (s) of ``repeat`` calls, after one warm-up call (numba compilation, page cache)."""
    function()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return float(np.median(times))
