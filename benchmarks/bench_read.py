"""Reading real logs end to end: ``avar compute`` on 1-hour and 8-hour 200 Hz 6-axis CSVs.

Writes the CSVs (a time column and six channels, written once and kept in ``--dir``), then
times, each in a fresh subprocess, with its peak resident memory (``os.wait4``):

* ``read_csv``: ``python -c "import pandas; pandas.read_csv(f)"`` (the floor: Python, pandas
  and the C parser);
* ``avar compute f``: the command line, end to end (read, rate, the Allan variance of every
  column, the table printed);
* ``read_csv + allantools.oadev``: pandas, then ``allantools.oadev`` of each column on the
  octave grid (the usual script a user would write).

Ratios are to ``read_csv`` of the same file in the same run; the machine's load shows in all
three alike. Usage::

    python benchmarks/bench_read.py                 # 1 h and 8 h, best of 3 and 1 runs
    python benchmarks/bench_read.py --hours 1 --repeat 5
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

RATE = 200.0
CHANNELS = ("gx", "gy", "gz", "ax", "ay", "az")
SRC = str(Path(__file__).resolve().parent.parent / "src")

READ_CSV = "import sys, pandas; pandas.read_csv(sys.argv[1])"
ALLANTOOLS = (
    "import sys, pandas, allantools\n"
    "frame = pandas.read_csv(sys.argv[1])\n"
    "for name in frame.columns[1:]:\n"
    "    allantools.oadev(frame[name].to_numpy(), rate=float(sys.argv[2]), data_type='freq', taus='octave')\n"
)


def write_log(path: Path, hours: float, seed: int = 0) -> Path:
    """A 200 Hz 6-axis log with a time column, written in blocks (bounded memory)."""
    n = int(hours * 3600 * RATE)
    if path.exists() and path.stat().st_size > 0 and path.with_suffix(".rows").read_text() == str(n):
        return path
    rng = np.random.default_rng(seed)
    block = 500_000
    with path.open("w") as out:
        out.write("time," + ",".join(CHANNELS) + "\n")
        for start in range(0, n, block):
            rows = min(block, n - start)
            table = np.empty((rows, 7))
            table[:, 0] = np.arange(start, start + rows) / RATE
            table[:, 1:] = rng.standard_normal((rows, 6)) * 0.01 + [0, 0, 0, 0, 0, 9.81]
            np.savetxt(out, table, fmt=["%.3f"] + ["%.9f"] * 6, delimiter=",")
    path.with_suffix(".rows").write_text(str(n))
    return path


def measure(command: list[str], env: dict) -> tuple[float, float, int]:
    """Wall time (s), peak resident memory (MB) and exit status of one subprocess."""
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    error = process.stderr.read().decode(errors="replace")
    process.stderr.close()
    code = os.waitstatus_to_exitcode(status)
    if code != 0:
        print(f"  {command[:4]} failed ({code}): {error.strip().splitlines()[-1:]}", file=sys.stderr)
    return wall, usage.ru_maxrss / 1024.0, code


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, nargs="+", default=[1.0, 8.0])
    parser.add_argument("--repeat", type=int, nargs="+", default=[3, 1], help="runs per file (best kept)")
    parser.add_argument("--dir", type=Path, default=Path(tempfile.gettempdir()) / "avar_bench_read")
    parser.add_argument("--no-allantools", action="store_true", help="skip the allantools script")
    args = parser.parse_args(argv)
    args.dir.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=SRC + os.pathsep + os.environ.get("PYTHONPATH", ""), MPLBACKEND="Agg")
    python = sys.executable
    rows = []
    for i, hours in enumerate(args.hours):
        repeat = args.repeat[min(i, len(args.repeat) - 1)]
        path = write_log(args.dir / f"imu_{hours:g}h.csv", hours)
        size = path.stat().st_size / 1e6
        cases = {
            "read_csv": [python, "-c", READ_CSV, str(path)],
            "avar compute": [python, "-m", "avar", "compute", str(path)],
        }
        if not args.no_allantools:
            cases["read_csv + allantools.oadev"] = [python, "-c", ALLANTOOLS, str(path), str(RATE)]
        best = {}
        for _ in range(repeat):  # interleaved, so that load changes hit every case alike
            for name, command in cases.items():
                wall, rss, code = measure(command, env)
                if code == 0 and (name not in best or wall < best[name][0]):
                    best[name] = (wall, max(rss, best.get(name, (0, 0))[1]))
        floor = best["read_csv"][0]
        for name, (wall, rss) in best.items():
            rows.append((f"{hours:g} h ({int(hours * 3600 * RATE):,} rows, {size:.0f} MB)", name, wall, wall / floor, rss))
    print(f"{'file':34s} {'command':30s} {'wall s':>8s} {'/ read_csv':>10s} {'peak RSS MB':>12s}")
    for file, name, wall, ratio, rss in rows:
        print(f"{file:34s} {name:30s} {wall:8.2f} {ratio:10.2f} {rss:12.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
