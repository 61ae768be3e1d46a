"""Dynamic deviations: ``avar.dadev`` of 1e6 points (windows of 1e4 every 1e3) next to ``avar.oadev``.

The dynamic deviation computes OADEV, with its noise identification, EDF and chi-squared bounds,
in each of 991 windows of 10,000 frequency samples, at the octave taus up to a quarter of the
window (m = 1 .. 2048, 12 levels), plus the whole record's OADEV (the reference of
``unstable()``). Both are timed in the same run on the same white FM record (median of repeated
calls after a warm-up call, :mod:`timing`), and the script prints their times and ratio, and the
time per window. ``--check`` also compares a few windows with ``avar.oadev`` of their samples.

How: each level's window sums come from compensated prefix sums of the record's squared second
differences (O(N) per level for all windows together, the levels on the threads); the noise of
each window is identified on its own phase (about half the time).

Run: ``python benchmarks/bench_dynamic.py [--n 1000000] [--window 10000] [--step 1000] [--check]``.
Measured (2 cores, a shared machine with other jobs running, numba cache warm): dadev 0.6-1.2 s,
oadev of the whole record 0.06 s, about 1 ms per window.
"""

from __future__ import annotations

import argparse

import numpy as np
from timing import median_time

import avar


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1_000_000)
    parser.add_argument("--window", type=int, default=10_000)
    parser.add_argument("--step", type=int, default=1_000)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--check", action="store_true", help="compare windows with avar.oadev of their samples")
    args = parser.parse_args()
    y = np.random.default_rng(0).standard_normal(args.n) * 1e-12  # white FM, 1e-12 at tau0

    result = avar.dadev(y, window=args.window, step=args.step)
    dynamic = median_time(lambda: avar.dadev(y, window=args.window, step=args.step), args.repeat)
    whole = median_time(lambda: avar.oadev(y), args.repeat)
    print(f"N = {args.n}, window {args.window}, step {args.step}: {result.n_windows} windows x "
          f"{len(result.taus)} taus (m = 1 .. {result.averaging_factors[-1]})")
    print(f"  avar.dadev        {dynamic:8.3f} s   ({1e3 * dynamic / result.n_windows:.2f} ms per window)")
    print(f"  avar.oadev (all)  {whole:8.3f} s")
    print(f"  ratio             {dynamic / whole:8.1f}x")
    if args.check:
        worst = 0.0
        for w in np.linspace(0, result.n_windows - 1, 5).astype(int).tolist():
            start = int(result.starts[w])
            alone = avar.oadev(y[start:start + args.window], taus=result.taus)
            worst = max(worst, float(np.max(np.abs(result.deviation[w] / alone.deviation - 1))))
        print(f"  largest relative difference from avar.oadev of 5 windows: {worst:.1e}")


if __name__ == "__main__":
    main()
