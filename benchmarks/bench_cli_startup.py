"""Cold and warm wall times of ``avar demo`` and ``avar report``, each in a fresh process.

Usage::

    nice python benchmarks/bench_cli_startup.py [--repeat 3] [--hours 2] [--rate 200]

A 6-axis IMU log (``time gx gy gz ax ay az``, white noise plus a random walk, rad/s and
m/s^2) of ``--hours`` at ``--rate`` Hz is written to a temporary CSV. Each command runs
as ``python -m avar ...`` in a new interpreter:

* **cold**: with a new, empty ``NUMBA_CACHE_DIR``, so numba compiles every kernel the
  command uses (what a user waits for on the first run);
* **warm**: with the cache the cold run filled (every later run).

The medians of ``--repeat`` runs are printed, with the warm/cold ratio and whether the
first-run notice appeared on stderr (it must on a cold cache, and must not on a warm one).
The command runs with the code of this checkout (``src`` first on ``PYTHONPATH``).
Acceptance (issue 25): a cold ``avar report`` of the 2 h 200 Hz log under 10 s.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

SRC = Path(__file__).resolve().parent.parent / "src"
NOTICE = "compiling"


def write_log(path: Path, hours: float, rate: float, seed: int = 7) -> int:
    """A 6-axis log of white noise plus a small random walk per axis; returns its rows."""
    n = int(hours * 3600 * rate)
    rng = np.random.default_rng(seed)
    t = np.arange(n) / rate
    columns = [t]
    for sigma, gamma in [(1e-3, 1e-6)] * 3 + [(2e-2, 1e-5)] * 3:
        columns.append(sigma * rng.standard_normal(n) + np.cumsum(gamma * rng.standard_normal(n)))
    table = np.column_stack(columns)
    np.savetxt(path, table, delimiter=",", fmt="%.9g", header="time,gx,gy,gz,ax,ay,az", comments="")
    return n


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(arguments: list[str], cache: Path, cwd: Path) -> tuple[float, float, bool]:
    """Wall and CPU time of ``python -m avar ARGUMENTS``, and whether stderr had the compile notice.

    The CPU time (user + system, all threads) is what a loaded machine does not inflate;
    the compilation is single-threaded, so on an idle machine it is also its wall time.
    """
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "MPLBACKEND": "Agg",
                   "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")])}
    cpu = _children_cpu()
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "avar", *arguments], cwd=cwd, env=environment,
                          capture_output=True, text=True)
    elapsed = time.perf_counter() - start
    cpu = _children_cpu() - cpu
    if done.returncode != 0:
        raise SystemExit(f"avar {' '.join(arguments)} failed ({done.returncode}):\n{done.stderr}")
    return elapsed, cpu, NOTICE in done.stderr


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs per case (default 3)")
    parser.add_argument("--hours", type=float, default=2.0, help="length of the log (default 2 h)")
    parser.add_argument("--rate", type=float, default=200.0, help="sampling rate of the log (default 200 Hz)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="avar-startup-") as folder:
        work = Path(folder)
        log = work / "imu.csv"
        rows = write_log(log, args.hours, args.rate)
        print(f"log: {rows} rows x 6 axes ({args.hours:g} h at {args.rate:g} Hz), {log.stat().st_size / 1e6:.0f} MB")
        commands = {
            "avar demo": ["demo", "--out", str(work / "demo"), "--force"],
            "avar report": ["report", str(log)],
        }
        print(f"\n| command | cold wall (median of {args.repeat}) | warm wall | cold / warm | cold CPU | warm CPU "
              "| compile CPU (cold - warm) | notice cold / warm |")
        print("|---|---|---|---|---|---|---|---|")
        for label, arguments in commands.items():
            runs: dict[str, list[tuple[float, float]]] = {"cold": [], "warm": []}
            notices = set()
            for index in range(args.repeat):
                cache = work / f"cache-{label.split()[1]}-{index}"
                for kind in ("cold", "warm"):  # the warm run reuses the cache the cold run filled
                    wall, cpu, notice = run(arguments, cache, work)
                    runs[kind].append((wall, cpu))
                    notices.add((kind, notice))
            cold, warm = ([statistics.median(v) for v in zip(*runs[k])] for k in ("cold", "warm"))
            shown = "/".join("yes" if (kind, True) in notices else "no" for kind in ("cold", "warm"))
            print(f"| `{label}` | {cold[0]:.1f} s | {warm[0]:.1f} s | {cold[0] / warm[0]:.1f}x | {cold[1]:.1f} s "
                  f"| {warm[1]:.1f} s | {cold[1] - warm[1]:.1f} s | {shown} |")
        print("\nacceptance: cold `avar report` of the 2 h 200 Hz log under 10 s (shared machine: see the load)")
        print(f"load average: {' '.join(f'{v:.1f}' for v in os.getloadavg())} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
