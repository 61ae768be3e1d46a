"""Time ``avlr(x, wn=..., rw=..., ci=True, B=100)`` (fit plus parametric bootstrap).

Targets of the AVLR issue: under 2 s at N = 10**5 and under 60 s at
N = 3 * 10**6. The series is WN(sigma2 = 1) + RW(gamma2 = 1e-7); the first
(warm-up) call also compiles the kernels and is reported separately.
Timings are the median of ``REPEATS`` calls.

Usage::

    PYTHONPATH=src python benchmarks/bench_avlr.py [N ...]
"""

from __future__ import annotations

import statistics
import sys
import time

from avar.fit.avlr import avlr
from avar.models import RW, WN

REPEATS = 3
LIMITS = {100_000: 2.0, 3_000_000: 60.0}
MODEL = WN(sigma2=1.0) + RW(gamma2=1e-7)


def selections(n: int) -> dict[str, range]:
    """WN on scales 1-8 and RW on the last five scales of the octave grid."""
    levels = n.bit_length() - 2
    return {"wn": range(1, 9), "rw": range(levels - 4, levels + 1)}


def time_fit(n: int, repeats: int = REPEATS) -> tuple[float, float]:
    """(first call, median of the following calls) in seconds."""
    x = MODEL.simulate(n, seed=1)
    scales = selections(n)
    times = []
    for i in range(repeats + 1):
        start = time.perf_counter()
        avlr(x, **scales, ci=True, B=100, seed=i)
        times.append(time.perf_counter() - start)
    return times[0], statistics.median(times[1:])


def main(argv: list[str]) -> None:
    sizes = [int(float(a)) for a in argv[1:]] or list(LIMITS)
    print("avlr(x, wn=1:8, rw=<last 5 scales>, ci=True, B=100), WN(1) + RW(1e-7)")
    for n in sizes:
        first, median = time_fit(n, REPEATS if n <= 1_000_000 else 1)
        limit = LIMITS.get(n)
        verdict = "" if limit is None else f"  target < {limit:g} s: {'PASS' if median < limit else 'FAIL'}"
        print(f"  N = {n:>9,}: {median:7.2f} s (first call {first:.2f} s){verdict}")


if __name__ == "__main__":
    main(sys.argv)
