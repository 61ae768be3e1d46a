"""``avar report LOG LOG...`` (or a folder of logs): per-log reports, pooled terms, agreement, temperature."""

from __future__ import annotations

import importlib.util
import pickle

import numpy as np
import pandas as pd
import pytest

from avar.cli.imu import report_many
from avar.models import RW, WN
from tests._support.cli_runner import cli

RATE = 100.0
N = 20_000
MODEL = WN(sigma2=1e-4) + RW(gamma2=1e-10)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """Three CSV logs of one gyro (time, gx, gy, temp); c's gx is twice as noisy, b warms by 3 degC."""
    where = tmp_path_factory.mktemp("logs")
    rng = np.random.default_rng(40)
    t = np.arange(N) / RATE
    for name in "abc":
        gx, gy = MODEL.simulate(N, seed=rng), MODEL.simulate(N, seed=rng)
        temp = 25.0 + 0.2 * np.sin(t / 30.0) + (3.0 * t / t[-1] if name == "b" else 0.0)
        columns = {"time": t, "gx": 2.0 * gx if name == "c" else gx, "gy": gy + 0.01 * temp, "temp": temp}
        pd.DataFrame(columns).to_csv(where / f"{name}.csv", index=False, float_format="%.12g")
    return where


def test_three_logs_print_pooled_table_per_log_lines_and_warnings(folder, capsys, tmp_path):
    out_csv = tmp_path / "pooled.csv"
    code, out, err = cli(capsys, "report", folder / "a.csv", folder / "b.csv", folder / "c.csv",
                         "--gyro-units", "rad/s", "--output", out_csv)
    assert code == 0, err
    assert f"Wrote {out_csv}" in out
    assert "reporting 3 logs one after the other" in err               # the progress notice
    assert "warning: c: disagrees with the other logs in channel gx, angle random walk (WN)" in err
    assert "warning: b: the temperature (temp) drifts by" in err
    # b's warming moves gy's bias (0.01 rad/s/degC): a ramp the other logs lack, which the test finds too
    assert "warning: b: disagrees with the other logs in channel gy, rate ramp (DR)" in err
    table = pd.read_csv(out_csv)
    assert {"Channel", "Term", "Pooled", "a", "b", "c", "Max/min"} <= set(table.columns)
    gx = table[(table["Channel"] == "gx") & (table["Process"] == "WN")].iloc[0]
    assert gx["c"] / gx["a"] == pytest.approx(2.0, rel=0.05)


def test_a_folder_of_logs_is_every_log_in_it(folder, capsys):
    code, out, err = cli(capsys, "report", folder, "--gyro-units", "rad/s")
    assert code == 0, err
    assert out.startswith("Noise reports of 3 logs of one sensor (a, b, c)")
    assert "The logs disagree: b, c" in out and "Pooled terms:" in out
    assert "  a: N = 20000 at 100 Hz; agrees" in out and "  c: N = 20000 at 100 Hz; disagrees in gx" in out
    assert "  b: N = 20000 at 100 Hz; disagrees in gy (rate ramp (DR)" in out
    assert "Bias versus temperature" in out and "rad/s/degC (temp" in out
    slopes = [line for line in out.splitlines() if line.startswith("  b gy: ")]
    slope, error = float(slopes[0].split()[2]), float(slopes[0].split()[4])
    assert abs(slope - 0.01) < 3 * error


def test_usage_errors(folder, capsys, tmp_path):
    code, _, err = cli(capsys, "report", folder / "a.csv", folder / "a.csv")
    assert code == 2 and "is given twice" in err
    code, _, err = cli(capsys, "report", folder / "a.csv", folder / "b.csv", "--kalibr", tmp_path / "k.yaml")
    assert code == 2 and "--kalibr writes one log's report" in err
    code, _, err = cli(capsys, "report", folder / "a.csv", "--workers", "2")
    assert code == 2 and "pool at least 2 logs; got 1" in err
    empty = tmp_path / "empty"
    empty.mkdir()
    code, _, err = cli(capsys, "report", empty)
    assert code != 0 and "a folder with no log" in err


def test_expand_logs_keeps_files_and_ros2_bag_folders(tmp_path):
    (tmp_path / "x.csv").write_text("t,gx\n")
    (tmp_path / "notes.md").write_text("not a log")
    bag = tmp_path / "run2"
    bag.mkdir()
    (bag / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    assert report_many.expand_logs([str(tmp_path)]) == [str(bag), str(tmp_path / "x.csv")]
    assert report_many.expand_logs([str(bag)]) == [str(bag)]


def test_cluster_tasks_travel_pickled_and_give_the_serial_result(folder, capsys, tmp_path, monkeypatch):
    """--workers sends one picklable task per log to map_on_cluster (here a stand-in that pickles the function,
    the tasks and the results as a cluster does, without starting processes: benchmarks/bench_several_logs.py
    runs a real local cluster); the table equals the serial run's."""
    import avar.stability.allan.dask as dask_module

    calls = []

    def pickling_map(function, items, *args, **options):
        calls.append(options)
        function, items, args = pickle.loads(pickle.dumps((function, list(items), args)))
        return [pickle.loads(pickle.dumps(function(item, *args))) for item in items]

    monkeypatch.setattr(dask_module, "map_on_cluster", pickling_map)
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: object())
    serial, parallel = tmp_path / "serial.csv", tmp_path / "parallel.csv"
    logs = [folder / f"{name}.csv" for name in "abc"]
    code, _, err = cli(capsys, "report", *logs, "--gyro-units", "rad/s", "--output", serial)
    assert code == 0, err
    code, _, err = cli(capsys, "report", *logs, "--gyro-units", "rad/s", "--output", parallel, "--workers", "2")
    assert code == 0, err
    assert "on 2 local worker(s)" in err and calls[0]["workers"] == 2 and calls[0]["unit"] == "log"
    pd.testing.assert_frame_equal(pd.read_csv(parallel), pd.read_csv(serial), rtol=1e-12)
