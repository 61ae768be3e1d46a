"""``avar report``, run for real in subprocesses on files written to disk."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
import yaml

from tests._support.imu_logs import write_imu_csv

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
FREQ = 50.0
DEG = math.pi / 180


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "avar", "report", *args], capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def imu_file(tmp_path_factory):
    """A CSV log: time, three gyros in deg/s and three accelerometers in g, 1 hour at 50 Hz."""
    return write_imu_csv(tmp_path_factory.mktemp("log") / "imu.csv", 3600, FREQ, seed=5)


def test_one_command_writes_yaml_figure_and_table(imu_file, tmp_path):
    yaml_path, png, csv = tmp_path / "imu.yaml", tmp_path / "report.png", tmp_path / "terms.csv"
    result = run(str(imu_file), "--gyro", "gx", "gy", "gz", "--accel", "ax", "ay", "az", "--gyro-units", "deg/s",
                 "--accel-units", "g", "--topic", "/imu0", "--kalibr", str(yaml_path), "--plot", str(png),
                 "--output", str(csv))
    assert result.returncode == 0, result.stderr
    assert "Angle random walk" in result.stdout and "deg/sqrt(h)" in result.stdout
    assert "Bias instability" in result.stdout and "ug" in result.stdout
    assert f"Wrote {yaml_path}" in result.stdout
    fields = yaml.safe_load(yaml_path.read_text())
    assert fields["rostopic"] == "/imu0" and fields["update_rate"] == pytest.approx(FREQ, rel=1e-9)
    assert fields["gyroscope_noise_density"] == pytest.approx(3e-3 * DEG, rel=0.03)
    assert fields["accelerometer_noise_density"] == pytest.approx(2e-5 * 9.80665, rel=0.03)
    assert png.read_bytes()[:8] == PNG_MAGIC
    table = pd.read_csv(csv)
    ieee = table[table["Process"].isin(["QN", "WN", "FN", "RW", "DR", "MIN"])]
    assert len(ieee) == 6 * 6 and set(table["Channel"]) == {"gx", "gy", "gz", "ax", "ay", "az"}
    wn = table[(table["Channel"] == "gx") & (table["Process"] == "WN")].iloc[0]
    assert wn["Customary"] == pytest.approx(3e-3 * 60, rel=0.03)  # deg/sqrt(h)
    absent = table[table["Status"] == "absent"]
    assert absent["Value"].isna().all() and not absent.empty  # empty cells, never the text "nan"
    assert "nan" not in csv.read_text().lower()


def test_columns_are_found_by_name(imu_file):
    result = run(str(imu_file), "--gyro-units", "deg/s")
    assert result.returncode == 0, result.stderr
    assert "gx (gyroscope)" in result.stdout and "az (accelerometer)" in result.stdout


def test_outputs_are_safe(imu_file, tmp_path):
    existing = tmp_path / "imu.yaml"
    existing.write_text("keep\n")
    result = run(str(imu_file), "--kalibr", str(existing))
    assert result.returncode == 2 and "--force" in result.stderr
    assert existing.read_text() == "keep\n"
    result = run(str(imu_file), "--kalibr", str(existing), "--force")
    assert result.returncode == 0, result.stderr
    assert yaml.safe_load(existing.read_text())["rostopic"] == "/imu0"
    result = run(str(imu_file), "--output", str(imu_file))
    assert result.returncode == 2 and "input file" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["imu.yaml"]  # no temporary file left


def test_errors_are_one_line(tmp_path):
    path = tmp_path / "x.csv"
    pd.DataFrame({"gx": np.random.default_rng(1).standard_normal(1000)}).to_csv(path, index=False)
    result = run(str(path))
    assert result.returncode == 1 and "--rate" in result.stderr and "Traceback" not in result.stderr
    result = run(str(path), "--freq", "100", "--gyro-units", "rpm")
    assert result.returncode == 2
    result = run(str(tmp_path / "missing.csv"), "--freq", "100")
    assert result.returncode == 1 and "no such file" in result.stderr


def test_curves_minimum_rows_and_kalibr_without_a_random_walk(tmp_path):
    """White noise alone: the random walk is not resolved, yet --kalibr writes every key (its bound, marked)."""
    n = int(600 * FREQ)
    rng = np.random.default_rng(8)
    frame = pd.DataFrame({"time": np.arange(n) / FREQ, "gx": 0.01 * rng.standard_normal(n),
                          "ax": 0.002 * rng.standard_normal(n)})
    log = tmp_path / "white.csv"
    frame.to_csv(log, index=False)
    yaml_path, curves, terms = tmp_path / "imu.yaml", tmp_path / "curves.csv", tmp_path / "terms.csv"
    result = run(str(log), "--kalibr", str(yaml_path), "--curves", str(curves), "--output", str(terms),
                 "--kalibr-axis", "mean")
    assert result.returncode == 0, result.stderr
    text = yaml_path.read_text()
    fields = yaml.safe_load(text)
    assert set(fields) == {"gyroscope_noise_density", "gyroscope_random_walk", "accelerometer_noise_density",
                           "accelerometer_random_walk", "rostopic", "update_rate"}
    assert all(isinstance(fields[k], float) and fields[k] > 0 for k in fields if k != "rostopic")
    assert text.count("one-sided 97.5 % upper bound") >= 2 and "mean over the axes" in text
    assert fields["gyroscope_noise_density"] == pytest.approx(0.01 / math.sqrt(FREQ), rel=0.05)
    table = pd.read_csv(curves)
    assert list(table.columns[:6]) == ["Channel", "Tau (s)", "ADEV", "Lower", "Upper", "Implied ADEV"]
    assert set(table["Channel"]) == {"gx", "ax"} and (table["Lower"] <= table["ADEV"]).all()
    assert (table["ADEV"] <= table["Upper"]).all()
    rows = pd.read_csv(terms)
    minimum = rows[rows["Term"].str.contains("minimum")]
    assert list(minimum["Channel"]) == ["gx", "ax"]
    for _, row in minimum.iterrows():  # read where at least 8 clusters average: tau <= 600 s / 8
        own = table[(table["Channel"] == row["Channel"]) & (table["Tau (s)"] <= 600.0 / 8)]
        assert row["Value"] == pytest.approx(own["ADEV"].min(), rel=1e-9)  # SI: rad/s and m/s^2 by default
        assert row["Tau (s)"] == pytest.approx(float(own.loc[own["ADEV"].idxmin(), "Tau (s)"]))


def test_wrong_units_are_named(tmp_path):
    """deg/s gyros and g accelerometers read with the default SI units: each mistake is named with its flag."""
    n = int(600 * FREQ)
    rng = np.random.default_rng(9)
    frame = pd.DataFrame({"time": np.arange(n) / FREQ,
                          "gx": 0.03 * math.sqrt(FREQ) * rng.standard_normal(n),  # 1.8 deg/sqrt(h) in deg/s
                          "az": -1.0 + 0.002 * rng.standard_normal(n)})            # gravity in g
    log = tmp_path / "units.csv"
    frame.to_csv(log, index=False)
    result = run(str(log))
    assert result.returncode == 0, result.stderr
    assert "--gyro-units deg/s" in result.stderr and "--accel-units g" in result.stderr
    right = run(str(log), "--gyro-units", "deg/s", "--accel-units", "g")
    assert right.returncode == 0 and "--gyro-units" not in right.stderr and "--accel-units" not in right.stderr


def test_bag_units_must_be_si(tmp_path):
    bag = tmp_path / "log.bag"
    bag.write_bytes(b"")
    result = run(str(bag), "--gyro-units", "deg/s")
    assert result.returncode == 2 and "SI units" in result.stderr and "--gyro-units" in result.stderr
