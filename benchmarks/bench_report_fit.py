"""How well the noise report's implied curve holds on static IMU logs: per channel, the share of levels that fit.

For every log given on the command line (``.npz`` with ``data`` (N, channels) and
``columns``, as in ``../shared/realdata``; or any file :func:`avar.read` opens), runs
:func:`avar.noise_report` and prints per channel:

* the fraction of levels where the implied deviation lies inside the empirical band
  or within 10 % of the empirical deviation (the report's own fit check, column ``Fits``);
* the terms selected, with each term's group (IEEE 952 or sensor filtering) and, for a
  Gauss-Markov term, its correlation time;
* the warnings of that channel.

Nothing is read unless given: the logs are arguments. The ``.npz`` logs of the ADIS16405
(100 Hz, gyroscopes in deg/s, accelerometers in g) need no options; ``--rate``,
``--gyro-units`` and ``--accel-units`` override them.

Usage::

    python benchmarks/bench_report_fit.py ../shared/realdata/*.npz
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pandas as pd

import avar


def _table(path: Path, rate: float) -> tuple[pd.DataFrame, float]:
    if path.suffix == ".npz":
        data = np.load(path)
        columns = [str(c) for c in data["columns"]]
        return pd.DataFrame({c: data["data"][:, k] for k, c in enumerate(columns)}), rate
    recording = avar.read(str(path))
    return pd.DataFrame(dict(recording.columns)), float(recording.rate)


def measure(path: Path, rate: float, gyro_units: str, accel_units: str) -> None:
    table, rate = _table(path, rate)
    gyro = [c for c in table.columns if c.lower().startswith("gyr")]
    accel = [c for c in table.columns if c.lower().startswith("acc")]
    start = time.perf_counter()
    report = avar.noise_report(table, gyro_units=gyro_units, accel_units=accel_units, rate=rate,
                               gyro=gyro or None, accel=accel or None)
    elapsed = time.perf_counter() - start
    print(f"\n{path.name}: {len(report.channels)} channels, {report.n_samples} samples at {rate:g} Hz, "
          f"report {elapsed:.1f} s, {len(report.warnings)} warning(s)")
    terms = report.table
    for channel in report.channels:
        curves = report.curves[report.curves["Channel"] == channel]
        fits = curves["Fits"].astype(bool)
        rows = terms[(terms["Channel"] == channel) & (terms["Status"] == "present")]
        shown = []
        for _, row in rows.iterrows():
            process = str(row["Process"])
            if process.endswith((".T", ".f")):
                continue
            text = process
            if process.startswith("AR1"):
                text += f"(T={float(row['Tau (s)']):.3g} s)"
            if process.startswith("SIN"):
                text += f"({1.0 / float(row['Tau (s)']):.3g} Hz)"
            group = row.get("Group", "")
            if isinstance(group, str) and group == "sensor filtering":
                text += "[filt]"
            shown.append(text)
        bad = [f"{t:.3g}" for t, ok in zip(curves["Tau (s)"], fits) if not ok]
        print(f"  {channel:<10} fits {fits.mean():.3f} ({int(fits.sum())}/{fits.size} levels)  "
              f"terms {' + '.join(shown)}" + (f"  misfit at tau {', '.join(bad)} s" if bad else ""))
        for note in terms[(terms["Channel"] == channel) & (terms["Status"] == "warning")]["Note"]:
            print(f"    warning: {note}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("logs", nargs="+", type=Path, help="static IMU logs (.npz with data/columns, or any avar.read file)")
    parser.add_argument("--rate", type=float, default=100.0, help="sampling rate of .npz logs, Hz (default 100)")
    parser.add_argument("--gyro-units", default="deg/s")
    parser.add_argument("--accel-units", default="g")
    args = parser.parse_args()
    for path in args.logs:
        measure(path, args.rate, args.gyro_units, args.accel_units)


if __name__ == "__main__":
    main()
