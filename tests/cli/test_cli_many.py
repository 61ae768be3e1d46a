"""``avar compute FILE...``: several files, serially and on dask.distributed clusters, in process."""

from __future__ import annotations

import importlib.util
import io

import numpy as np
import pandas as pd
import pytest

distributed = pytest.importorskip("dask.distributed")

from avar.cli import compute_many  # noqa: E402
from tests._support.cli_runner import cli  # noqa: E402

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> list:
    """8 files: CSV with a time column (2 channels), whitespace text, and .npy (1-D, 2-D, structured)."""
    folder = tmp_path_factory.mktemp("many")
    rng = np.random.default_rng(20)
    paths = []
    for i in range(3):
        n = 20_000 + 1_000 * i
        path = folder / f"gyro{i}.csv"
        pd.DataFrame({"time": np.arange(n) / 50.0, "gx": rng.standard_normal(n),
                      "gy": 1e3 + np.cumsum(rng.standard_normal(n))}).to_csv(path, index=False)
        paths.append(path)
    np.savetxt(folder / "plain.txt", rng.standard_normal(12_345))
    paths.append(folder / "plain.txt")
    for i in range(2):
        np.save(folder / f"series{i}.npy", 0.1 * rng.standard_normal(30_000 + 17 * i))
        paths.append(folder / f"series{i}.npy")
    np.save(folder / "table.npy", rng.standard_normal((16_000, 3)))
    paths.append(folder / "table.npy")
    record = np.zeros(9_000, dtype=[("time", "f8"), ("ax", "f4")])
    record["time"] = np.arange(9_000) / 100.0
    record["ax"] = rng.standard_normal(9_000)
    np.save(folder / "record.npy", record)
    paths.append(folder / "record.npy")
    assert len(paths) == 8
    return paths


@pytest.fixture(scope="module")
def cluster():
    """A running 2-worker cluster of single-threaded processes: its scheduler address."""
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0") as running:
        yield running.scheduler_address


def combined_csv(capsys, files, tmp_path, name, *options) -> pd.DataFrame:
    out = tmp_path / f"{name}.csv"
    code, _, err = cli(capsys, "compute", *files, "--output", out, *options)
    assert code == 0, err
    return pd.read_csv(out)


def assert_tables_equal(got: pd.DataFrame, want: pd.DataFrame) -> None:
    assert list(got.columns) == list(want.columns)
    numeric = got.select_dtypes("number").columns
    pd.testing.assert_frame_equal(got.drop(columns=numeric), want.drop(columns=numeric))
    np.testing.assert_allclose(got[numeric].to_numpy(), want[numeric].to_numpy(), rtol=1e-12, atol=0)


def assert_equals_single_runs(capsys, files, table, tmp_path, *options) -> None:
    """The rows of each file, without the File column, are that file's own ``avar compute FILE`` table."""
    assert list(table["File"].unique()) == [path.stem for path in files]
    for path in files:
        single = combined_csv(capsys, [path], tmp_path, f"single-{path.stem}", *options)
        rows = table[table["File"] == path.stem].drop(columns="File").reset_index(drop=True)
        if "Channel" in rows and "Channel" not in single:  # a one-column file among files with several
            rows = rows.drop(columns="Channel")
        assert_tables_equal(rows, single)


def test_eight_files_on_own_local_cluster_equal_the_serial_and_single_runs(capsys, files, tmp_path):
    serial = combined_csv(capsys, files, tmp_path, "serial")
    parallel = combined_csv(capsys, files, tmp_path, "parallel", "--workers", "2")
    assert_tables_equal(parallel, serial)
    assert list(serial.columns[:3]) == ["File", "Channel", "Scale"]
    assert set(serial["Channel"]) == {"gx", "gy", "x", "x1", "x2", "x3", "ax"}
    assert_equals_single_runs(capsys, files, parallel, tmp_path)


def test_running_scheduler_gives_the_serial_result(capsys, files, cluster, tmp_path):
    options = ("--type", "to", "--taus", "decade")
    serial = combined_csv(capsys, files, tmp_path, "serial", *options)
    remote = combined_csv(capsys, files, tmp_path, "remote", *options, "--scheduler", cluster)
    assert_tables_equal(remote, serial)
    assert_equals_single_runs(capsys, files[:2], remote[remote["File"].isin(["gyro0", "gyro1"])], tmp_path,
                              *options)


def test_one_file_on_the_cluster_prints_todays_table(capsys, files, cluster):
    code, today, _ = cli(capsys, "compute", files[0])
    assert code == 0
    code, remote, err = cli(capsys, "compute", files[0], "--scheduler", cluster)
    assert code == 0, err
    assert remote == today and "File" not in today
    assert "gyro0.csv: 2 column(s) x 20000 samples at 50 Hz" in err  # the reader's note, from the worker


def test_one_imu_per_file_and_a_comparison_figure(capsys, files, cluster, tmp_path):
    imu_files = files[:3]
    table = combined_csv(capsys, imu_files, tmp_path, "imu", "--gyro", "gx", "--gyro", "gy",
                         "--scheduler", cluster, "--plot", tmp_path / "imu.png")
    assert list(table.columns[:3]) == ["File", "Channel", "Scale"]
    assert_equals_single_runs(capsys, imu_files, table, tmp_path, "--gyro", "gx", "--gyro", "gy")
    assert (tmp_path / "imu.png").read_bytes().startswith(PNG_MAGIC)
    results = [res for res, _ in compute_many.compute_files([str(p) for p in files[2:4]],
                                                            compute_many.ReadOptions())]
    figure = compute_many.figure_of_files(["gyro2", "plain"], results)
    assert [line.get_label() for line in figure.axes[0].lines] == ["gyro2: gx", "gyro2: gy", "plain"]


def test_one_column_per_file_has_no_channel_column(capsys, files, tmp_path):
    npy = [path for path in files if path.name.startswith("series")]
    table = combined_csv(capsys, npy, tmp_path, "npy", "--freq", "10")
    assert list(table.columns) == ["File", "Scale", "Time", "AVar", "ADev", "Lower CI", "Upper CI"]
    assert_equals_single_runs(capsys, npy, table, tmp_path, "--freq", "10")


@pytest.mark.parametrize(
    "args, message",
    [
        (["--workers", "0"], "argument --workers: expected a whole number of worker processes >= 1, got '0'"),
        (["--workers", "two"], "argument --workers: expected a whole number of worker processes >= 1, got 'two'"),
        (["--scheduler", "localhost"], "argument --scheduler: expected a dask.distributed scheduler address"),
        (["--workers", "2", "--scheduler", "tcp://127.0.0.1:8786"], "give one of them"),
        (["--column", "gx", "--gyro", "gy"], "--column cannot be combined with --gyro/--accel"),
    ],
)
def test_usage_errors_exit_2_and_write_nothing(capsys, files, tmp_path, args, message):
    code, out, err = cli(capsys, "compute", *files[:2], *args, "--output", tmp_path / "o.csv")
    assert code == 2 and message in err and out == ""
    assert not (tmp_path / "o.csv").exists()


def test_a_missing_file_among_several_is_named_and_nothing_is_written(capsys, files, tmp_path):
    missing = tmp_path / "nowhere.csv"
    for cluster_option in ([], ["--workers", "2"]):
        code, out, err = cli(capsys, "compute", *files[:3], missing, *files[3:], *cluster_option,
                             "--output", tmp_path / "o.csv", "--plot", tmp_path / "o.png")
        assert code == 1 and out == ""
        assert err.strip() == f"avar: error: {missing}: no such file"
        assert list(tmp_path.iterdir()) == []


def test_a_bad_file_on_a_worker_is_named_and_nothing_is_written(capsys, files, cluster, tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("a,b\n1,2\n3,oops\n5,6\n7,8\n")
    code, out, err = cli(capsys, "compute", *files[:2], bad, "--scheduler", cluster, "--output", tmp_path / "o.csv")
    assert code == 1 and out == ""
    assert f"{bad}: column 'b' is not numeric: row 2 (line 3) holds 'oops'" in err
    assert "Traceback" not in err and not (tmp_path / "o.csv").exists()


def test_without_dask_distributed_the_message_says_what_to_install(capsys, files, monkeypatch):
    find_spec = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *rest: None if name == "distributed" else find_spec(name, *rest))
    code, _, err = cli(capsys, "compute", files[0], "--workers", "2")
    assert code == 2
    assert 'dask.distributed, which is not installed: pip install "allanvar[dask]"' in err


@pytest.mark.parametrize("on_cluster", [False, True])
def test_the_progress_bar_counts_the_files_on_stderr(capsys, files, cluster, monkeypatch, on_cluster):
    monkeypatch.setattr(compute_many, "SHOW_PROGRESS", True)
    code, out, err = cli(capsys, "compute", *files, *(["--scheduler", cluster] if on_cluster else []))
    assert code == 0, err
    assert "computing: 100%" in err and "8/8" in err and "file/s" in err
    assert "File" in out and "%" not in out
    monkeypatch.setattr(compute_many, "SHOW_PROGRESS", False)
    code, out, err = cli(capsys, "compute", *files[:2], *(["--scheduler", cluster] if on_cluster else []))
    assert code == 0 and "%" not in err
    table = pd.read_csv(io.StringIO(out), sep=r"\s+")
    assert set(table["File"]) == {"gyro0", "gyro1"}
