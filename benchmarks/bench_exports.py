"""Time each estimator export from one noise report (the report is computed once, not timed).

Usage::

    python benchmarks/bench_exports.py             # 200 Hz, 20 min, 3 gyros + 3 accelerometers
    python benchmarks/bench_exports.py --minutes 60

For every export (``kalibr``, ``openvins``, ``vins``, ``orbslam3``, ``basalt``, ``matlab``) the
table gives the median time of ``report.export(name)`` (the text: values picked from the table,
comments, formatting) and of writing it to a file (``path=...``, temporary file and rename), and
the file's size. The time to build the report itself is printed first: it is the cost of an
export, the export being a small fraction of it.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
from timing import median_time

import avar
from avar.fit.report.exports.registry import DEFAULT_FILES, EXPORTS
from avar.models import FN, RW, WN


def simulated_report(rate: float, minutes: float):
    """A report of three gyroscopes (deg/s) and three accelerometers (g) with known N, B, K."""
    n = int(minutes * 60 * rate)
    rng = np.random.default_rng(1)

    def model(noise, bias, walk):
        return WN.from_continuous(noise, rate) + FN.from_continuous(bias, rate) + RW.from_continuous(walk, rate)

    columns = {f"gyro_{a}": model(3e-3, 2e-3, 3e-4).simulate(n, seed=rng) for a in "xyz"}
    columns |= {f"acc_{a}": model(2e-5, 1.5e-5, 2e-6).simulate(n, seed=rng) for a in "xyz"}
    recording = SimpleNamespace(columns=pd.DataFrame(columns), freq=rate, topic="/imu0", source="bench.bag")
    return avar.noise_report(recording, gyro_units="deg/s", accel_units="g")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=float, default=200.0, help="sampling rate, Hz (default 200)")
    parser.add_argument("--minutes", type=float, default=20.0, help="log length, minutes (default 20)")
    parser.add_argument("--repeat", type=int, default=5, help="least number of timed calls (default 5)")
    args = parser.parse_args()
    start = time.perf_counter()
    report = simulated_report(args.rate, args.minutes)
    print(f"noise report of 6 channels x {int(args.minutes * 60 * args.rate)} samples: "
          f"{time.perf_counter() - start:.2f} s (not part of the exports' times)\n")
    print(f"{'export':<10} {'file':<24} {'text (ms)':>10} {'write (ms)':>11} {'bytes':>7}")
    with tempfile.TemporaryDirectory() as folder:
        for name in EXPORTS:
            path = Path(folder) / DEFAULT_FILES[name]
            text_time = median_time(lambda name=name: report.export(name), args.repeat)
            write_time = median_time(lambda name=name, path=path: report.export(name, path, force=True), args.repeat)
            print(f"{name:<10} {DEFAULT_FILES[name]:<24} {1e3 * text_time:>10.2f} {1e3 * write_time:>11.2f} "
                  f"{path.stat().st_size:>7}")


if __name__ == "__main__":
    main()
