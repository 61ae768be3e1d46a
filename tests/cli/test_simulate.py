"""``avar simulate`` and :func:`avar.simulate_log`: a fitted model played back, written for real, read back.

The model read from a terms CSV is checked against the fitted model exactly (the theoretical Allan
variance of the per-sample processes equals the report's implied one), each conversion against its
closed form, and the logs are written as CSV and as ROS bags with the command line, then read back
by ``avar.read`` / ``avar report`` with no column options. The tolerances of the recovered terms are
the report's own standard errors (from its 95 % intervals); the 2-hour check of 3 % on N and 40 % on
K is benchmarks/bench_simulate_recheck.py.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
import yaml

import avar
from avar.fit.report.simulate import Term, channel_terms, parse_duration
from tests._support.cli_runner import cli

RATE = 200.0
Z95 = 1.959964
#: Kalibr densities (SI) of an ADIS16405-like IMU; K large enough to be resolved in 10 minutes.
KALIBR = {"gyroscope_noise_density": 6e-4, "gyroscope_random_walk": 8e-4,
          "accelerometer_noise_density": 3e-3, "accelerometer_random_walk": 4e-3,
          "rostopic": "/imu0", "update_rate": RATE}


def standard_errors(row) -> float:
    """Relative standard error of a term from its 95 % chi-squared interval (on the log scale)."""
    return (math.log(row["Upper"]) - math.log(row["Lower"])) / (2 * Z95)


@pytest.fixture(scope="module")
def kalibr_yaml(tmp_path_factory):
    path = tmp_path_factory.mktemp("kalibr") / "imu.yaml"
    path.write_text(yaml.safe_dump(KALIBR))
    return path


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """A 6-axis CSV log with white noise, random walk, a Gauss-Markov and a sinusoid, and its report."""
    folder = tmp_path_factory.mktemp("fitted")
    n, rate = 60_000, 100.0
    gyro = (avar.WN.from_continuous(1e-3, rate) + avar.RW.from_continuous(2e-4, rate)
            + avar.SIN.from_continuous(4e-3, 3.0, rate))
    accel = avar.WN.from_continuous(3e-3, rate) + avar.AR1(phi=math.exp(-1 / (rate * 2.0)), sigma2=2e-7)
    rng = np.random.default_rng(11)
    columns = {"time": np.arange(n) / rate}
    columns |= {f"gyro_{a}": gyro.simulate(n, seed=rng) for a in "xyz"}
    columns |= {f"acc_{a}": accel.simulate(n, seed=rng) for a in "xyz"}
    log = folder / "log.csv"
    pd.DataFrame(columns).to_csv(log, index=False)
    return log, avar.noise_report(avar.read(log))


def test_terms_csv_gives_back_the_fitted_model_exactly(fitted, tmp_path, capsys):
    log, report = fitted
    terms = tmp_path / "terms.csv"
    code, _, err = cli(capsys, "report", log, "--output", terms)
    assert code == 0, err
    source = channel_terms(terms)
    channels = source.channels
    assert source.rate is None and source.duration is None  # a CSV holds neither
    assert [c.channel for c in channels] == list(report.channels)
    assert [c.column for c in channels] == ["gx", "gy", "gz", "ax", "ay", "az"]
    kinds = set()
    for channel in channels:
        av = report.avs[channel.channel]
        model = channel.model(report.rate)
        kinds |= {p.name for p in model.components}
        np.testing.assert_allclose(model.theoretical_av(av.averaging_factors), report.implied_av(channel.channel),
                                   rtol=1e-9)
        assert sorted(p.name for p in model.components) == sorted(report.fits[channel.channel].kinds)
    assert {"WN", "SIN", "AR1"} <= kinds  # the shaped terms went through their two rows each


def test_every_conversion_is_the_inverse_of_the_reports():
    f = 200.0
    rows = [("g", "Gyroscope", "QN", "present", 2e-6, "rad"), ("g", "Gyroscope", "WN", "present", 1e-3, "rad/s/sqrt(Hz)"),
            ("g", "Gyroscope", "FN", "present", 5e-5, "rad/s"), ("g", "Gyroscope", "RW", "present", 2e-5, "rad/s^2/sqrt(Hz)"),
            ("g", "Gyroscope", "DR", "present", 3e-6, "rad/s^2"), ("g", "Gyroscope", "AR1_1", "present", 4e-4, "rad/s"),
            ("g", "Gyroscope", "AR1_1.T", "present", 0.5, "s"), ("g", "Gyroscope", "SIN_1", "present", 2e-3, "rad/s"),
            ("g", "Gyroscope", "SIN_1.f", "present", 7.5, "Hz"), ("g", "Gyroscope", "MIN", "measured", 1e-4, "rad/s"),
            ("t", "", "WN", "present", 0.25, "K/sqrt(Hz)"), ("t", "", "RW", "bound", None, "K*sqrt(Hz)/s"),
            ("t", "", "FN", "absent", None, "K")]
    table = pd.DataFrame(rows, columns=["Channel", "Sensor", "Process", "Status", "Value", "Unit"])
    gyro, temp = channel_terms(table).channels
    assert (gyro.column, gyro.sensor, temp.column, temp.sensor) == ("gx", "Gyroscope", "t", None)
    qn, wn, fn, rw, dr, ar1, sin = gyro.model(f).components
    assert qn.q2 == pytest.approx((2e-6 * f) ** 2, rel=1e-14)          # Q = sqrt(q2) / f
    assert wn.sigma2 == pytest.approx(1e-6 * f, rel=1e-14)              # N = sqrt(sigma2 / f)
    assert fn.b2 == pytest.approx(25e-10, rel=1e-14)                    # B = sqrt(b2)
    assert rw.gamma2 == pytest.approx(4e-10 / f, rel=1e-14)             # K = sqrt(gamma2 f)
    assert dr.omega == pytest.approx(3e-6 / f, rel=1e-14)               # R = omega f
    phi = math.exp(-1 / (f * 0.5))
    assert ar1.phi == pytest.approx(phi, rel=1e-14)                     # T = -1 / (f ln phi)
    assert ar1.sigma2 / (1 - phi**2) == pytest.approx(16e-8, rel=1e-12)  # sigma^2 = sigma2 / (1 - phi^2)
    assert (sin.amplitude, sin.f * f) == pytest.approx((2e-3, 7.5), rel=1e-14)
    assert temp.terms == (Term("WN", 0.25),)  # the bound and absent terms are not simulated
    with pytest.raises(ValueError, match="channel .g. has two QN terms"):
        channel_terms(pd.concat([table, table]))
    with pytest.raises(ValueError, match="7.5 Hz cannot be sampled at 10 Hz"):
        gyro.model(10.0)


def test_kalibr_yaml_to_csv_to_report_recovers_n_and_k(kalibr_yaml, tmp_path, capsys):
    log, terms = tmp_path / "sim.csv", tmp_path / "terms.csv"
    code, out, err = cli(capsys, "simulate", kalibr_yaml, "--duration", "10min", "--output", log, "--seed", "4")
    assert code == 0, err
    assert f"Wrote {log}: 120000 samples x 6 channels (gx, gy, gz, ax, ay, az) at 200 Hz" in out
    code, _, err = cli(capsys, "report", log, "--output", terms)  # no column, unit or rate option
    assert code == 0, err
    table = pd.read_csv(terms)
    assert table.groupby("Channel", sort=False)["Sensor"].first().to_dict() == {
        **dict.fromkeys(("gx", "gy", "gz"), "Gyroscope"), **dict.fromkeys(("ax", "ay", "az"), "Accelerometer")}
    resolved = {"WN": 0, "RW": 0}
    for process, key in (("WN", "noise_density"), ("RW", "random_walk")):
        for sensor, prefix in (("Gyroscope", "gyroscope_"), ("Accelerometer", "accelerometer_")):
            rows = table[(table["Sensor"] == sensor) & (table["Process"] == process) & (table["Status"] == "present")]
            resolved[process] += len(rows)
            for _, row in rows.iterrows():
                error = math.log(row["Value"] / KALIBR[prefix + key])
                assert abs(error) < 4 * standard_errors(row), (row["Channel"], process, row["Value"])
                if process == "WN":
                    assert abs(error) < 0.03
    # N on every axis; K where the selection keeps a random walk (within 10 minutes it may take the
    # random walk for a Gauss-Markov term of long correlation time: the benchmark's 2 h log does not)
    assert resolved["WN"] == 6 and resolved["RW"] >= 4, resolved


def test_bags_and_csv_are_written_and_read_back_with_no_options(kalibr_yaml, tmp_path, capsys):
    expected = avar.simulate_log(kalibr_yaml, duration=60, seed=3)
    assert expected.names == ("gx", "gy", "gz", "ax", "ay", "az") and expected.n_samples == 12_000
    for suffix in (".db3", ".mcap", ".bag"):
        path = tmp_path / f"sim{suffix}"
        code, out, err = cli(capsys, "simulate", kalibr_yaml, "--duration", "60", "--output", path, "--seed", "3")
        assert code == 0, err
        imu = avar.read(path)
        assert isinstance(imu, avar.IMU) and imu.name == "/imu0", suffix
        assert imu.sensor_types == ("Gyroscope",) * 3 + ("Accelerometer",) * 3
        np.testing.assert_array_equal(imu.data, np.column_stack([expected[c] for c in expected.names]))  # bit for bit
        assert imu.rate == pytest.approx(RATE, rel=1e-9)
    for suffix in (".db3", ".mcap"):
        code, out, err = cli(capsys, "report", tmp_path / f"sim{suffix}")  # no topic, column or unit option
        assert code == 0, err
        assert "Gyro. X (gyroscope)" in out and "Accel. Z (accelerometer)" in out
    path = tmp_path / "sim.csv"
    assert cli(capsys, "simulate", kalibr_yaml, "--duration", "1min", "--output", path, "--seed", "3")[0] == 0
    recording = avar.read(path)
    assert recording.names == expected.names and recording.time_column == "time"
    assert recording.rate == pytest.approx(RATE, rel=1e-9)
    for name in expected.names:
        np.testing.assert_array_equal(recording[name], expected[name])  # shortest exact decimals: bit for bit


def test_user_errors_are_refused_before_anything_is_written(kalibr_yaml, fitted, tmp_path, capsys):
    _, report = fitted
    terms = tmp_path / "terms.csv"
    report.table.to_csv(terms, index=False)
    out = tmp_path / "sim.csv"
    code, _, err = cli(capsys, "simulate", terms, "--duration", "1h", "--output", out)
    assert code == 2 and "give --rate" in err and not out.exists()
    code, _, err = cli(capsys, "simulate", kalibr_yaml, "--duration", "1 week", "--output", out)
    assert code == 2 and "--duration" in err and not out.exists()
    code, _, err = cli(capsys, "simulate", kalibr_yaml, "--duration", "60", "--output", tmp_path / "sim.txt")
    assert code == 2 and ".mcap" in err
    code, _, err = cli(capsys, "simulate", kalibr_yaml, "--duration", "60", "--output", out, "--topic", "/x")
    assert code == 2 and "--topic" in err
    out.write_text("keep me")
    code, _, err = cli(capsys, "simulate", kalibr_yaml, "--duration", "60", "--output", out)
    assert code == 2 and "--force" in err and out.read_text() == "keep me"
    gyro_only = tmp_path / "gyro.yaml"
    gyro_only.write_text("imu0:\n  gyroscope_noise_density: 1e-3\n  update_rate: 100\n")  # nested, 1e-3 a string
    bag = tmp_path / "gyro.db3"
    code, _, err = cli(capsys, "simulate", gyro_only, "--duration", "60", "--output", bag)
    assert code == 2 and "three gyroscope and three accelerometer axes" in err and not bag.exists()
    assert not list(tmp_path.glob(".gyro.db3*"))  # the temporary folder is gone
    code, _, err = cli(capsys, "simulate", gyro_only, "--duration", "60", "--output", tmp_path / "gyro.csv")
    assert code == 0 and pd.read_csv(tmp_path / "gyro.csv").columns.tolist() == ["time", "gx", "gy", "gz"]
    no_rate = tmp_path / "no_rate.yaml"
    no_rate.write_text("accelerometer_noise_density: 2.0e-3\n")
    code, _, err = cli(capsys, "simulate", no_rate, "--duration", "60", "--output", tmp_path / "a.csv")
    assert code == 2 and "the yaml has no update_rate; give --rate" in err


def test_simulate_log_defaults_to_the_reports_length_and_rate(fitted):
    _, report = fitted
    log = avar.simulate_log(report, seed=5)
    assert (log.n_samples, log.rate) == (report.n_samples, report.rate)
    assert log.names == ("gx", "gy", "gz", "ax", "ay", "az")
    again = avar.simulate_log(report, seed=5)
    assert all(np.array_equal(log[c], again[c]) for c in log.names)
    assert not np.array_equal(log["gx"], avar.simulate_log(report, seed=6)["gx"])
    short = avar.simulate_log(report, duration="90 s", rate=50.0, seed=5)
    assert (short.n_samples, short.rate) == (4500, 50.0)
    with pytest.raises(ValueError, match="rate"):
        avar.simulate_log(report.table, duration=60)
    with pytest.raises(ValueError, match="duration"):
        avar.simulate_log(report.table, rate=100.0)
    with pytest.raises(TypeError, match="terms must be"):
        avar.simulate_log(42, duration=60, rate=100.0)


def test_durations_are_seconds_or_a_number_with_a_unit():
    assert [parse_duration(v) for v in (7200, 7200.0, "7200", "2h", "2 h", "120min", "0.5d", "1e3 s")] == [
        7200.0, 7200.0, 7200.0, 7200.0, 7200.0, 7200.0, 43200.0, 1000.0]
    for bad in ("2 weeks", "h", "-5", "0", ""):
        with pytest.raises(ValueError, match="duration"):
            parse_duration(bad)
    with pytest.raises(TypeError, match="duration"):
        parse_duration(True)
