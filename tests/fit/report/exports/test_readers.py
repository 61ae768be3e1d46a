"""Every export written from a simulated IMU's report and read back as its estimator reads it.

Kalibr: PyYAML; OpenVINS, VINS, ORB-SLAM3: OpenCV ``cv2.FileStorage`` (the reader their C++ uses);
Basalt: ``json``; MATLAB: the script's assignments parsed. Each value must equal the report's
(largest over the axes, or the mean), in SI continuous time, times ``inflate``, read back exactly.
"""

from __future__ import annotations

import json
import math
import re

import pytest
import yaml

from avar.fit.report.noise_terms import ACCEL, GYRO

cv2 = pytest.importorskip("cv2")

RATE = 200.0
DEG = 3.141592653589793 / 180


def opencv(path):
    storage = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    assert storage.isOpened(), path
    return storage


@pytest.mark.parametrize("axis, inflate", [("max", 1.0), ("mean", 10.0)])
def test_kalibr_imu_yaml(imu_report, expected, tmp_path, axis, inflate):
    path = tmp_path / "imu.yaml"
    text = imu_report.export("kalibr", path, axis=axis, inflate=inflate)
    fields = yaml.safe_load(path.read_text())
    assert path.read_text() == text
    assert fields["gyroscope_noise_density"] == expected(imu_report, GYRO, "WN", axis) * inflate
    assert fields["gyroscope_random_walk"] == expected(imu_report, GYRO, "RW", axis) * inflate
    assert fields["accelerometer_noise_density"] == expected(imu_report, ACCEL, "WN", axis) * inflate
    assert fields["accelerometer_random_walk"] == expected(imu_report, ACCEL, "RW", axis) * inflate
    assert (fields["rostopic"], fields["update_rate"]) == ("/imu0/data", RATE)
    # the simulated truth, in SI continuous time (N: 3e-3 deg/s/sqrt(Hz))
    assert fields["gyroscope_noise_density"] == pytest.approx(3e-3 * DEG * inflate, rel=0.03)
    assert fields["accelerometer_noise_density"] == pytest.approx(2e-5 * 9.80665 * inflate, rel=0.03)


@pytest.mark.parametrize("axis, inflate", [("max", 1.0), ("mean", 10.0)])
def test_openvins_imu0_node(imu_report, expected, tmp_path, axis, inflate):
    path = tmp_path / "kalibr_imu_chain.yaml"
    imu_report.export("openvins", path, axis=axis, inflate=inflate)
    assert path.read_text().startswith("%YAML:1.0\n")
    storage = opencv(path)  # kept alive while its nodes are read
    imu0 = storage.getNode("imu0")
    for key, kind, process in (("gyroscope_noise_density", GYRO, "WN"), ("gyroscope_random_walk", GYRO, "RW"),
                               ("accelerometer_noise_density", ACCEL, "WN"), ("accelerometer_random_walk", ACCEL, "RW")):
        node = imu0.getNode(key)
        assert node.isReal(), key
        assert node.real() == expected(imu_report, kind, process, axis) * inflate, key
    assert imu0.getNode("update_rate").real() == RATE
    assert imu0.getNode("time_offset").real() == 0.0
    assert imu0.getNode("rostopic").string() == "/imu0/data"
    assert imu0.getNode("model").string() == "kalibr"
    for key, diagonal in (("Tw", 1.0), ("Ta", 1.0), ("R_IMUtoGYRO", 1.0), ("R_IMUtoACC", 1.0), ("Tg", 0.0)):
        rows = imu0.getNode(key)  # ov_core::YamlParser reads a matrix as rows of a sequence
        assert rows.size() == 3, key
        assert [[rows.at(r).at(c).real() for c in range(3)] for r in range(3)] == \
               [[diagonal if r == c else 0.0 for c in range(3)] for r in range(3)], key
    assert imu0.getNode("T_i_b").size() == 4


@pytest.mark.parametrize("axis, inflate", [("max", 1.0), ("mean", 2.5)])
def test_vins_keys(imu_report, expected, tmp_path, axis, inflate):
    path = tmp_path / "vins_imu.yaml"
    imu_report.export("vins", path, axis=axis, inflate=inflate)
    storage = opencv(path)
    for key, kind, process in (("acc_n", ACCEL, "WN"), ("gyr_n", GYRO, "WN"), ("acc_w", ACCEL, "RW"),
                               ("gyr_w", GYRO, "RW")):
        # VINS takes discrete-time values: its integration_base.h uses them per sample (no rate conversion)
        value = expected(imu_report, kind, process, axis) * inflate * math.sqrt(RATE)
        assert storage.getNode(key).real() == pytest.approx(value, rel=1e-15, abs=0), key
    assert storage.getNode("g_norm").real() == 9.80665
    assert storage.getNode("imu").isInt() and int(storage.getNode("imu").real()) == 1
    assert storage.getNode("imu_topic").string() == "/imu0/data"


@pytest.mark.parametrize("axis, inflate", [("max", 1.0), ("mean", 10.0)])
def test_orbslam3_keys_are_reals(imu_report, expected, tmp_path, axis, inflate):
    path = tmp_path / "orbslam3_imu.yaml"
    imu_report.export("orbslam3", path, axis=axis, inflate=inflate)
    storage = opencv(path)
    for key, kind, process in (("IMU.NoiseGyro", GYRO, "WN"), ("IMU.NoiseAcc", ACCEL, "WN"),
                               ("IMU.GyroWalk", GYRO, "RW"), ("IMU.AccWalk", ACCEL, "RW")):
        node = storage.getNode(key)
        assert node.isReal(), key  # Settings::readIMU aborts on a key that is not a real number
        assert node.real() == expected(imu_report, kind, process, axis) * inflate, key
    frequency = storage.getNode("IMU.Frequency")
    assert frequency.isReal() and frequency.real() == RATE


@pytest.mark.parametrize("axis, inflate", [("max", 1.0), ("mean", 10.0)])
def test_basalt_value0_vectors(imu_report, expected, tmp_path, axis, inflate):
    path = tmp_path / "basalt_calib.json"
    imu_report.export("basalt", path, axis=axis, inflate=inflate)
    body = json.loads(path.read_text())["value0"]
    assert body["imu_update_rate"] == RATE
    for key, kind, process in (("accel_noise_std", ACCEL, "WN"), ("gyro_noise_std", GYRO, "WN"),
                               ("accel_bias_std", ACCEL, "RW"), ("gyro_bias_std", GYRO, "RW")):
        assert body[key] == [expected(imu_report, kind, process, axis) * inflate] * 3, key


ASSIGNMENT = re.compile(r"^(gyro|accel)\.(\w+) = ([-+0-9.eE]+);$", re.M)


@pytest.mark.parametrize("axis, inflate", [("max", 1.0), ("mean", 10.0)])
def test_matlab_script(imu_report, expected, tmp_path, axis, inflate):
    path = tmp_path / "imu_params.m"
    imu_report.export("matlab", path, axis=axis, inflate=inflate)
    text = path.read_text()
    assert "gyro = gyroparams();" in text and "accel = accelparams();" in text
    assert "imu = imuSensor('accel-gyro', 'SampleRate', 200.0, 'Gyroscope', gyro, 'Accelerometer', accel);" in text
    values = {(sensor, prop): float(value) for sensor, prop, value in ASSIGNMENT.findall(text)}
    assert len(values) == 6
    for sensor, kind in (("gyro", GYRO), ("accel", ACCEL)):
        assert values[sensor, "NoiseDensity"] == expected(imu_report, kind, "WN", axis) * inflate
        assert values[sensor, "RandomWalk"] == expected(imu_report, kind, "RW", axis) * inflate
        assert values[sensor, "BiasInstability"] == expected(imu_report, kind, "FN", axis)  # never inflated
    assert all(line.startswith("%") or not line or "=" in line for line in text.splitlines())


def test_every_value_has_at_least_six_significant_digits(imu_report):
    for name in ("kalibr", "openvins", "vins", "orbslam3", "matlab"):
        text = imu_report.export(name)
        for line in text.splitlines():
            match = re.search(r"(?:noise_density|random_walk|acc_n|gyr_n|acc_w|gyr_w|Noise\w*|\w*Walk|"
                              r"BiasInstability)\s*[:=]\s*([0-9.eE+-]+)", line)
            if match and not line.lstrip().startswith(("#", "%")):
                digits = match.group(1).lower().split("e")[0].replace(".", "").lstrip("0")
                assert len(digits) >= 6, (name, line)
