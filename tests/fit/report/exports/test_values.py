"""The shared picking of export values: bounds marked, inflate, the Gauss-Markov conversion, errors."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml

import avar
from avar.fit.report.exports.registry import DEFAULT_FILES, EXPORTS, export, export_notes
from avar.fit.report.exports.values import check_inflate, equivalent_random_walk, gauss_markov, number
from avar.fit.report.noise_terms import ACCEL, GYRO


def markov_adev(tau, sigma, time):
    """IEEE Std 952-1997 Annex C.6: the Allan deviation of a first-order Gauss-Markov process."""
    q2 = 2.0 * sigma**2 / time
    x = tau / time
    return np.sqrt(q2 * time**2 / tau * (1.0 - (3.0 - 4.0 * np.exp(-x) + np.exp(-2.0 * x)) / (2.0 * x)))


def test_gauss_markov_peaks_on_the_bias_instability_floor_at_the_minimum():
    b, tau_min = 3e-5, 120.0
    gm = gauss_markov(b, tau_min)
    taus = np.geomspace(tau_min / 10, tau_min * 10, 20001)
    ad = markov_adev(taus, gm.sigma, gm.correlation_time)
    peak = int(np.argmax(ad))
    assert taus[peak] == pytest.approx(tau_min, rel=1e-3)  # the peak sits at the AD minimum's tau
    assert ad[peak] == pytest.approx(math.sqrt(2 * math.log(2) / math.pi) * b, rel=1e-6)  # on 0.664 B
    assert gm.driving == pytest.approx(math.sqrt(2 * gm.sigma**2 / gm.correlation_time), rel=1e-12)
    assert equivalent_random_walk(gm.sigma, 400.0) * math.sqrt(400.0) == pytest.approx(gm.sigma, rel=1e-12)
    with pytest.raises(ValueError, match="tau_min"):
        gauss_markov(b, 0.0)


@pytest.mark.parametrize("value", [200.0, 1e-05, 1.2345678901234567e-07, 0.000123456789, 3.0, 9.80665])
def test_numbers_read_back_exactly_and_look_real(value):
    text = number(value)
    assert float(text) == value and ("." in text)
    assert yaml.safe_load(f"k: {text}")["k"] == value


@pytest.mark.parametrize("bad", [0, -1.0, float("nan"), float("inf"), "ten", True])
def test_inflate_must_be_a_finite_factor(bad, imu_report):
    with pytest.raises(ValueError, match="inflate"):
        check_inflate(bad)
    with pytest.raises(ValueError, match="inflate"):
        imu_report.export("vins", inflate=bad)


def test_names_and_axis_are_checked(imu_report):
    assert EXPORTS == ("kalibr", "openvins", "vins", "orbslam3", "basalt", "matlab")
    with pytest.raises(ValueError, match="name must be one of"):
        imu_report.export("okvis")
    with pytest.raises(ValueError, match="axis must be 'max'"):
        imu_report.export("basalt", axis="median")


def test_bounds_only_terms_are_marked_in_every_export(white_report, expected):
    row = white_report.table.set_index(["Channel", "Process"]).loc[("gx", "RW")]
    assert row["Status"] == "bound"
    for name in ("kalibr", "openvins", "vins", "orbslam3", "matlab"):
        text = white_report.export(name)
        assert "one-sided 97.5 % upper bound" in text, name
        assert "not resolved on gx: an upper bound, not a measurement" in text, name
        assert "95 % upper bound)" not in text.replace("97.5 % upper bound)", ""), name  # one wording only
    body = json.loads(white_report.export("basalt"))["value0"]
    assert body["gyro_bias_std"] == [expected(white_report, GYRO, "RW")] * 3 == [float(row["Upper"])] * 3
    notes = export_notes(white_report, "basalt")
    assert any(line.startswith("gyro_bias_std: rad/s^2/sqrt(Hz)") and "not resolved on gx" in line for line in notes)


def test_inflation_is_written_with_its_reason(imu_report):
    for name in ("kalibr", "openvins", "vins", "orbslam3", "matlab"):
        assert "multiplied by inflate = 10" in imu_report.export(name, inflate=10), name
        assert "inflate = 1: the measured static values" in imu_report.export(name), name
    assert any("inflate = 10" in line for line in export_notes(imu_report, "basalt", inflate=10))
    assert imu_report.value("gyro_x", "WN") == imu_report.table.set_index(["Channel", "Process"]).loc[
        ("gyro_x", "WN"), "Value"]  # the table keeps the measured value


def test_estimators_that_need_both_sensors_say_so():
    x = avar.WN(sigma2=1e-4).simulate(20_000, seed=2)
    gyro_only = avar.noise_report(x, gyro_units="rad/s", rate=100.0)
    for name in ("openvins", "vins", "orbslam3", "basalt"):
        with pytest.raises(ValueError, match=f"{name} export needs gyroscope and accelerometer.*accelerometer"):
            gyro_only.export(name)
    text = gyro_only.export("matlab")  # MATLAB's imuSensor keeps an ideal accelerometer
    assert "gyro = gyroparams();" in text and "accelparams()" not in text
    assert list(yaml.safe_load(gyro_only.export("kalibr"))) == ["gyroscope_noise_density", "gyroscope_random_walk",
                                                                 "rostopic", "update_rate"]


def test_written_files_follow_the_output_rules(imu_report, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = export(imu_report, "orbslam3", True)
    assert (tmp_path / DEFAULT_FILES["orbslam3"]).read_text() == text
    with pytest.raises(FileExistsError, match="force"):
        imu_report.export("orbslam3", DEFAULT_FILES["orbslam3"])
    imu_report.export("orbslam3", DEFAULT_FILES["orbslam3"], inflate=3, force=True)
    assert "inflate = 3" in (tmp_path / "orbslam3_imu.yaml").read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["orbslam3_imu.yaml"]  # no temporary left


def test_opencv_topics_are_quoted_and_read_back(imu_report, tmp_path):
    cv2 = pytest.importorskip("cv2")
    from dataclasses import replace

    odd = replace(imu_report, topic='/imu "0"\\raw #1')
    path = tmp_path / "vins.yaml"
    odd.export("vins", path)
    storage = cv2.FileStorage(str(path), cv2.FILE_STORAGE_READ)
    assert storage.getNode("imu_topic").string() == '/imu "0"\\raw #1'
    with pytest.raises(ValueError, match="control or format character"):
        replace(imu_report, topic="/imu\n0").export("vins")


def test_bias_instability_lines_give_the_gauss_markov_equivalent(imu_report):
    text = imu_report.export("vins")
    line = next(line for line in text.splitlines() if line.startswith("# gyroscope bias instability B ="))
    b = float(line.split("B = ")[1].split()[0])
    table = imu_report.table
    fn = table[(table["Sensor"] == GYRO) & (table["Process"] == "FN")]
    values = [float(r["Value"]) if r["Status"] == "present" else float(r["Upper"]) for _, r in fn.iterrows()]
    assert b == pytest.approx(max(values), rel=1e-5)
    following = text.splitlines()[text.splitlines().index(line) + 1]
    assert "Gauss-Markov" in following and "T = " in following
    assert ACCEL.lower() in text
