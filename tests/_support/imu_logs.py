"""The simulated IMU the report tests share: three gyroscopes and three accelerometers whose
noise is known (white noise N, bias instability B, random walk K, continuous time), each term
dominating a decade or more of an hour."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from avar.models import FN, RW, WN

#: Gyroscope terms in deg/s units (N deg/s/sqrt(Hz), B deg/s, K deg/s^2/sqrt(Hz)).
GYRO_TRUTH = {"N": 3e-3, "B": 2e-3, "K": 3e-4}
#: Accelerometer terms in g units.
ACCEL_TRUTH = {"N": 2e-5, "B": 1.5e-5, "K": 2e-6}


def sensor_model(truth: dict, rate: float):
    """White noise + flicker + random walk with the continuous-time terms of ``truth`` at ``rate`` Hz."""
    return (WN.from_continuous(truth["N"], rate) + FN.from_continuous(truth["B"], rate)
            + RW.from_continuous(truth["K"], rate))


def imu_columns(n_samples: int, rate: float, seed: int, gyro: str = "g{}", accel: str = "a{}") -> dict:
    """Six simulated channels named by the ``gyro`` and ``accel`` patterns (x, y, z), gyroscopes first."""
    rng = np.random.default_rng(seed)
    columns = {gyro.format(a): sensor_model(GYRO_TRUTH, rate).simulate(n_samples, seed=rng) for a in "xyz"}
    columns |= {accel.format(a): sensor_model(ACCEL_TRUTH, rate).simulate(n_samples, seed=rng) for a in "xyz"}
    return columns


def write_imu_csv(path: Path, seconds: float, rate: float, seed: int) -> Path:
    """A CSV log as a user gives it: ``time`` then ``gx gy gz`` (deg/s) and ``ax ay az`` (g)."""
    n_samples = int(seconds * rate)
    columns = {"time": np.arange(n_samples) / rate} | imu_columns(n_samples, rate, seed)
    pd.DataFrame(columns).to_csv(path, index=False, float_format="%.10g")
    return path
