"""Tests of the Kalibr imu.yaml export: written with PyYAML and read back."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
import yaml

import avar
from avar.models import WN
from tests._support.imu_logs import ACCEL_TRUTH, GYRO_TRUTH, imu_columns

FREQ = 100.0
N_SAMPLES = 360_000
G0 = 9.80665
DEG = math.pi / 180


@pytest.fixture(scope="module")
def recording():
    columns = imu_columns(N_SAMPLES, FREQ, seed=21, gyro="gyro_{}", accel="acc_{}")  # deg/s, g
    return SimpleNamespace(columns=pd.DataFrame(columns), freq=FREQ, topic="/imu0/data", source="flight.bag")


@pytest.fixture(scope="module")
def report(recording):
    return avar.noise_report(recording, gyro_units="deg/s", accel_units="g")


def test_kalibr_yaml_holds_the_simulated_densities_in_si(report, tmp_path):
    path = report.to_kalibr(tmp_path / "imu.yaml", axis="mean")  # the axes share one truth
    fields = yaml.safe_load(path.read_text())
    assert list(fields) == ["gyroscope_noise_density", "gyroscope_random_walk", "accelerometer_noise_density",
                            "accelerometer_random_walk", "rostopic", "update_rate"]
    assert fields["gyroscope_noise_density"] == pytest.approx(GYRO_TRUTH["N"] * DEG, rel=0.03)
    assert fields["gyroscope_random_walk"] == pytest.approx(GYRO_TRUTH["K"] * DEG, rel=0.15)
    assert fields["accelerometer_noise_density"] == pytest.approx(ACCEL_TRUTH["N"] * G0, rel=0.03)
    assert fields["accelerometer_random_walk"] == pytest.approx(ACCEL_TRUTH["K"] * G0, rel=0.15)
    assert fields["rostopic"] == "/imu0/data"
    assert fields["update_rate"] == 100.0


def test_densities_are_the_largest_axis_or_the_mean(report):
    gyro_wn = [report.value(f"gyro_{a}", "WN") for a in "xyz"]
    acc_rw = [report.value(f"acc_{a}", "RW") for a in "xyz"]
    largest, mean = report.kalibr(), report.kalibr(axis="mean")
    assert largest["gyroscope_noise_density"] == max(gyro_wn)
    assert largest["accelerometer_random_walk"] == max(acc_rw)
    assert mean["gyroscope_noise_density"] == pytest.approx(np.mean(gyro_wn), rel=1e-14)
    assert mean["accelerometer_random_walk"] == pytest.approx(np.mean(acc_rw), rel=1e-14)
    with pytest.raises(ValueError, match="axis"):
        report.kalibr(axis="median")


def test_every_axis_is_named_in_a_comment_above_its_density(report, tmp_path):
    text = report.to_kalibr(tmp_path / "imu.yaml").read_text()
    lines = text.splitlines()
    for key, process, prefix in (("gyroscope_noise_density", "WN", "gyro"), ("accelerometer_random_walk", "RW", "acc")):
        at = next(k for k, line in enumerate(lines) if line.startswith(key + ":"))
        comment = lines[at - 1]
        assert comment.startswith("# largest over the axes:")
        for axis in "xyz":
            assert f"{prefix}_{axis} {report.value(f'{prefix}_{axis}', process):.4g}" in comment


def test_topic_rate_and_overrides(report, recording, tmp_path):
    fields = report.kalibr(rostopic="/other", update_rate=200, gyroscope_random_walk=1e-5)
    assert (fields["rostopic"], fields["update_rate"], fields["gyroscope_random_walk"]) == ("/other", 200.0, 1e-5)
    plain = avar.noise_report(recording.columns[["gyro_x"]], gyro_units="deg/s", rate=FREQ)
    assert plain.kalibr()["rostopic"] == "/imu0"  # Kalibr's example topic when not from a bag
    assert list(plain.kalibr()) == ["gyroscope_noise_density", "gyroscope_random_walk", "rostopic", "update_rate"]
    with pytest.raises(TypeError, match="unknown Kalibr field"):
        report.kalibr(gyro_noise=1.0)


def test_existing_file_is_refused_and_nothing_half_written(report, tmp_path):
    path = tmp_path / "imu.yaml"
    path.write_text("keep me\n")
    with pytest.raises(FileExistsError, match="force"):
        report.to_kalibr(path)
    assert path.read_text() == "keep me\n"
    report.to_kalibr(path, force=True)
    assert yaml.safe_load(path.read_text())["update_rate"] == 100.0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["imu.yaml"]  # no temporary left behind


def test_an_unresolved_random_walk_gives_its_bound_with_a_comment(tmp_path):
    x = WN(sigma2=1e-4).simulate(50_000, seed=1)
    rep = avar.noise_report(x, gyro_units="rad/s", rate=100.0)
    row = rep.table.set_index("Process").loc["RW"]
    assert row["Status"] == "bound" and row["Value"] is pd.NA
    path = rep.to_kalibr(tmp_path / "imu.yaml")
    fields = yaml.safe_load(path.read_text())
    assert fields["gyroscope_random_walk"] == pytest.approx(float(row["Upper"]), rel=1e-12)
    lines = path.read_text().splitlines()
    comment = lines[lines.index(f"gyroscope_random_walk: {fields['gyroscope_random_walk']!r}") - 1]
    assert "x " in comment and "(one-sided 97.5 % upper bound)" in comment and "not resolved on x" in comment
    # a white noise of 1e-4 per sample at 100 Hz: no random walk, so the bound must be small but positive
    assert 0 < fields["gyroscope_random_walk"] < 1e-3
    assert rep.kalibr(gyroscope_random_walk=1e-6)["gyroscope_random_walk"] == 1e-6
    with pytest.raises(ValueError, match="no gyroscope or accelerometer"):
        avar.noise_report(x, rate=100.0).kalibr()
