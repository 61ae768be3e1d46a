"""The ``avar`` command, run for real in subprocesses."""

from __future__ import annotations

import io
import re
import shutil
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import avar
from avar.models import RW, WN

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def run(*args: str, cwd=None, script: bool = False) -> subprocess.CompletedProcess:
    command = [shutil.which("avar")] if script else [sys.executable, "-m", "avar"]
    return subprocess.run(command + list(args), capture_output=True, text=True, cwd=cwd, timeout=300)


@pytest.fixture(scope="module")
def series_file(tmp_path_factory):
    """A CSV with a time column at 50 Hz and two channels."""
    folder = tmp_path_factory.mktemp("data")
    gx = (WN(sigma2=1.0) + RW(gamma2=1e-6)).simulate(20_000, seed=1)
    gy = WN(sigma2=4.0).simulate(20_000, seed=2)
    path = folder / "gyro.csv"
    pd.DataFrame({"time": np.arange(20_000) / 50.0, "gx": gx, "gy": gy}).to_csv(path, index=False)
    return path, gx, gy


def test_demo_prints_both_tables_and_writes_the_figure(tmp_path):
    result = run("demo", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert "Time" in result.stdout and "AVar" in result.stdout and "Upper CI" in result.stdout  # AV summary
    assert "AVLR fit: WN on scales" in result.stdout and "RW" in result.stdout  # fit table
    figure = (tmp_path / "avar_demo.png").read_bytes()
    assert figure.startswith(PNG_MAGIC) and len(figure) > 20_000


def test_compute_gives_the_library_numbers(series_file, tmp_path):
    path, gx, gy = series_file
    out = tmp_path / "av.csv"
    result = run("compute", str(path), "--type", "to", "--output", str(out), "--plot", str(tmp_path / "av.png"))
    assert result.returncode == 0, result.stderr
    table = pd.read_csv(out)
    for name, values in (("gx", gx), ("gy", gy)):
        expected = avar.avar(values, type="to", freq=50.0).summary().reset_index()  # Scale column
        got = table[table["Channel"] == name].drop(columns="Channel").reset_index(drop=True)
        pd.testing.assert_frame_equal(got, expected, rtol=1e-14, atol=0)
    assert (tmp_path / "av.png").read_bytes().startswith(PNG_MAGIC)


def test_compute_reads_an_npz_archive_with_column_names(tmp_path):
    data = np.random.default_rng(4).standard_normal((2000, 2))
    np.savez(tmp_path / "imu.npz", data=data, columns=np.array(["Gyro. X", "Gyro. Y"]))
    out = tmp_path / "av.csv"
    result = run("compute", str(tmp_path / "imu.npz"), "--freq", "100", "--output", str(out))
    assert result.returncode == 0, result.stderr
    table = pd.read_csv(out)
    assert sorted(set(table["Channel"])) == ["Gyro. X", "Gyro. Y"]
    got = table[table["Channel"] == "Gyro. Y"]["AVar"].to_numpy()
    np.testing.assert_allclose(got, avar.avar(data[:, 1], freq=100.0).allan, rtol=1e-14)


def test_compute_one_column_of_whitespace_text(tmp_path):
    x = np.random.default_rng(3).standard_normal(3000)
    np.savetxt(tmp_path / "x.txt", x)
    result = run("compute", str(tmp_path / "x.txt"), "--freq", "10", "--taus", "decade")
    assert result.returncode == 0, result.stderr
    printed = pd.read_csv(io.StringIO(result.stdout), sep=r"\s+")
    expected = avar.avar(x, freq=10.0, taus="decade")
    np.testing.assert_allclose(printed["Time"], expected.levels)
    np.testing.assert_allclose(printed["AVar"], expected.allan, rtol=1e-5)  # printed with 6 digits


def test_fit_writes_the_estimates(series_file, tmp_path):
    path, gx, _ = series_file
    out = tmp_path / "fit.csv"
    result = run("fit", str(path), "--column", "gx", "--wn", "1:5", "--rw", "10:12", "--output", str(out))
    assert result.returncode == 0, result.stderr
    expected = avar.avlr(avar.avar(gx, freq=50.0), wn=range(1, 6), rw=range(10, 13)).estimates
    table = pd.read_csv(out, index_col=0)
    np.testing.assert_allclose(table["Value"], expected.to_numpy(), rtol=1e-14)
    assert "WN" in result.stdout and "RW" in result.stdout


def test_fit_of_an_imu(series_file):
    path, gx, gy = series_file
    result = run("fit", str(path), "--gyro", "gx", "--gyro", "gy", "--wn", "1:5")
    assert result.returncode == 0, result.stderr
    assert "gyroscopes" in result.stdout


def test_datasets(tmp_path):
    listing = run("datasets")
    assert listing.returncode == 0, listing.stderr
    for name in ("adis_av", "imar_av", "kvh1750_av", "ln200_av", "navchip_av"):
        assert name in listing.stdout
    one = run("datasets", "navchip_av", "--plot", str(tmp_path / "navchip.png"))
    assert one.returncode == 0, one.stderr
    assert "NAVCHIP_FLT @ 250 Hz" in one.stdout
    assert (tmp_path / "navchip.png").read_bytes().startswith(PNG_MAGIC)


BAD_FILES = {
    "missing": (None, "no such file"),
    "unreadable": (b'a,b\n"1,2\n3,4\n5,6\n7,8\n', "not a readable CSV"),
    "non-numeric": (b"a,b\n1,2\n3,oops\n5,6\n7,8\n", r"column 'b' is not numeric: row 2 \(line 3\) holds 'oops'"),
    "too short": (b"a\n1\n2\n3\n", r"3 sample\(s\); the Allan variance needs at least 4"),
    "nan values": (b"a\n1\n2\nnan\n4\n\n6\n", r"column 'a' has 2 missing or non-finite value\(s\); the first is in row 3 \(line 4\)"),
}


@pytest.mark.parametrize("case", list(BAD_FILES))
def test_bad_files_exit_1_with_a_message(case, tmp_path):
    content, message = BAD_FILES[case]
    path = tmp_path / "input.csv"
    if content is not None:
        path.write_bytes(content)
    result = run("compute", str(path))
    assert result.returncode == 1
    assert result.stderr.startswith("avar: error: ")
    assert "Traceback" not in result.stderr
    assert re.search(message, result.stderr), result.stderr


def test_unknown_column_exits_1(series_file):
    result = run("compute", str(series_file[0]), "--column", "gz")
    assert result.returncode == 1
    assert "unknown column(s) ['gz']; the file has ['time', 'gx', 'gy']" in result.stderr


@pytest.mark.parametrize(
    "args, message",
    [
        (["compute"], "the following arguments are required: file"),
        (["compute", "x.csv", "--type", "xx"], "invalid choice: 'xx'"),
        (["fit", "x.csv", "--wn", "a:b"], "invalid scale selection 'a:b'"),
        (["nonsense"], "invalid choice: 'nonsense'"),
    ],
)
def test_usage_errors_exit_2_on_one_line(args, message):
    result = run(*args)
    assert result.returncode == 2
    assert message in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("command", [[], ["demo"], ["compute"], ["fit"], ["datasets"]])
def test_help_of_every_subcommand(command):
    result = run(*command, "--help")
    assert result.returncode == 0
    assert result.stdout.startswith("usage: avar")


def test_console_script_is_installed():
    assert shutil.which("avar"), "the console script 'avar' is not on PATH: install the package (pip install .)"
    result = run("fit", "--help", script=True)
    assert result.returncode == 0 and "--wn SCALES" in result.stdout


def test_freq_overrides_the_rate_but_time_stays_out_of_the_data(series_file):
    result = run("compute", str(series_file[0]), "--freq", "25")
    assert result.returncode == 0, result.stderr
    assert "time" not in set(pd.read_csv(io.StringIO(result.stdout), sep=r"\s+")["Channel"])
    assert "at 25 Hz (--freq)" in result.stderr
    from_time = run("compute", str(series_file[0]), "--column", "gx")
    assert "at 50 Hz from time column 'time'" in from_time.stderr


@pytest.mark.parametrize(
    "args, message",
    [
        (["--column", "gx", "--wn", "7:1"], "invalid scale range '7:1'"),
        (["--column", "gx", "--wn", "1:5", "--per-axis"], "--per-axis applies to IMU fits only"),
        (["--column", "gx", "--wn", "1:5", "--gyro-units", "deg/s", "--accel-units", "g"],
         "give --gyro-units or --accel-units, not both"),
        (["--column", "gx", "--wn", "1:5", "--wn-gyro", "1:3"], "--wn-gyro apply to IMU fits only"),
    ],
)
def test_fit_options_that_do_not_go_together_exit_2(series_file, args, message):
    result = run("fit", str(series_file[0]), *args)
    assert result.returncode == 2
    assert message in result.stderr


def test_closed_pipe_is_not_an_error(series_file):
    command = f"'{sys.executable}' -m avar compute '{series_file[0]}' | head -1"
    result = subprocess.run(command, shell=True, capture_output=True, text=True, timeout=300)
    assert "Scale" in result.stdout and "error" not in result.stderr
