"""One simulated IMU report for every export test (200 Hz, 20 min, three gyros and three accelerometers)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import avar
from avar.models import WN
from tests._support.imu_logs import imu_columns

RATE = 200.0
N_SAMPLES = int(20 * 60 * RATE)
DEG = math.pi / 180
G0 = 9.80665


@pytest.fixture(scope="session")
def imu_report():
    columns = imu_columns(N_SAMPLES, RATE, seed=21, gyro="gyro_{}", accel="acc_{}")  # deg/s, g
    recording = SimpleNamespace(columns=pd.DataFrame(columns), freq=RATE, topic="/imu0/data", source="flight.bag")
    return avar.noise_report(recording, gyro_units="deg/s", accel_units="g")


@pytest.fixture(scope="session")
def white_report():
    """White noise only (gyro rad/s, accel m/s^2): the random walk and bias instability are bounds only."""
    rng = np.random.default_rng(4)
    columns = pd.DataFrame({"gx": WN(sigma2=1e-4).simulate(40_000, seed=rng),
                            "ax": WN(sigma2=4e-4).simulate(40_000, seed=rng)})
    return avar.noise_report(columns, rate=100.0, gyro=["gx"], accel=["ax"], gyro_units="rad/s",
                             accel_units="m/s^2")


@pytest.fixture(scope="session")
def expected():
    """:func:`table_value`, for the tests."""
    return table_value


def table_value(report, kind: str, process: str, axis: str = "max") -> float:
    """The report's value of a term for a sensor type, read from its table with a plain loop: the value of
    each axis (its upper bound where only bounded), then the largest or the mean."""
    table = report.table
    values = []
    for _, row in table.iterrows():
        if row["Sensor"] != kind or row["Process"] != process:
            continue
        if row["Status"] == "present":
            values.append(float(row["Value"]))
        elif row["Status"] == "bound":
            values.append(float(row["Upper"]))
    assert values, (kind, process)
    return max(values) if axis == "max" else sum(values) / len(values)
