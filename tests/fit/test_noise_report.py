"""Tests of avar.noise_report: IEEE 952 terms of simulated gyros and accelerometers of known truth."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import avar
from avar.fit.noise_fit import fit_noise_terms, term_regressors
from avar.models import FN, QN, RW, WN
from avar.models.flicker import FLICKER_AV_FACTOR

FREQ = 100.0
N_SAMPLES = 360_000  # one hour
# gyroscope truth in deg/s units: white noise meets the flicker plateau at 5 s, flicker meets the walk at 59 s
N_DEG, B_DEG, K_DEG = 3e-3, 2e-3, 3e-4
DEG = math.pi / 180


def gyro_model(scale=1.0):
    return (WN.from_continuous(N_DEG * scale, FREQ) + FN.from_continuous(B_DEG * scale, FREQ)
            + RW.from_continuous(K_DEG * scale, FREQ))


@pytest.fixture(scope="module")
def gyro():
    return gyro_model().simulate(N_SAMPLES, seed=11)


@pytest.fixture(scope="module")
def report(gyro):
    return avar.noise_report(gyro, gyro_units="deg/s", rate=FREQ)


def test_terms_match_the_simulated_truth(report):
    assert report.value("x", "WN") == pytest.approx(N_DEG * DEG, rel=0.03)
    assert report.value("x", "FN") == pytest.approx(B_DEG * DEG, rel=0.20)
    assert report.value("x", "RW") == pytest.approx(K_DEG * DEG, rel=0.30)
    assert report.value("x", "QN") is None and report.value("x", "DR") is None


def test_customary_units_follow_ieee_952(report):
    table = report.table.set_index("Process")
    n_si, b_si, k_si = (report.value("x", p) for p in ("WN", "FN", "RW"))
    # written out independently: deg/sqrt(h) = deg/s * sqrt(3600 s/h); deg/h = deg/s * 3600; deg/h/sqrt(h)
    assert table.loc["WN", "Customary"] == pytest.approx(n_si / DEG * 60, rel=1e-12)
    assert table.loc["FN", "Customary"] == pytest.approx(b_si / DEG * 3600, rel=1e-12)
    assert table.loc["RW", "Customary"] == pytest.approx(k_si / DEG * 3600 * 60, rel=1e-12)
    assert list(table.loc[["WN", "FN", "RW"], "Customary unit"]) == ["deg/sqrt(h)", "deg/h", "deg/h/sqrt(h)"]
    assert list(table.loc[["WN", "FN", "RW"], "Unit"]) == ["rad/s/sqrt(Hz)", "rad/s", "rad/s^2/sqrt(Hz)"]
    assert list(table["Term"]) == ["Quantization", "Angle random walk",
                                   "Bias instability B (AD = 0.664 B)", "Rate random walk",
                                   "Rate ramp", "AD minimum (in-run bias stability)"]


def test_units_of_the_data_only_rescale(gyro, report):
    in_rad = avar.noise_report(gyro * DEG, gyro_units="rad/s", rate=FREQ)
    in_deg_h = avar.noise_report(gyro * 3600, gyro_units="deg/h", rate=FREQ)
    for other in (in_rad, in_deg_h):
        for process in ("WN", "FN", "RW"):
            assert other.value("x", process) == pytest.approx(report.value("x", process), rel=1e-9)


def test_absent_processes_are_absent_never_nan(report):
    table = report.table
    absent = table[table["Status"] == "absent"]
    assert list(absent["Process"]) == ["QN", "DR"]
    assert all(v is pd.NA for v in absent["Value"])
    present = table[table["Status"].isin(["present", "measured"])]
    values = present[["Value", "Lower", "Upper"]].to_numpy(dtype=float)
    assert np.all(np.isfinite(values)) and np.all(values[:, 1] < values[:, 0]) and np.all(values[:, 0] < values[:, 2])
    assert "absent" in str(report) and "nan" not in str(report).lower()


def test_white_noise_alone_reports_only_white_noise():
    x = WN(sigma2=1e-4).simulate(100_000, seed=2)
    rep = avar.noise_report(x, accel_units="m/s^2", rate=50.0)
    statuses = dict(zip(rep.table["Process"], rep.table["Status"]))
    # the terms an engineer needs are bounded when the data do not show them; the others absent
    assert statuses == {"QN": "absent", "WN": "present", "FN": "bound", "RW": "bound", "DR": "absent", "MIN": "measured"}
    table = rep.table.set_index("Process")
    assert table.loc["FN", "Value"] is pd.NA and table.loc["FN", "Upper"] > 0
    # sigma2 per sample = N^2 f
    assert rep.value("x", "WN") == pytest.approx(math.sqrt(1e-4 / 50.0), rel=0.01)
    assert list(rep.table["Term"])[1] == "Velocity random walk"


def test_quantization_is_found():
    x = (QN(q2=0.05) + WN(sigma2=0.01)).simulate(200_000, seed=3)
    rep = avar.noise_report(x, rate=10.0)
    # QN.from_continuous: q2 = Q^2 f^2
    assert rep.value("x", "QN") == pytest.approx(math.sqrt(0.05) / 10.0, rel=0.05)
    assert rep.table.set_index("Process").loc["QN", "Unit"] == "u s"  # unknown sensor: data units


def test_accelerometer_units(gyro):
    # the same numbers read as an accelerometer in g: SI = g0 times, ug = B[g] * 1e6
    rep = avar.noise_report(gyro, accel_units="g", rate=FREQ)
    b_g = math.sqrt([c.scale for c in rep.fits["x"].components if c.kind == "FN"][0])
    assert rep.value("x", "FN") == pytest.approx(b_g * 9.80665, rel=1e-12)
    assert rep.value("x", "FN", customary=True) == pytest.approx(b_g * 1e6, rel=1e-12)
    assert rep.value("x", "WN", customary=True) == pytest.approx(rep.value("x", "WN") * 60, rel=1e-12)
    in_mg = avar.noise_report(gyro * 1000, accel_units="mg", rate=FREQ)
    assert in_mg.value("x", "FN") == pytest.approx(rep.value("x", "FN"), rel=1e-9)


def test_the_allan_deviation_minimum_is_the_empirical_one(report):
    row = report.table.set_index("Process").loc["MIN"]
    av = report.avs["x"]
    at = int(np.argmin(av.adev))
    assert row["Tau (s)"] == av.levels[at]
    assert row["Value"] == pytest.approx(av.adev[at] * DEG, rel=1e-12)
    assert row["Customary"] == pytest.approx(av.adev[at] * 3600, rel=1e-12)  # deg/h
    assert row["Customary unit"] == "deg/h" and row["Lower"] < row["Value"] < row["Upper"]
    assert 5.0 < row["Tau (s)"] < 60.0  # between the crossings of the truth
    # the IEEE plateau convention: the flicker line of the fit is 0.664 B
    assert math.sqrt(FLICKER_AV_FACTOR) == pytest.approx(0.664, abs=5e-4)


def test_the_joint_fit_recovers_an_exact_curve():
    tau = 2.0 ** np.arange(-4, 12)
    truth = {"QN": 0.0, "WN": 0.3**2, "FN": 0.05**2, "RW": 0.002**2, "DR": 0.0}
    av = term_regressors(tau) @ np.array(list(truth.values()))
    fit = fit_noise_terms(tau, av, np.full(tau.size, 1e4))
    for term, value in truth.items():
        assert fit.squared[term] == pytest.approx(value, rel=1e-8, abs=1e-20)
    assert fit.present == {"QN": False, "WN": True, "FN": True, "RW": True, "DR": False}
    assert FLICKER_AV_FACTOR == pytest.approx(2 * math.log(2) / math.pi)
    np.testing.assert_allclose(fit.model_av(tau), av, rtol=1e-8)


def test_every_input_kind_gives_the_same_terms(gyro, report):
    data = np.column_stack([gyro, gyro[::-1].copy()])
    frame = pd.DataFrame({"gyro_x": data[:, 0], "gyro_y": data[:, 1]})
    imu = avar.IMU(frame, freq=FREQ, units={"gyro": "deg/s"})
    recording = SimpleNamespace(columns=frame, freq=FREQ, topic="/imu", source="log.bag")
    mapping = SimpleNamespace(columns={"gyro_x": data[:, 0]}, freq=FREQ)
    reports = [
        avar.noise_report(imu),
        avar.noise_report(avar.avar(imu, taus=2.0 ** np.arange(18) / FREQ)),
        avar.noise_report(frame, gyro_units="deg/s", rate=FREQ),
        avar.noise_report(recording, gyro_units="deg/s"),
        avar.noise_report(mapping, gyro_units="deg/s"),
        avar.noise_report(avar.avar(gyro, freq=FREQ, taus=2.0 ** np.arange(18) / FREQ), gyro_units="deg/s"),
    ]
    for rep in reports:
        channel = rep.channels[0]
        assert rep.sensor_types[0] == "Gyroscope" or rep.channels == ("x",)
        for process in ("WN", "FN", "RW"):
            assert rep.value(channel, process) == pytest.approx(report.value("x", process), rel=1e-12)
    assert reports[3].topic == "/imu" and reports[3].source == "log.bag"
    assert reports[0].channels == ("gyro_x", "gyro_y")


def test_bad_arguments():
    x = WN(sigma2=1).simulate(1000, seed=1)
    with pytest.raises(ValueError, match="gyro_units"):
        avar.noise_report(x, gyro_units="rpm")
    with pytest.raises(ValueError, match="not both"):
        avar.noise_report(x, gyro_units="rad/s", accel_units="g")
    with pytest.raises(ValueError, match="confidence"):
        avar.noise_report(x, confidence=1.5)
    with pytest.raises(ValueError, match="at least 3"):
        avar.noise_report(x[:5])
    with pytest.raises(ValueError, match="gyro column"):
        avar.noise_report(pd.DataFrame({"a": x}), gyro=["b"], rate=1.0)
    with pytest.raises(KeyError, match="no term"):
        avar.noise_report(x).value("x", "XX")
