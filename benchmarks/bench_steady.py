"""Steady-state call times in a process that compiled its kernels itself, against one that found them cached.

Usage::

    python benchmarks/bench_steady.py [--repeat 3] [--only "avar 1e4"] [--src OTHER_CHECKOUT/src]

Issue 39's warm regression check. For each case (``oadev`` and ``mdev`` of 1e6 samples,
``avar.avar`` of 1e4), two fresh interpreters run the same code: the first with a new,
empty ``NUMBA_CACHE_DIR`` (its kernels never compiled nor cached: the small-record NumPy
twins of :mod:`avar._kernels.runtime.paths` answer first, and compile once the process
turns hot), the second with the cache the first filled. Each makes one call, then as many
more as the case says (enough for the twins to turn hot: 100 calls of 1e6 samples, 3000
of 1e4), and prints the first call, the median of calls 2-11 and that of the last ten: the
"cold-cache" process must end at the "warm-cache" one's speed. Ratios in the same run
(cold-cache median / warm-cache median); repeated ``--repeat`` times, medians reported.
``--src`` runs another checkout's code (e.g. an export of the previous commit), for a
before/after comparison in one session.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

SRC = Path(__file__).resolve().parent.parent / "src"

CASES = {
    "oadev 1e6": (10**6, "avar.oadev(x)", 100),
    "mdev 1e6": (10**6, "avar.mdev(x)", 100),
    "avar 1e4": (10**4, "avar.avar(x, rate=100.0)", 3000),
}
CHILD = """
import time
import numpy as np
import avar
x = np.random.default_rng(1).standard_normal({n})
times = []
for _ in range({calls} + 1):
    start = time.perf_counter()
    {call}
    times.append(time.perf_counter() - start)
print(times[0], float(np.median(times[-10:])), float(np.median(times[1:11])))
"""


def run(code: str, cache: str, src: Path = SRC) -> list[float]:
    env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": f"{src}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    env.pop("AVAR_KERNEL_PATH", None)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return [float(v) for v in out.stdout.split()[-3:]]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="pairs of processes per case (medians reported)")
    parser.add_argument("--src", type=Path, default=SRC, help="the package source to run (default: this checkout's)")
    parser.add_argument("--only", nargs="+", metavar="CASE", help="cases to run (e.g. 'avar 1e4')")
    args = parser.parse_args()
    print("| case | cold-cache first (s) | cold-cache calls 2-11 (ms) | cold-cache last 10 (ms) "
          "| warm-cache last 10 (ms) | cold / warm (last 10) |")
    print("|---|---|---|---|---|---|")
    for name, (n, call, calls) in CASES.items():
        if args.only and name not in args.only:
            continue
        code = CHILD.format(n=n, calls=calls, call=call)
        rows = []
        for _ in range(args.repeat):
            with tempfile.TemporaryDirectory() as cache:
                cold = run(code, cache, args.src)
                warm = run(code, cache, args.src)
            rows.append((cold[0], cold[2], cold[1], warm[1], cold[1] / warm[1]))
        first, early, late, warm, ratio = np.median(np.array(rows), axis=0)
        print(f"| {name} | {first:.2f} | {early * 1e3:.2f} | {late * 1e3:.2f} | {warm * 1e3:.2f} | {ratio:.2f} |",
              flush=True)


if __name__ == "__main__":
    main()
