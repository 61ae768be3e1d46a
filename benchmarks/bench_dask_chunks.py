"""Dask arrays with many small chunks against the NumPy path: time and peak memory.

Usage::

    python benchmarks/bench_dask_chunks.py [--n 1000000] [--chunks 1000] [--taus octave]

Each case runs in a fresh process (so that its peak RSS growth is its own):
``avar.avar(x)`` on a NumPy array, then ``avar.avar(dask.array.from_array(x,
chunks=C))``, and, to show that the graph stays bounded on the chunk-by-chunk
path too, the same with the in-memory fallback disabled. Printed per case: the
wall time, the peak RSS growth over the process after its imports and numba's
warm-up, and the ratio to the NumPy time. The acceptance of the hostile-input
issue: 1e6 samples in chunks of 1,000 within 2x the NumPy time + 2 s and under
500 MB of peak RSS growth.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys

CASE = r"""
import json, resource, sys, time
import numpy as np
import dask.array as da
import avar
from avar.stability.allan import dask as dask_backend

n, chunks, taus, mode = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4]
x = np.random.default_rng(1).standard_normal(n)
if mode == "out-of-core":
    dask_backend.IN_MEMORY_BYTES = 0  # as for a series larger than memory: rechunked, chunk by chunk
for values in (x[: n // 8], x):  # numba's compiled code loaded first, then the measured call
    data = values if mode == "numpy" else da.from_array(values, chunks=chunks)
    if values is not x:
        avar.avar(data, taus=taus)
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
start = time.perf_counter()
result = avar.avar(data, taus=taus)
seconds = time.perf_counter() - start
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"seconds": seconds, "growth_mb": (peak - before) / 1024, "allan0": float(result.allan[0])}))
"""


def run(n: int, chunks: int, taus: str, mode: str) -> dict:
    out = subprocess.run([sys.executable, "-c", CASE, str(n), str(chunks), taus, mode], check=True,
                         capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1_000_000, help="samples (default 1e6)")
    parser.add_argument("--chunks", type=int, default=1000, help="samples per Dask chunk (default 1000)")
    parser.add_argument("--taus", default="octave", help="tau grid (default octave)")
    args = parser.parse_args()
    numpy = run(args.n, args.chunks, args.taus, "numpy")
    print(f"{args.n} samples, Dask chunks of {args.chunks}, taus={args.taus}")
    print(f"{'path':<28}{'seconds':>10}{'peak RSS +MB':>14}{'x NumPy':>10}")
    for mode in ("numpy", "dask", "out-of-core"):
        got = numpy if mode == "numpy" else run(args.n, args.chunks, args.taus, mode)
        assert abs(got["allan0"] - numpy["allan0"]) <= 1e-12 * numpy["allan0"], (mode, got, numpy)
        print(f"{mode:<28}{got['seconds']:>10.3f}{got['growth_mb']:>14.1f}{got['seconds'] / numpy['seconds']:>10.1f}")
        if mode == "dask":
            budget = 2 * numpy["seconds"] + 2.0
            verdict = "within" if got["seconds"] <= budget and got["growth_mb"] < 500 else "OUTSIDE"
            print(f"{'':<28}{verdict} the budget: <= {budget:.2f} s (2x NumPy + 2 s), < 500 MB")


if __name__ == "__main__":
    main()
