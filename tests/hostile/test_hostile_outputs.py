"""Hostile outputs: what is not a regular file, races, long names, closed streams, spreadsheets.

Each case is reproduced for real: FIFOs, symbolic links and device nodes are
created, two runs race on one name, real processes run with stdout or stderr
closed, and the CSV files written are read back.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

import avar
from avar.cli import outputs
from tests._support.cli_runner import cli

X = np.random.default_rng(27).standard_normal(2048)


@pytest.fixture(scope="module")
def data_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("outputs") / "data.csv"
    pd.DataFrame({"time": np.arange(X.size) / 10.0, "gx": X}).to_csv(path, index=False)
    return path


def _no_temporaries(folder: Path) -> bool:
    return not [p for p in folder.iterdir() if p.name.endswith(".part")]


# --------------------------------------------------------------------------- --force and what is not a file
@pytest.mark.parametrize("kind", ["fifo", "symlink to a file", "symlink to /dev/null", "dangling symlink"])
def test_force_never_replaces_what_is_not_a_regular_file(kind, data_file, tmp_path, capsys):
    target = tmp_path / "out.csv"
    victim = tmp_path / "victim.txt"
    victim.write_text("keep")
    if kind == "fifo":
        os.mkfifo(target)
    elif kind == "symlink to a file":
        target.symlink_to(victim)
    elif kind == "symlink to /dev/null":
        target.symlink_to("/dev/null")
    else:
        target.symlink_to(tmp_path / "nowhere")
    before = os.lstat(target)
    code, _, err = cli(capsys, "compute", data_file, "--output", target, "--force")
    assert code == 2, err
    assert "only a regular file (or a new name) is written, even with --force" in err
    assert "Traceback" not in err and len(err.splitlines()) == 1
    after = os.lstat(target)
    assert (after.st_mode, after.st_ino) == (before.st_mode, before.st_ino)  # the node itself is untouched
    assert victim.read_text() == "keep"
    assert _no_temporaries(tmp_path)


def test_force_refuses_a_device_node(data_file, capsys):
    before = os.lstat("/dev/null")
    code, _, err = cli(capsys, "compute", data_file, "--output", "/dev/null", "--force")
    assert code == 2
    assert "'/dev/null' is a character device" in err
    assert os.lstat("/dev/null").st_rdev == before.st_rdev


def test_kalibr_dash_is_refused_and_no_file_named_dash(data_file, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, err = cli(capsys, "report", data_file, "--gyro", "gx", "--kalibr", "-")
    assert code == 2
    assert "--kalibr writes a file; '-' (stdout) is only for --output" in err
    assert not (tmp_path / "-").exists()


# --------------------------------------------------------------------------- two runs, one name
def test_a_file_created_while_computing_is_never_replaced(data_file, tmp_path, capsys, monkeypatch):
    """The slower of two runs with the same --output: its rename refuses the faster run's file."""
    from avar.cli import compute

    out, fig = tmp_path / "o.csv", tmp_path / "p.png"
    real = compute.compute_from_args

    def slower(args, progress):
        results = real(args, progress)
        out.write_text("the other run's table")  # the faster run finished meanwhile
        return results

    monkeypatch.setattr(compute, "compute_from_args", slower)
    code, stdout, err = cli(capsys, "compute", data_file, "--output", out, "--plot", fig)
    assert code == 2, err
    assert "was created by another program while this run computed" in err
    assert out.read_text() == "the other run's table"
    assert not fig.exists()  # nothing of the failed run is left
    assert stdout == "" and _no_temporaries(tmp_path)


def test_rename_no_replace_is_atomic_and_keeps_the_existing_file(tmp_path):
    source, target = tmp_path / "new", tmp_path / "target"
    source.write_text("new")
    target.write_text("old")
    with pytest.raises(FileExistsError):
        outputs.rename_no_replace(str(source), target)
    assert target.read_text() == "old" and source.read_text() == "new"
    target.unlink()
    outputs.rename_no_replace(str(source), target)
    assert target.read_text() == "new" and not source.exists()


def test_two_concurrent_processes_one_output_one_wins(data_file, tmp_path):
    """Real processes started together: exactly one writes the file, the other exits 2 and replaces nothing."""
    out = tmp_path / "o.csv"
    command = [sys.executable, "-m", "avar", "compute", str(data_file), "--column", "gx", "--output", str(out)]
    runs = [subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(2)]
    results = [(run.wait(timeout=300), run.stderr.read()) for run in runs]
    codes = sorted(code for code, _ in results)
    assert codes == [0, 2], results
    loser = next(err for code, err in results if code == 2)
    assert "exists; pass --force" in loser or "created by another program" in loser
    table = pd.read_csv(out)
    np.testing.assert_allclose(table["AVar"], avar.avar(X, freq=10.0).allan, rtol=1e-12)
    assert _no_temporaries(tmp_path)


# --------------------------------------------------------------------------- names and folders, before computing
def test_a_249_byte_name_is_written_and_a_256_byte_one_refused_before_computing(data_file, tmp_path, capsys):
    long_name = "a" * 245 + ".csv"  # 249 bytes: legal, though its old temporary name was not
    code, _, err = cli(capsys, "compute", data_file, "--output", tmp_path / long_name)
    assert code == 0, err
    assert len(pd.read_csv(tmp_path / long_name)) == avar.avar(X).allan.size
    too_long = "b" * 252 + ".csv"
    code, stdout, err = cli(capsys, "compute", data_file, "--output", tmp_path / too_long)
    assert code == 2
    assert "the file name is 256 bytes long, more than the 255 its folder allows" in err
    assert stdout == "" and "column(s) x" not in err  # refused before the file was read
    assert sorted(p.name for p in tmp_path.iterdir()) == [long_name]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a read-only folder")
def test_a_read_only_folder_is_refused_before_computing(data_file, tmp_path, capsys):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        code, _, err = cli(capsys, "compute", data_file, "--output", folder / "o.csv")
    finally:
        folder.chmod(0o755)
    assert code == 2
    assert "is not writable" in err and ".part" not in err


# --------------------------------------------------------------------------- closed standard streams
def _run_with_closed(fd: int, *args: str) -> subprocess.CompletedProcess:
    keep = subprocess.PIPE
    return subprocess.run([sys.executable, "-m", "avar", *args], preexec_fn=lambda: os.close(fd),
                          stdout=None if fd == 1 else keep, stderr=None if fd == 2 else keep, timeout=300)


@pytest.mark.parametrize("fd", [1, 2])
def test_closed_stdout_or_stderr_loses_no_output(fd, data_file, tmp_path):
    out, fig = tmp_path / "o.csv", tmp_path / "p.png"
    run = _run_with_closed(fd, "compute", str(data_file), "--column", "gx", "--output", str(out), "--plot", str(fig))
    assert run.returncode == 0
    shown = (run.stderr if fd == 1 else run.stdout).decode()
    assert "Traceback" not in shown and "Error" not in shown
    if fd == 2:
        assert f"Wrote {out}" in shown  # the table and its lines still reach stdout
    table = pd.read_csv(out)
    np.testing.assert_allclose(table["AVar"], avar.avar(X, freq=10.0).allan, rtol=1e-12)
    assert fig.read_bytes().startswith(b"\x89PNG")
    assert "AVar" not in out.read_text().split("\n", 1)[1]  # no printed table leaked into the file


# --------------------------------------------------------------------------- spreadsheets and terminals
def test_csv_outputs_are_protected_against_formula_injection(tmp_path, capsys):
    path = tmp_path / "cells.csv"
    names = ["=HYPERLINK(\"http://x\",\"y\")", "+cmd", "-2+3", "@SUM(A1)", "plain"]
    rng = np.random.default_rng(3)
    pd.DataFrame({"time": np.arange(512) / 10.0, **{n: rng.standard_normal(512) for n in names}}).to_csv(
        path, index=False)
    code, _, err = cli(capsys, "compute", path, "--output", tmp_path / "o.csv")
    assert code == 0, err
    table = pd.read_csv(tmp_path / "o.csv")
    assert sorted(set(table["Channel"])) == sorted(["'" + n for n in names[:4]] + ["plain"])
    assert table["AVar"].dtype == np.float64  # numbers stay numbers
    assert table["Scale"].dtype == np.int64


def test_control_characters_of_a_header_are_escaped_on_the_terminal(tmp_path, capsys):
    path = tmp_path / "ansi.csv"
    rng = np.random.default_rng(4)
    pd.DataFrame({"time": np.arange(512) / 10.0, "\x1b[2Jred\x1b[0m": rng.standard_normal(512),
                  "b\x07ell": rng.standard_normal(512)}).to_csv(path, index=False)
    code, stdout, err = cli(capsys, "compute", path)
    assert code == 0, err
    assert "\x1b" not in stdout + err and "\x07" not in stdout + err
    assert "\\x1b[2Jred\\x1b[0m" in stdout and "b\\x07ell" in stdout
    named = tmp_path / "log\x1b[31m.csv"  # a file name with an escape: notes and errors escape it too
    named.write_bytes(path.read_bytes())
    for extra in ([], ["--column", "nope"]):
        code, stdout, err = cli(capsys, "compute", named, *extra)
        assert code == (1 if extra else 0), err
        assert "\x1b" not in stdout + err and "log\\x1b[31m.csv" in stdout + err


# --------------------------------------------------------------------------- usage errors: exit 2
@pytest.mark.parametrize("args, fragment", [
    (["fit", "{data}", "--column", "gx", "--wn", "1:3", "--alpha", "0"], "argument --alpha: expected 1 - the confidence"),
    (["fit", "{data}", "--column", "gx", "--wn", "1:3", "--alpha", "1.5"], "a number in (0, 1) such as 0.05, got '1.5'"),
    (["fit", "{data}", "--column", "gx", "--wn", "1:3", "--alpha", "nan"], "got 'nan'"),
    (["report", "{data}", "--gyro", "gx", "--alpha", "0"], "argument --alpha: expected 1 - the confidence"),
    (["fit", "{data}", "--column", "gx", "--wn", "1:3", "--ci", "--seed", "-1"], "argument --seed: expected a whole"),
    (["fit", "{data}", "--column", "gx", "--wn", "1:3", "--ci", "--seed", "abc"], "got 'abc'"),
])
def test_bad_option_values_are_usage_errors(args, fragment, data_file, capsys):
    code, _, err = cli(capsys, *(a.format(data=data_file) for a in args))
    assert code == 2
    assert fragment in err and len(err.splitlines()) == 1


def test_kalibr_with_a_failing_plot_writes_nothing(tmp_path, capsys, monkeypatch):
    from avar.fit.report import result as report_result

    data_file = tmp_path.parent / f"{tmp_path.name}-gyro.csv"
    gx = (avar.WN(sigma2=1e-6) + avar.RW(gamma2=1e-10)).simulate(100_000, seed=7)
    pd.DataFrame({"time": np.arange(gx.size) / 100.0, "gx": gx}).to_csv(data_file, index=False)

    def broken(self, *args, **kwargs):
        raise ValueError("the figure cannot be drawn")

    monkeypatch.setattr(report_result.NoiseReport, "plot", broken)
    yaml_path, fig = tmp_path / "imu.yaml", tmp_path / "r.png"
    code, _, err = cli(capsys, "report", data_file, "--gyro", "gx", "--kalibr", yaml_path, "--plot", fig)
    assert code == 1
    assert "the figure cannot be drawn" in err
    assert sorted(tmp_path.iterdir()) == []  # every output rendered before any is written


# --------------------------------------------------------------------------- write_kalibr
def _report(source=None):
    terms = pd.DataFrame({"Sensor": ["Gyroscope"] * 2, "Process": ["WN", "RW"], "Status": ["present"] * 2,
                          "Value": [1e-3, 2e-5]})
    return SimpleNamespace(terms=terms, sensor_types=("Gyroscope",), topic=None, rate=200.0, source=source)


def test_write_kalibr_mode_follows_the_umask(tmp_path):
    from avar.fit.report.exports.kalibr import write_kalibr

    old = os.umask(0o027)
    try:
        path = write_kalibr(_report(), tmp_path / "imu.yaml")
    finally:
        os.umask(old)
    assert path.stat().st_mode & 0o777 == 0o640
    assert "gyroscope_noise_density: 0.001" in path.read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["imu.yaml"]


def test_write_kalibr_refuses_nan_fifos_and_names_the_target(tmp_path):
    from avar.fit.report.exports.kalibr import write_kalibr

    with pytest.raises(ValueError, match=r"\['gyroscope_noise_density'\] are not finite numbers"):
        write_kalibr(_report(), tmp_path / "a.yaml", gyroscope_noise_density=float("nan"))
    os.mkfifo(tmp_path / "fifo.yaml")
    with pytest.raises(ValueError, match="exists and is not a regular file"):
        write_kalibr(_report(), tmp_path / "fifo.yaml", force=True)
    with pytest.raises(OSError) as info:
        write_kalibr(_report(), tmp_path / "missing" / "imu.yaml")
    assert str(tmp_path / "missing" / "imu.yaml") in str(info.value)
    assert ".part" not in str(info.value) and ".tmp" not in str(info.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo.yaml"]
