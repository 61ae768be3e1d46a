"""``avar fit`` options for IMU fits: --ci, --per-axis, --deviation, --gyro-units/--accel-units (real files, subprocesses)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import avar
from avar.models import RW, WN

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "avar", "fit", *args], capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def imu_file(tmp_path_factory):
    model = WN(sigma2=1.0) + RW(gamma2=1e-6)
    data = {name: model.simulate(20_000, seed=k) for k, name in enumerate(("gx", "gy", "ax", "ay"))}
    path = tmp_path_factory.mktemp("fit") / "imu.csv"
    pd.DataFrame({"time": np.arange(20_000) / 10.0, **data}).to_csv(path, index=False, float_format="%.17g")
    return path, data


def test_imu_bootstrap_per_axis_with_units_and_deviation_plot(imu_file, tmp_path):
    path, data = imu_file
    png, out = tmp_path / "fit.png", tmp_path / "fit.csv"
    result = run(str(path), "--gyro", "gx", "--gyro", "gy", "--accel", "ax", "--accel", "ay", "--wn", "1:5",
                 "--ci", "--B", "20", "--seed", "3", "--per-axis", "--deviation", "--gyro-units", "deg/s",
                 "--accel-units", "g", "--plot", str(png), "--output", str(out))
    assert result.returncode == 0, result.stderr
    assert "Bootstrap (B = 20)" in result.stdout and "Lower" in result.stdout
    labels = out.read_text()
    assert "sigma [deg/s s^1/2]" in labels and "sigma [g s^1/2]" in labels
    assert png.read_bytes()[:8] == PNG_MAGIC
    table = pd.read_csv(out, index_col=[0, 1])
    imu = avar.IMU(pd.DataFrame(data), freq=10.0, gyro=["gx", "gy"], accel=["ax", "ay"])
    expected = avar.avlr(imu, wn_gyro=range(1, 6), wn_acc=range(1, 6), per_axis=True)
    np.testing.assert_allclose(table.loc["Gyroscope", "X"], expected.estimates["Gyroscope"].loc["X"], rtol=1e-12)


def test_joint_imu_bootstrap_matches_the_library(imu_file):
    path, data = imu_file
    result = run(str(path), "--gyro", "gx", "--gyro", "gy", "--wn", "1:5", "--ci", "--B", "30", "--seed", "4")
    assert result.returncode == 0, result.stderr
    imu = avar.IMU(pd.DataFrame({k: data[k] for k in ("gx", "gy")}), freq=10.0, gyro=["gx", "gy"])
    fit = avar.avlr(imu, wn_gyro=range(1, 6), ci=True, B=30, seed=4)
    sd = fit.ci["Gyroscope"].loc["WN", "SD"]
    assert f"{sd:.6g}" in result.stdout
    # the pooled estimator of two axes is about sqrt(2) less variable than one axis alone
    single = avar.avlr(avar.avar(data["gx"], freq=10.0), wn=range(1, 6), ci=True, B=200, seed=5).ci.loc["WN", "SD"]
    assert 0.5 < sd / (single / np.sqrt(2)) < 1.6
