"""``avar report --export``: every estimator's file from one run, read back as the estimator reads it."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
import yaml

from tests._support.imu_logs import write_imu_csv

RATE = 100.0


def run(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "avar", "report", *args], capture_output=True, text=True,
                          timeout=300, cwd=cwd)


@pytest.fixture(scope="module")
def log(tmp_path_factory):
    """A CSV log: three gyros (deg/s) and three accelerometers (g), 10 minutes at 100 Hz."""
    return write_imu_csv(tmp_path_factory.mktemp("log") / "imu.csv", 600, RATE, seed=8)


UNITS = ("--gyro-units", "deg/s", "--accel-units", "g")


def table_value(terms: pd.DataFrame, sensor: str, process: str, axis: str) -> float:
    rows = terms[(terms["Sensor"] == sensor) & (terms["Process"] == process)]
    values = [row["Value"] if row["Status"] == "present" else row["Upper"] for _, row in rows.iterrows()]
    return max(values) if axis == "max" else float(np.mean(values))


def test_every_export_in_one_run_with_default_names(log, tmp_path):
    cv2 = pytest.importorskip("cv2")
    result = run(str(log), *UNITS, "--export", "kalibr", "--export", "openvins", "--export", "vins",
                 "--export", "orbslam3", "--export", "basalt", "--export", "matlab=params.m", "--axis", "mean",
                 "--inflate", "10", "--output", "terms.csv", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    names = {"imu.yaml", "kalibr_imu_chain.yaml", "vins_imu.yaml", "orbslam3_imu.yaml", "basalt_calib.json",
             "params.m", "terms.csv"}
    assert {p.name for p in tmp_path.iterdir()} == names
    terms = pd.read_csv(tmp_path / "terms.csv")
    gyro_n = table_value(terms, "Gyroscope", "WN", "mean") * 10
    acc_w = table_value(terms, "Accelerometer", "RW", "mean") * 10
    assert yaml.safe_load((tmp_path / "imu.yaml").read_text())["gyroscope_noise_density"] == pytest.approx(gyro_n, rel=1e-9)
    storage = cv2.FileStorage(str(tmp_path / "vins_imu.yaml"), cv2.FILE_STORAGE_READ)
    assert storage.getNode("gyr_n").real() == pytest.approx(gyro_n * RATE**0.5, rel=1e-9)  # discrete time
    assert storage.getNode("acc_w").real() == pytest.approx(acc_w * RATE**0.5, rel=1e-9)
    storage = cv2.FileStorage(str(tmp_path / "orbslam3_imu.yaml"), cv2.FILE_STORAGE_READ)
    assert storage.getNode("IMU.NoiseGyro").real() == pytest.approx(gyro_n, rel=1e-9)
    storage = cv2.FileStorage(str(tmp_path / "kalibr_imu_chain.yaml"), cv2.FILE_STORAGE_READ)
    assert storage.getNode("imu0").getNode("accelerometer_random_walk").real() == pytest.approx(acc_w, rel=1e-9)
    body = json.loads((tmp_path / "basalt_calib.json").read_text())["value0"]
    assert body["gyro_noise_std"] == pytest.approx([gyro_n] * 3, rel=1e-9)
    assert "gyro.NoiseDensity = " in (tmp_path / "params.m").read_text()
    # Basalt's JSON holds no comments: they go to stderr
    assert "--export basalt: gyro_noise_std: rad/s/sqrt(Hz), continuous-time white noise" in result.stderr
    assert "multiplied by inflate = 10" in result.stderr


def test_kalibr_alias_deprecated_axis_and_refusals(log, tmp_path):
    a, b = tmp_path / "a.yaml", tmp_path / "b.yaml"
    result = run(str(log), *UNITS, "--kalibr", str(a), "--export", f"kalibr={b}", "--kalibr-axis", "mean")
    assert result.returncode == 0, result.stderr
    assert "--kalibr-axis is deprecated" in result.stderr
    assert a.read_text() == b.read_text() and "mean over the axes" in a.read_text()
    same = run(str(log), *UNITS, "--export", f"vins={tmp_path / 'x.yaml'}", "--export",
               f"orbslam3={tmp_path / 'x.yaml'}")
    assert same.returncode == 2 and "also given for another output" in same.stderr
    exists = run(str(log), *UNITS, "--export", f"kalibr={a}")
    assert exists.returncode == 2 and "exists; pass --force" in exists.stderr
    for bad, message in ((["--export", "okvis"], "must be one of kalibr, openvins"),
                         (["--inflate", "0", "--export", "vins"], "--inflate must be a finite factor > 0"),
                         (["--axis", "max", "--kalibr-axis", "mean"], "disagree")):
        refused = run(str(log), *UNITS, *bad, cwd=tmp_path)
        assert refused.returncode == 2 and message in refused.stderr, (bad, refused.stderr)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.yaml", "b.yaml"]
