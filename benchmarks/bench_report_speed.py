"""CPU time of :func:`avar.noise_report` per log, and the cold-versus-warm gap of ``avar report`` (issue 39).

Three measurements, medians of ``--repeat`` runs in this process after one warm-up call:

* every log given on the command line (``.npz`` of ``../shared/realdata``: 6 channels at 100 Hz,
  deg/s and g): CPU seconds (``time.process_time``) of one ``avar.noise_report``, each run on the
  log scaled by another factor (another fit of the same length: no cache of its own models helps);
* simulated 2 h 200 Hz 6-axis logs (another seed each run) of the ADIS16405-like "ieee" model of
  ``bench_simulate_recheck.py`` (white noise, flicker and random walk per axis);
* with ``--cli``, that log written to CSV and ``avar report sim.csv`` run twice in fresh
  interpreters sharing a new, empty ``NUMBA_CACHE_DIR`` and ``XDG_CACHE_HOME``: the first run
  is cold (every kernel compiled), the second warm; the gap is what issue 39 bounds (3 s).

The code of this checkout runs (``src`` first on ``PYTHONPATH``; ``--src`` points at another
tree, to time a before/after pair in one session). Prints numbers; asserts nothing. Usage::

    python benchmarks/bench_report_speed.py ../shared/realdata/*.npz --simulated --cli
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"

#: The "ieee" model of bench_simulate_recheck.py, SI units.
MODEL = {"Gyroscope": {"WN": 5.2e-4, "FN": 1.0e-4, "RW": 1.3e-5},
         "Accelerometer": {"WN": 3.2e-3, "FN": 1.7e-3, "RW": 3.0e-4}}
UNITS = {"Gyroscope": {"WN": "rad/s/sqrt(Hz)", "FN": "rad/s", "RW": "rad/s^2/sqrt(Hz)"},
         "Accelerometer": {"WN": "m/s^2/sqrt(Hz)", "FN": "m/s^2", "RW": "m/s^3/sqrt(Hz)"}}
AXES = {"Gyroscope": ("gx", "gy", "gz"), "Accelerometer": ("ax", "ay", "az")}


def terms_table():
    import pandas as pd

    return pd.DataFrame([{"Channel": axis, "Sensor": kind, "Term": p, "Process": p, "Status": "present",
                          "Value": v, "Unit": UNITS[kind][p]}
                         for kind, terms in MODEL.items() for axis in AXES[kind] for p, v in terms.items()])


def cpu_time(call, repeat: int) -> tuple[float, list[float]]:
    """Median CPU seconds of ``call(run)``, run = 1..repeat, after ``call(0)`` (kernels compiled or loaded).

    Each run gets another log of the same length (``run`` changes it): what a user running many logs
    of one length and rate waits for, without a cache of the same log's own models helping.
    """
    call(0)
    times = []
    for run in range(1, repeat + 1):
        start = time.process_time()
        call(run)
        times.append(time.process_time() - start)
    return statistics.median(times), times


def cold_warm(csv: Path, src: Path) -> tuple[float, float]:
    """Wall seconds of ``avar report csv`` in two fresh interpreters sharing a new, empty cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(cache) / "numba"), XDG_CACHE_HOME=str(Path(cache) / "xdg"),
                   PYTHONPATH=f"{src}{os.pathsep}{os.environ.get('PYTHONPATH', '')}")
        out = []
        for run in range(2):
            start = time.perf_counter()
            done = subprocess.run([sys.executable, "-c", "import sys; from avar.cli import main; sys.exit(main())",
                                   "report", str(csv), "--output", str(Path(cache) / f"terms{run}.csv")], env=env,
                                  capture_output=True, text=True)
            out.append(time.perf_counter() - start)
            if done.returncode != 0:
                raise SystemExit(f"avar report exited with {done.returncode}: {done.stderr[-2000:]}")
        return out[0], out[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("logs", nargs="*", type=Path, help=".npz logs (data, columns) at 100 Hz")
    parser.add_argument("--simulated", action="store_true", help="time a simulated 2 h 200 Hz 6-axis log")
    parser.add_argument("--cli", action="store_true", help="cold and warm avar report of the simulated log's CSV")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--src", type=Path, default=SRC, help="source tree to time (default: this checkout's)")
    args = parser.parse_args()
    sys.path.insert(0, str(args.src))
    import numpy as np

    import avar

    print(f"avar from {Path(avar.__file__).parent}; medians of {args.repeat} runs (CPU s, time.process_time)")
    for path in args.logs:
        data = np.load(path)
        def report(run: int, values=data["data"]):  # the log scaled by 1 + 1e-3 run: another fit, same lengths
            imu = avar.IMU(values * (1.0 + 1e-3 * run), rate=100.0, gyro=[0, 1, 2], accel=[3, 4, 5])
            return avar.noise_report(imu, gyro_units="deg/s", accel_units="g")

        median, times = cpu_time(report, args.repeat)
        print(f"{path.name}: noise_report {median:.2f} s CPU (runs {', '.join(f'{t:.2f}' for t in times)})")
    if args.simulated or args.cli:
        logs = [avar.simulate_log(terms_table(), duration="2h", rate=200.0, seed=seed) for seed in range(args.repeat + 1)]
        median, times = cpu_time(lambda run: avar.noise_report(logs[run]), args.repeat)
        print(f"simulated 2 h 200 Hz 6 axes: noise_report {median:.2f} s CPU "
              f"(runs {', '.join(f'{t:.2f}' for t in times)})")
        if args.cli:
            from avar.cli.main import main as avar_cli

            with tempfile.TemporaryDirectory() as folder:
                csv, terms = Path(folder) / "sim.csv", Path(folder) / "terms.csv"
                terms_table().to_csv(terms, index=False)
                if avar_cli(["simulate", str(terms), "--duration", "2h", "--rate", "200", "--output", str(csv),
                             "--seed", "1"]) != 0:
                    raise SystemExit("avar simulate failed")
                for _ in range(max(1, args.repeat // 2)):
                    cold, warm = cold_warm(csv, args.src)
                    print(f"avar report sim.csv (wall): cold {cold:.2f} s, warm {warm:.2f} s, gap {cold - warm:.2f} s")


if __name__ == "__main__":
    main()
