"""Time ``import avar`` against ``import numpy`` in fresh interpreters.

Usage::

    python benchmarks/bench_import.py [--repeat 7]

Each statement runs in ``--repeat`` fresh processes (``python -X importtime``
is not used: the wall time of the whole process start is what a user waits
for); the medians of both, measured in this run, and their ratio are printed.
A third line times the first real call, ``avar.avar`` on 10^4 samples, which
loads NumPy, numba and the compiled kernels on demand.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

STATEMENTS = {
    "python -c pass": "pass",
    "import numpy": "import numpy",
    "import avar": "import avar",
    "import avar; avar.avar(1e4 samples)": "import avar, numpy; avar.avar(numpy.ones(10_000))",
}


def wall_time(code: str) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="fresh processes per statement (default 7)")
    args = parser.parse_args()
    wall_time("import avar, numpy; avar.avar(numpy.ones(100))")  # warm the numba cache and the page cache
    medians = {}
    for label, code in STATEMENTS.items():
        medians[label] = statistics.median(wall_time(code) for _ in range(args.repeat))
    print(f"| statement | median of {args.repeat} fresh processes |")
    print("|---|---|")
    for label, value in medians.items():
        print(f"| `{label}` | {1000 * value:.1f} ms |")
    ratio = medians["import avar"] / medians["import numpy"]
    print(f"\nimport avar / import numpy: {ratio:.2f}x (target < 3x)")


if __name__ == "__main__":
    main()
