"""``avar compute`` reading files: options of the reader, run for real in subprocesses."""

from __future__ import annotations

import io
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import avar
from avar.io.read import read


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "avar", *args], capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def imu_csv(tmp_path_factory):
    rng = np.random.default_rng(11)
    frame = pd.DataFrame(rng.standard_normal((3000, 4)), columns=["gx", "gy", "ax", "ay"])
    frame.insert(0, "time", np.arange(3000) / 100.0)
    path = tmp_path_factory.mktemp("cli") / "imu.csv"
    frame.to_csv(path, index=False)
    return path


@pytest.mark.parametrize(
    "args, code, message",
    [
        (["--column", "gx", "--gyro", "gy"], 2, "--column cannot be combined with --gyro/--accel"),
        (["--column", "time"], 1, "['time'] are time columns; a time column is never data"),
    ],
)
def test_column_options_that_would_mislead(imu_csv, args, code, message):
    result = run("compute", str(imu_csv), *args)
    assert result.returncode == code
    assert message in result.stderr and "Traceback" not in result.stderr


def test_a_directory_is_not_missing(tmp_path):
    result = run("compute", str(tmp_path))
    assert result.returncode == 1
    assert result.stderr.strip() == f"avar: error: {tmp_path}: is a directory, not a file"


def test_gaps_refused_then_ignored_on_stderr(tmp_path):
    t = np.arange(400) / 50.0
    t[300:] += 3.0
    path = tmp_path / "gap.csv"
    pd.DataFrame({"time": t, "gx": np.sin(np.arange(400.0))}).to_csv(path, index=False)
    refused = run("compute", str(path))
    assert refused.returncode == 1
    assert "1 gap(s)" in refused.stderr and "row 301 at t = 9 s" in refused.stderr and "--gaps ignore" in refused.stderr
    ignored = run("compute", str(path), "--gaps", "ignore")
    assert ignored.returncode == 0, ignored.stderr
    assert "treated as contiguous" in ignored.stderr and "at 50 Hz" in ignored.stderr
    table = pd.read_csv(io.StringIO(ignored.stdout), sep=r"\s+")
    expected = avar.avar(np.sin(np.arange(400.0)), freq=50.0)
    np.testing.assert_allclose(table["AVar"], expected.allan, rtol=1e-5)


def test_integers_beyond_2_53_are_not_lost(tmp_path):
    """The CLI reads int64 and hands avar() the exact integers: the AV of 2**60 + k^2 is that of k^2."""
    values = [2**60 + k * k for k in range(256)]
    path = tmp_path / "big.csv"
    path.write_text("counts\n" + "".join(f"{v}\n" for v in values))
    assert read(path)["counts"].dtype == np.int64
    result = run("compute", str(path))
    assert result.returncode == 0, result.stderr
    table = pd.read_csv(io.StringIO(result.stdout), sep=r"\s+")
    exact = avar.avar(np.array([k * k for k in range(256)], dtype=np.float64))
    np.testing.assert_allclose(table["AVar"], exact.allan, rtol=1e-5)  # the table prints 6 digits
    assert table["AVar"].iloc[0] > 0


def test_progress_bar_only_when_asked_or_on_a_terminal(tmp_path, capsys):
    path = tmp_path / "p.csv"
    path.write_text("x\n" + "".join(f"{i % 5}\n" for i in range(100)))
    read(path)
    assert capsys.readouterr().err == ""  # captured stderr is not a terminal: no bar
    read(path, progress=True)
    assert "reading p.csv" in capsys.readouterr().err
