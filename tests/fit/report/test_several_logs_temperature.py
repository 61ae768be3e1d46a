"""Bias versus temperature in ``avar.noise_reports``: the slope, its standard error, the drift warning."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import avar
from avar.fit.report.sessions.temperature import DRIFT_LIMIT, is_temperature_name, temperature_fit

RATE = 100.0
N = 30_000


def drifting_temperature(n: int, rise: float) -> np.ndarray:
    """A warming log: a linear rise plus a slow oscillation of 0.3 degC (degC)."""
    t = np.arange(n) / RATE
    return 22.0 + rise * t / t[-1] + 0.3 * np.sin(2 * np.pi * t / 97.0)


def test_slope_of_a_bias_linear_in_a_drifting_temperature_is_recovered_within_its_error():
    rng = np.random.default_rng(7)
    temp = drifting_temperature(N, 4.0)
    slope = 3e-3                                              # rad/s per degC
    gx = 0.02 + slope * temp + rng.normal(0.0, 0.01, N)
    fit = temperature_fit({"gx": gx}, temp, "temp", {"gx": "rad/s"}, log="a.csv")
    row = fit.slopes.iloc[0]
    assert row["Unit"] == "rad/s/degC" and row["Windows"] == 100
    assert abs(row["Slope"] - slope) < 2.5 * row["SE"]
    # the standard error of least squares on 100 window means of 300 white samples each
    temps = temp[: 100 * 300].reshape(100, 300).mean(axis=1)
    plain = 0.01 / np.sqrt(300) / np.sqrt(np.sum((temps - temps.mean()) ** 2))
    assert row["SE"] == pytest.approx(plain, rel=0.25)
    assert fit.range == pytest.approx(temps.max() - temps.min(), rel=1e-12)   # of the window means
    assert fit.warning.startswith("a.csv: the temperature (temp) drifts by 4.")


def test_the_standard_error_covers_the_slope_in_repeated_logs():
    """z = (slope - truth) / SE over 150 simulated logs: standard deviation near 1 (the SE is honest)."""
    rng = np.random.default_rng(8)
    temp = drifting_temperature(6400, 2.0)
    z = []
    for _ in range(150):
        y = -1e-3 * temp + rng.normal(0.0, 0.005, temp.size)
        row = temperature_fit({"ax": y}, temp).slopes.iloc[0]
        z.append((row["Slope"] + 1e-3) / row["SE"])
    assert 0.8 < float(np.std(z)) < 1.25 and abs(float(np.mean(z))) < 0.3


def test_drift_warning_threshold():
    rng = np.random.default_rng(9)
    noise = {"gx": rng.normal(0.0, 0.01, 5000)}
    calm, warm = temperature_fit(noise, drifting_temperature(5000, 0.2)), temperature_fit(noise, drifting_temperature(5000, 1.5))
    assert calm.range < DRIFT_LIMIT < warm.range
    assert calm.warning is None and "drifts by" in warm.warning and "(> 1 degC)" in warm.warning
    constant = temperature_fit(noise, np.full(5000, 25.0)).slopes.iloc[0]
    assert np.isnan(constant["Slope"]) and np.isnan(constant["SE"])


def test_names_of_temperature_columns():
    assert [is_temperature_name(n) for n in ("temp", "temp_c", "Temperature", "imu_degC", "T", "tmp")] == [True] * 6
    assert [is_temperature_name(n) for n in ("t", "time", "timestamp", "gx", "acc_temp_x")] == [False] * 5


def test_recordings_with_a_temperature_column_give_slopes_per_log_and_axis():
    slope = 2e-3
    logs = {}
    for i, rise in enumerate((0.5, 3.0, 0.5)):
        rng = np.random.default_rng(100 + i)
        temp = drifting_temperature(N, rise)
        columns = {"gx": rng.normal(0.0, 0.01, N) + slope * temp, "gy": rng.normal(0.0, 0.01, N), "temp": temp}
        logs[f"log{i}.csv"] = avar.Recording(columns, rate=RATE, source=f"log{i}.csv")
    several = avar.noise_reports(list(logs.values()), gyro_units="rad/s", progress=False)
    assert several.names == ("log0.csv", "log1.csv", "log2.csv")
    assert several.pooled.channels == ("gx", "gy")                      # the temperature is no channel
    table = several.temperature
    assert len(table) == 6 and set(table["Column"]) == {"temp"}
    gx = table[(table["Log"] == "log1.csv") & (table["Channel"] == "gx")].iloc[0]
    assert abs(gx["Slope"] - slope) < 2.5 * gx["SE"] and gx["Unit"] == "rad/s/degC"
    gy = table[table["Channel"] == "gy"]
    assert (np.abs(gy["Slope"]) < 3 * gy["SE"]).all()                  # no dependence: slopes near 0
    drift = [w for w in several.warnings if "drifts" in w]
    assert len(drift) == 1 and drift[0].startswith("log1.csv: the temperature (temp) drifts by")
    assert "Bias versus temperature" in str(several)


def test_temperature_option():
    rng = np.random.default_rng(3)
    frames = [pd.DataFrame({"gx": rng.normal(0, 0.01, 8000), "board": drifting_temperature(8000, 0.5)})
              for _ in range(2)]
    named = avar.noise_reports(frames, rate=RATE, temperature="board", progress=False)
    assert set(named.temperature["Column"]) == {"board"} and named.pooled.channels == ("gx",)
    off = avar.noise_reports(frames, rate=RATE, temperature=None, progress=False)
    assert off.temperature.empty and off.pooled.channels == ("gx", "board")
    with pytest.raises(ValueError, match="temperature column 'temp' is not a column of the log"):
        avar.noise_reports(frames, rate=RATE, temperature="temp", progress=False)


def test_a_random_walk_bias_gets_the_sandwich_error_of_its_noise_model():
    """A wandering (random-walk) bias and a steadily warming log, no thermal slope: least squares alone would
    see slopes of many of its errors (a spurious regression); the sandwich under the fitted white noise and
    random walk gives z-scores of standard deviation ~ 1 (the exact variance of the slope under that model)."""
    rng = np.random.default_rng(12)
    n, white, walk = 6400, 1e-4, 1e-8
    temp = drifting_temperature(n, 2.0)
    plain, sandwich = [], []
    for _ in range(200):
        y = rng.normal(0.0, np.sqrt(white), n) + np.cumsum(rng.normal(0.0, np.sqrt(walk), n))
        plain.append(temperature_fit({"gx": y}, temp).slopes.iloc[0])
        sandwich.append(temperature_fit({"gx": y}, temp, noise={"gx": {"WN": white, "RW": walk}}).slopes.iloc[0])
    z_plain = np.array([row["Slope"] / row["SE"] for row in plain])
    z_model = np.array([row["Slope"] / row["SE"] for row in sandwich])
    assert np.std(z_plain) > 2.0                      # the residual-based error is far too small
    assert 0.8 < np.std(z_model) < 1.2
