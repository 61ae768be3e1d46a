"""``avar simulate`` then ``avar report``, and ``--recheck``: the 2-hour acceptance figures.

Two models of an ADIS16405-like IMU (the values of the real logs' reports, SI units), each on
three gyroscope and three accelerometer axes, 2 h at 200 Hz:

* **kalibr**: a Kalibr ``imu.yaml`` (white noise N and random walk K per sensor type), the
  acceptance case: ``avar simulate imu.yaml --duration 2h --rate 200 --output sim.csv`` then
  ``avar report sim.csv`` (no options) should recover N within 3 % and K within 40 % on every
  axis, and ``recheck(20)`` should cover N and K with its 95 % intervals 0.85 - 1.0 of the time,
  pooled over the three axes of each sensor type (60 draws);
* **ieee**: a terms CSV with bias instability B too (``avar simulate terms.csv``), where B and K
  compete for the long taus: the same figures, for information.

With ``--real PATH`` (an ``.npz`` of /work/shared/realdata), the same recheck of a real log's
report (every term the data chose: Gauss-Markov and sinusoid terms too), for information.
Prints the figures; asserts nothing (a benchmark, not a test). Run from the repository root::

    python benchmarks/bench_simulate_recheck.py [--hours 2] [--rate 200] [--replicates 20] [--real PATH]

``--truth-seeds 40 [--sensors Gyroscope]`` instead counts, over 40 logs simulated from the
"ieee" model itself (the truth known, not a fitted model), how often the report's 95 %
intervals of N, B and K hold the simulated values (target 0.85 - 1.0 for N and K).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import math
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

import avar
from avar.cli.main import main as avar_cli

#: SI values (rad/s/sqrt(Hz), rad/s, rad/s^2/sqrt(Hz); m/s^2/sqrt(Hz), m/s^2, m/s^3/sqrt(Hz)) of the ADIS16405 reports.
MODEL = {"Gyroscope": {"WN": 5.2e-4, "FN": 1.0e-4, "RW": 1.3e-5},
         "Accelerometer": {"WN": 3.2e-3, "FN": 1.7e-3, "RW": 3.0e-4}}
UNITS = {"Gyroscope": {"WN": "rad/s/sqrt(Hz)", "FN": "rad/s", "RW": "rad/s^2/sqrt(Hz)"},
         "Accelerometer": {"WN": "m/s^2/sqrt(Hz)", "FN": "m/s^2", "RW": "m/s^3/sqrt(Hz)"}}
AXES = {"Gyroscope": ("gx", "gy", "gz"), "Accelerometer": ("ax", "ay", "az")}
TOLERANCE = {"WN": 0.03, "RW": 0.40}


KALIBR_KEYS = {("Gyroscope", "WN"): "gyroscope_noise_density", ("Gyroscope", "RW"): "gyroscope_random_walk",
               ("Accelerometer", "WN"): "accelerometer_noise_density",
               ("Accelerometer", "RW"): "accelerometer_random_walk"}


def write_model(folder: Path, case: str, rate: float) -> tuple[Path, dict]:
    """The model file of a case (imu.yaml or terms.csv) and its terms per sensor type."""
    if case == "kalibr":
        model = {kind: {p: v for p, v in terms.items() if p != "FN"} for kind, terms in MODEL.items()}
        path = folder / "imu.yaml"
        fields = {KALIBR_KEYS[kind, p]: v for kind, terms in model.items() for p, v in terms.items()}
        path.write_text(yaml.safe_dump({**fields, "rostopic": "/imu0", "update_rate": rate}))
        return path, model
    rows = [{"Channel": axis, "Sensor": kind, "Term": process, "Process": process, "Status": "present",
             "Value": value, "Unit": UNITS[kind][process]}
            for kind, terms in MODEL.items() for axis in AXES[kind] for process, value in terms.items()]
    path = folder / "terms.csv"
    pd.DataFrame(rows).to_csv(path, index=False)
    return path, MODEL


def run_cli(*args) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        code = avar_cli([str(a) for a in args])
    if code != 0:
        raise SystemExit(f"avar {' '.join(map(str, args))} exited with {code}")
    return out.getvalue()


def simulate_then_report(folder: Path, case: str, hours: float, rate: float) -> Path:
    source, model = write_model(folder, case, rate)
    log, fitted = folder / "sim.csv", folder / "fitted.csv"
    started = time.perf_counter()
    print(run_cli("simulate", source, "--duration", f"{hours}h", "--rate", rate, "--output", log, "--seed", 1).strip())
    print(f"  simulate: {time.perf_counter() - started:.1f} s")
    started = time.perf_counter()
    run_cli("report", log, "--output", fitted)
    print(f"  report: {time.perf_counter() - started:.1f} s")
    table = pd.read_csv(fitted)
    print(f"\n[{case}] 1. avar simulate {source.name} ({hours:g} h at {rate:g} Hz) then avar report: "
          "recovered / simulated")
    print(f"{'axis':<6}{'term':<5}{'status':<9}{'ratio':>8}{'tolerance':>11}  verdict")
    for kind, terms_of in model.items():
        for axis in AXES[kind]:
            for process in ("WN", "RW"):
                row = table[(table["Channel"] == axis) & (table["Process"] == process)].iloc[0]
                ratio = row["Value"] / terms_of[process] if row["Status"] == "present" else math.nan
                ok = abs(ratio - 1) <= TOLERANCE[process]
                print(f"{axis:<6}{process:<5}{row['Status']:<9}{ratio:>8.4f}{TOLERANCE[process]:>10.0%}  "
                      f"{'ok' if ok else 'OUT'}")
    return log


def coverage(report, replicates: int, title: str) -> None:
    started = time.perf_counter()
    check = avar.recheck(report, replicates, seed=2, progress=True)
    print(f"\n{title} ({time.perf_counter() - started:.0f} s)")
    print(str(check))
    summary = check.summary()
    print("\npooled over the axes:")
    print(summary.to_string(index=False, float_format="{:.3f}".format))
    for _, row in summary[summary["Process"].isin(["WN", "RW"])].iterrows():
        spread = math.sqrt(0.95 * 0.05 / row["Draws"])
        verdict = "ok" if 0.85 <= row["Coverage"] <= 1.0 else "OUT"
        print(f"  {row['Sensor']:<14}{row['Process']:<4}coverage {row['Coverage']:.3f} of {row['Draws']} draws "
              f"(0.95 +- {spread:.3f} binomial sd; accepted 0.85 - 1.0): {verdict}")


def truth_coverage(seeds: int, hours: float, rate: float, sensors: tuple[str, ...]) -> None:
    """Coverage of the report's intervals of N, B and K over ``seeds`` logs simulated from the "ieee" model itself
    (the truth known): the share of the draws whose interval (or bound) holds the simulated value."""
    model = MODEL
    rows = pd.DataFrame([{"Channel": axis, "Sensor": kind, "Term": p, "Process": p, "Status": "present", "Value": v,
                          "Unit": UNITS[kind][p]} for kind in sensors for axis in AXES[kind]
                         for p, v in model[kind].items()])
    draws = []
    started = time.perf_counter()
    for seed in range(1, seeds + 1):
        table = avar.noise_report(avar.simulate_log(rows, duration=f"{hours}h", rate=rate, seed=seed)).table
        for kind in sensors:
            for axis in AXES[kind]:
                for process, truth in model[kind].items():
                    row = table[(table["Channel"] == axis) & (table["Process"] == process)].iloc[0]
                    if row["Status"] == "present":
                        covered = row["Lower"] <= truth <= row["Upper"]
                    elif row["Status"] == "bound":
                        covered = truth <= row["Upper"]
                    else:
                        covered = False
                    draws.append((kind, process, row["Status"], covered, row["Value"] / truth))
    frame = pd.DataFrame(draws, columns=["Sensor", "Process", "Status", "Covered", "Ratio"])
    print(f"\n[ieee] coverage of the 95 % intervals over {seeds} seeds of the known model "
          f"({hours:g} h at {rate:g} Hz; {time.perf_counter() - started:.0f} s)")
    for (kind, process), group in frame.groupby(["Sensor", "Process"], sort=False):
        spread = math.sqrt(0.95 * 0.05 / len(group))
        statuses = ", ".join(f"{s} {n}" for s, n in group["Status"].value_counts().items())
        print(f"  {kind:<14}{process:<4}coverage {group['Covered'].mean():.3f} of {len(group)} draws "
              f"(0.95 +- {spread:.3f}); median ratio {group['Ratio'].median():.3f}; {statuses}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hours", type=float, default=2.0)
    parser.add_argument("--rate", type=float, default=200.0)
    parser.add_argument("--replicates", type=int, default=20)
    parser.add_argument("--real", type=Path, default=None, help="an .npz of /work/shared/realdata (optional)")
    parser.add_argument("--truth-seeds", type=int, default=0,
                        help="only the coverage of N, B, K over this many logs of the known ieee model (e.g. 40)")
    parser.add_argument("--sensors", nargs="+", default=list(MODEL), choices=list(MODEL))
    args = parser.parse_args()
    if args.truth_seeds:
        truth_coverage(args.truth_seeds, args.hours, args.rate, tuple(args.sensors))
        return
    for case in ("kalibr", "ieee"):
        with tempfile.TemporaryDirectory() as folder:
            log = simulate_then_report(Path(folder), case, args.hours, args.rate)
            report = avar.noise_report(avar.read(log))
            coverage(report, args.replicates, f"[{case}] 2. recheck {args.replicates} of the simulated log's report")
    if args.real is not None:
        data = np.load(args.real)
        imu = avar.IMU(data["data"], rate=100.0, gyro=[0, 1, 2], accel=[3, 4, 5])
        real = avar.noise_report(imu, gyro_units="deg/s", accel_units="g", name=args.real.name)
        coverage(real, args.replicates, f"3. recheck {args.replicates} of the report of {args.real.name}")


if __name__ == "__main__":
    main()
