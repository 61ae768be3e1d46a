"""``avar clock-report``: the h_alpha and Kalman q tables of a clock, its CSV, figure and q YAML."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
import yaml

import avar
from tests._support.cli_runner import cli

TRUE_Q1, TRUE_Q2 = 1e-22, 1e-28  # WN sigma2 = 1e-22 at 1 Hz: h_0 = 2e-22, q1 = h_0 / 2; RW gamma2 = 1e-28: q2


@pytest.fixture(scope="module")
def clock_file(tmp_path_factory):
    y = (avar.WN(sigma2=1e-22) + avar.RW(gamma2=1e-28)).simulate(20_000, seed=1)
    x = np.concatenate([[0.0], np.cumsum(y)])  # time error (s) at 1 Hz
    path = tmp_path_factory.mktemp("clock") / "clock.csv"
    pd.DataFrame({"t": np.arange(x.size, dtype=float), "x": x}).to_csv(path, index=False)
    return path, x


def test_tables_yaml_and_csv_agree_with_the_library_and_the_truth(capsys, clock_file, tmp_path):
    path, x = clock_file
    q, table, figure = tmp_path / "q.yaml", tmp_path / "clock.csv", tmp_path / "clock.png"
    code, out, err = cli(capsys, "clock-report", path, "--data-type", "phase", "--B", "20", "--seed", "2",
                         "--export", f"q={q}", "--output", table, "--plot", figure)
    assert code == 0, err
    expected = avar.clock_report(x, rate=1.0, data_type="phase", B=20, seed=2)
    assert out.startswith("clock.csv [x]: phase data\nClock noise model at 1 Hz, N = 20000")
    assert f"q1 = {expected.q['q1']:.4g} s" in out and "fit: " in out
    for row in expected.coefficients.itertuples():
        assert f"h({row.alpha:+d}) = {row.h:.4g}  [{row.Lower:.4g}, {row.Upper:.4g}]" in out
    loaded = yaml.safe_load(q.read_text())
    assert {loaded[name]["unit"] for name in ("q1", "q2", "r")} == {"s", "1/s", "s^2"}
    assert loaded["rate_hz"] == 1.0 and loaded["confidence"] == 0.95
    assert loaded["q1"]["value"] == pytest.approx(TRUE_Q1, rel=0.1)  # white FM: 20,000 values pin it
    assert loaded["q2"]["lower"] <= TRUE_Q2 <= loaded["q2"]["upper"]
    for name in ("q1", "q2", "r"):
        assert loaded[name]["value"] == pytest.approx(expected.q[name], rel=1e-12)
    text = q.read_text()
    assert "q1 = h_0 / 2" in text and "q2 = 2 pi^2 h_-2" in text and "q1 / tau + q2 tau / 3" in text
    frame = pd.read_csv(table)
    h = frame[frame.Quantity == "h"].set_index("alpha")
    rows = frame.set_index("Quantity")
    assert rows.loc["q1", "Value"] == pytest.approx(h.loc[0, "Value"] / 2, rel=1e-12)
    assert rows.loc["q2", "Value"] == pytest.approx(2 * math.pi**2 * h.loc[-2, "Value"], rel=1e-12)
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_clock_log_with_a_gap_is_filled_and_said(capsys, tmp_path):
    y = avar.WN(sigma2=1e-16).simulate(3000, seed=4)
    x = np.concatenate([[0.0], np.cumsum(y) * 16.0])  # time error (s), an update every 16 s
    path = tmp_path / "loopstats"
    with path.open("w") as f:
        for k, value in enumerate(x):
            if k != 1000:  # one missed update
                day, second = divmod(16 * k, 86400)
                f.write(f"{60000 + day} {second}.000 {value:.12f} 13.778190 0.000351733 0.013380 6\n")
    code, out, err = cli(capsys, "clock-report", path, "--B", "10", "--seed", "1")
    assert code == 0, err
    assert "ntpd loopstats" in err and "column: ntpd loopstats: offset (s)" in err and "fill" in err.lower()
    assert "at 0.0625 Hz, N = 3000" in out
    h0 = float(out.split("h(+0) = ")[1].split()[0])
    assert h0 == pytest.approx(2e-16 / 0.0625, rel=0.15)  # white FM: h_0 = 2 sigma2 / rate


@pytest.mark.parametrize(("export", "message"), [("x=a.yaml", "NAME one of q"), ("q=", "--export q=FILE")])
def test_bad_export_is_a_usage_error(capsys, clock_file, export, message):
    code, _, err = cli(capsys, "clock-report", clock_file[0], "--data-type", "phase", "--export", export)
    assert code == 2 and message in err


def test_export_without_a_file_takes_its_default_name(capsys, clock_file, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = cli(capsys, "clock-report", clock_file[0], "--data-type", "phase", "--export", "q", "--B", "10",
                         "--seed", "3")
    assert code == 0, err
    assert "Wrote clock_q.yaml" in out and yaml.safe_load((tmp_path / "clock_q.yaml").read_text())["q1"]["unit"] == "s"


def test_table_needs_its_data_type(capsys, clock_file):
    code, _, err = cli(capsys, "clock-report", clock_file[0])
    assert code == 2 and "--data-type" in err
