"""Time ``avar(imu)`` on a 6-channel IMU against six single-column ``avar`` calls.

The IMU path computes all channels in one pass of the kernels; the acceptance
criterion is that it takes at most 1.2 times the sum of the single-column
calls (and gives the same numbers). Timings are the median of 5 runs after a
warm-up run (which also compiles the kernels), the two calls interleaved.

Usage::

    PYTHONPATH=src python benchmarks/bench_imu.py [N ...]
"""

from __future__ import annotations

import statistics
import sys
import time
from collections.abc import Callable

import numpy as np

import avar
from avar.imu import IMU

CHANNELS = 6
REPEATS = 5
LIMIT = 1.2


def median_times(functions: list[Callable[[], object]], repeats: int = REPEATS) -> list[tuple[float, float]]:
    """Median (wall, CPU) time of each function over ``repeats`` calls after one warm-up call.

    The calls are interleaved (a, b, a, b, ...) so that a change in machine
    load affects all functions alike. CPU time is the process time of all
    threads (user + system), which other processes on the machine do not
    inflate the way they inflate wall time.
    """
    for function in functions:
        function()
    times: list[list[tuple[float, float]]] = [[] for _ in functions]
    for _ in range(repeats):
        for function, record in zip(functions, times):
            wall, cpu = time.perf_counter(), time.process_time()
            function()
            record.append((time.perf_counter() - wall, time.process_time() - cpu))
    return [
        (statistics.median(w for w, _ in record), statistics.median(c for _, c in record)) for record in times
    ]


def simulate(n: int, seed: int = 0) -> np.ndarray:
    """White noise plus a random walk, shape (n, CHANNELS)."""
    rng = np.random.default_rng(seed)
    return rng.standard_normal((n, CHANNELS)) + np.cumsum(rng.standard_normal((n, CHANNELS)) * 1e-3, axis=0)


def compare(n: int, kind: str = "mo") -> dict[str, float]:
    """Wall times (s) of the IMU call and of the single-column calls, the wall
    and CPU time ratios, and the largest relative difference of the results."""
    data = simulate(n)
    imu = IMU(data, 100.0, gyro=[0, 1, 2], accel=[3, 4, 5])
    columns = [np.ascontiguousarray(data[:, j]) for j in range(CHANNELS)]
    joint = avar.avar(imu, type=kind)
    singles = [avar.avar(column, type=kind, freq=100.0) for column in columns]
    difference = max(
        float(np.max(np.abs(joint[name].allan / single.allan - 1.0)))
        for name, single in zip(imu.channels, singles)
    )
    t_imu, t_single = median_times(
        [
            lambda: avar.avar(imu, type=kind),
            lambda: [avar.avar(column, type=kind, freq=100.0) for column in columns],
        ]
    )
    return {
        "imu": t_imu[0],
        "single": t_single[0],
        "ratio": t_imu[0] / t_single[0],
        "cpu_ratio": t_imu[1] / t_single[1],
        "difference": difference,
    }


def main(sizes: list[int]) -> int:
    print(f"avar(imu) vs {CHANNELS} single-column avar() calls, median of {REPEATS} after warm-up")
    print(f"{'N':>10} {'type':>4} {'avar(imu) s':>12} {'sum single s':>13} {'ratio':>6} {'CPU ratio':>9} {'max rel diff':>13}")
    worst = 0.0
    for n in sizes:
        for kind in ("mo", "to"):
            r = compare(n, kind)
            worst = max(worst, r["ratio"])
            print(f"{n:>10} {kind:>4} {r['imu']:>12.4f} {r['single']:>13.4f} {r['ratio']:>6.2f} {r['cpu_ratio']:>9.2f} {r['difference']:>13.2e}")
    verdict = "OK" if worst <= LIMIT else "SLOWER THAN ALLOWED"
    print(f"worst wall-time ratio {worst:.2f} (limit {LIMIT}): {verdict}")
    return 0 if worst <= LIMIT else 1


if __name__ == "__main__":
    sizes = [int(float(arg)) for arg in sys.argv[1:]] or [10**6, 10**7]
    sys.exit(main(sizes))
