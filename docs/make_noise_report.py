"""Regenerate docs/noise_report.png and the sample output in docs/noise_report.md.

Simulates one hour of a 6-axis IMU at 100 Hz (gyroscopes in deg/s, accelerometers in g) with white
noise, flicker (bias instability) and random walk of known size, writes it as a CSV log and runs the
one-command report on it, exactly as a user would::

    PYTHONPATH=src python docs/make_noise_report.py
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from avar.cli.main import main
from avar.models import FN, RW, WN

FREQ = 100.0
SECONDS = 3600
GYRO = {"N": 3e-3, "B": 2e-3, "K": 3e-4}  # deg/s/sqrt(Hz), deg/s, deg/s/sqrt(s)
ACCEL = {"N": 2e-5, "B": 1.5e-5, "K": 2e-6}  # g/sqrt(Hz), g, g/sqrt(s)


def model(truth: dict[str, float]):
    return (WN.from_continuous(truth["N"], FREQ) + FN.from_continuous(truth["B"], FREQ)
            + RW.from_continuous(truth["K"], FREQ))


def write_log(path: Path) -> None:
    n = int(SECONDS * FREQ)
    rng = np.random.default_rng(2026)
    columns = {"time": np.arange(n) / FREQ}
    columns |= {f"g{a}": model(GYRO).simulate(n, seed=rng) for a in "xyz"}
    columns |= {f"a{a}": model(ACCEL).simulate(n, seed=rng) for a in "xyz"}
    pd.DataFrame(columns).to_csv(path, index=False, float_format="%.10g")


if __name__ == "__main__":
    docs = Path(__file__).resolve().parent
    with tempfile.TemporaryDirectory() as folder:
        log = Path(folder) / "imu.csv"
        write_log(log)
        sys.exit(main(["report", str(log), "--gyro-units", "deg/s", "--accel-units", "g", "--topic", "/imu0",
                       "--kalibr", str(Path(folder) / "imu.yaml"), "--plot", str(docs / "noise_report.png"),
                       "--force"]))
