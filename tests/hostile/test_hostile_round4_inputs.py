"""Hostile inputs, round four: bombs, gaps, odd archives and the messages that name them (issue 38).

Every file is written to disk and read by the real command (a subprocess; the bombs with
``RLIMIT_AS`` at 1.5 GiB, where the old readers died of MemoryError) or by ``avar.read``.
The bombs are built cheaply from one compressed block repeated (gzip and bzip2 streams
concatenate), so each test takes seconds.
"""

from __future__ import annotations

import bz2
import gzip
import io
import os
import struct
import zipfile

import numpy as np
import pandas as pd
import pytest
import scipy.io
import scipy.sparse

import avar
from avar.io.text import sniff
from avar.stability.shared.registry import DEVIATION_STATISTICS
from tests._support.subprocess_cli import run_avar

#: The address space of the bomb runs: the old readers needed more and died of MemoryError.
LIMIT = 3 * 2**29  # 1.5 GiB
#: The issue's bound on the time a bomb may take (the bombs here are a quarter of the issue's).
SECONDS = 60
RNG = np.random.default_rng(3838)
X = RNG.standard_normal(2000)
TABLE = "time,gx\n" + "".join(f"{i / 100!r},{float(v)!r}\n" for i, v in enumerate(X))


def _one_line(run) -> bool:
    return run.stderr.count("\n") == 1 and "Traceback" not in run.stderr and "MemoryError" not in run.stderr


# --------------------------------------------------------------------------- decompression bombs
def test_a_gzip_of_256_mib_of_blank_lines_ends_quickly_in_bounded_memory(tmp_path):
    """The cause: the sniffer kept every blank line (1 GiB of them ran past 150 s at 2.4 GB)."""
    path = tmp_path / "blank.csv.gz"
    path.write_bytes(gzip.compress(b"\n" * (1 << 24), 9) * 16)  # 256 MiB of blank lines in 260 KB
    run = run_avar("compute", path, address_space=LIMIT)
    assert run.code == 1 and _one_line(run), run.stderr
    assert "blank.csv.gz: the file holds no data (only blank or # comment lines: 268,435,456)" in run.stderr
    assert run.seconds < SECONDS


def test_a_table_after_32_mib_of_bzip2_comment_lines_is_read(tmp_path):
    """The cause: 200 MiB of ``#`` lines before a table ended in MemoryError and the table was never read."""
    path = tmp_path / "comments.csv.bz2"
    path.write_bytes(bz2.compress(b"#\n" * (1 << 19), 9) * 32 + bz2.compress(TABLE.encode()))  # 16 Mi lines
    out = tmp_path / "av.csv"
    run = run_avar("compute", path, "--output", out, address_space=LIMIT)
    assert run.code == 0, run.stderr
    assert run.seconds < SECONDS
    np.testing.assert_allclose(pd.read_csv(out)["AVar"], avar.avar(X, rate=100.0).allan, rtol=1e-12)
    layout = sniff(path)
    assert layout.skip == 1 << 24 and layout.names == ["time", "gx"]


def test_a_gzip_whose_columns_exceed_the_memory_is_refused_before_allocating(tmp_path, monkeypatch):
    path = tmp_path / "zeros.csv.gz"
    path.write_bytes(gzip.compress(b"x\n") + gzip.compress(b"0\n" * (1 << 23), 6) * 32)  # 2**28 rows: 2 GiB of float64
    run = run_avar("compute", path, address_space=LIMIT)
    assert run.code == 1 and _one_line(run), run.stderr
    assert "zeros.csv.gz: 268,435,458 rows x 1 column(s) would take 2 GiB of memory, more than" in run.stderr
    assert "(the memory available to this process; set AVAR_MAX_INPUT_BYTES" in run.stderr
    small = tmp_path / "small.csv.gz"
    small.write_bytes(gzip.compress(b"x\n" + b"0.5\n" * 300_000))
    monkeypatch.setenv("AVAR_MAX_INPUT_BYTES", "1M")
    with pytest.raises(ValueError, match=r"small.csv.gz: 300,002 rows x 1 column\(s\) would take 2.29 MiB of memory, "
                                         r"more than 1 MiB \(the limit set by AVAR_MAX_INPUT_BYTES=1M"):
        avar.read(small)
    monkeypatch.setenv("AVAR_MAX_INPUT_BYTES", "4M")  # the variable raises the limit
    assert avar.read(small).n == 300_000


def test_a_gzip_of_one_endless_line_is_refused_naming_the_line(tmp_path):
    path = tmp_path / "line.csv.gz"
    path.write_bytes(gzip.compress(b"0" * (1 << 24), 9) * 8)  # 128 MiB without a line end
    run = run_avar("compute", path, address_space=LIMIT)
    assert run.code == 1 and _one_line(run), run.stderr
    assert "line.csv.gz: line 1 is longer than 67,108,864 characters" in run.stderr


def _npz_bomb(path, n: int) -> None:
    """A .npz whose member declares ``n`` float64 values (its data cut short: only the header matters)."""
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (n,)})
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("gx.npy", header.getvalue() + bytes(4096))


def _mat_bomb(path, rows: int, columns: int) -> None:
    """A MATLAB v5 file of 216 bytes whose one variable declares a rows x columns double matrix."""
    buffer = io.BytesIO()
    scipy.io.savemat(buffer, {"x": np.zeros((4, 1))}, do_compression=False)
    data = buffer.getvalue()
    dims, part = struct.pack("<IIii", 5, 8, 4, 1), struct.pack("<II", 9, 32)  # miINT32 dims, miDOUBLE data
    assert data.count(dims) == data.count(part) == 1
    path.write_bytes(data.replace(dims, struct.pack("<IIii", 5, 8, rows, columns))
                     .replace(part, struct.pack("<II", 9, rows * columns * 8)))


@pytest.mark.parametrize("kind", ["npz", "mat"])
def test_archive_size_bombs_are_refused_naming_the_file_size_and_limit(kind, tmp_path):
    path = tmp_path / f"bomb.{kind}"
    if kind == "npz":
        _npz_bomb(path, 2**31)
        what = "its arrays (the largest, 'gx', a (2147483648,) float64 array) would take 16 GiB"
    else:
        _mat_bomb(path, 2**27, 2)
        what = "its variables (the largest, 'x', a (134217728, 2) double matrix) would take 2 GiB"
    assert path.stat().st_size < 5000
    run = run_avar("compute", path, address_space=LIMIT)
    assert run.code == 1 and _one_line(run), run.stderr
    assert f"bomb.{kind}: {what} of memory, more than" in run.stderr


# --------------------------------------------------------------------------- gaps from the command line
def test_nan_policy_omit_reaches_the_readers_of_deviation_and_compute(tmp_path):
    x = X.copy()
    x[[100, 101, 700]] = np.nan
    path = tmp_path / "gappy.csv"  # a NaN cell, an empty cell, a "nan"
    path.write_text("freq\n" + "".join("\n" if i == 100 else "NaN\n" if i == 101 else "nan\n" if i == 700
                                       else f"{float(v)!r}\n" for i, v in enumerate(X)))
    refused = run_avar("deviation", path, "--data-type", "freq")
    assert refused.code == 1 and "3 missing or non-finite value(s); the first is in row 101" in refused.stderr
    assert "--nan-policy omit" in refused.stderr
    deviation, allan = tmp_path / "dev.csv", tmp_path / "av.csv"
    run = run_avar("deviation", path, "--data-type", "freq", "--nan-policy", "omit", "--stat", "oadev",
                   "--stat", "mdev", "--output", deviation)
    assert run.code == 0, run.stderr
    table = pd.read_csv(deviation)
    for stat in ("oadev", "mdev"):
        want = getattr(avar, stat)(x, data_type="freq", nan_policy="omit")
        rows = table[table["Stat"] == stat.upper()]
        np.testing.assert_array_equal(rows["#"], want.n)
        np.testing.assert_allclose(rows["Sigma"], want.deviation, rtol=1e-12)
    run = run_avar("compute", path, "--nan-policy", "omit", "--output", allan)
    assert run.code == 0, run.stderr
    np.testing.assert_allclose(pd.read_csv(allan)["AVar"], avar.avar(x, nan_policy="omit").allan, rtol=1e-12)
    np.testing.assert_array_equal(avar.read(path, nan_policy="omit")["freq"], x)


# --------------------------------------------------------------------------- options: the one typed, exit 2
@pytest.mark.parametrize("option, value", [("--rate", "0"), ("--rate", "-5"), ("--rate", "nan"), ("--rate", "inf"),
                                           ("--freq", "0"), ("--confidence", "0"), ("--confidence", "95")])
def test_bad_deviation_options_are_usage_errors_naming_the_option(option, value, tmp_path):
    path = tmp_path / "clock.csv"
    pd.DataFrame({"phase": X}).to_csv(path, index=False)
    run = run_avar("deviation", path, "--data-type", "phase", option, value)
    assert run.code == 2 and _one_line(run), run.stderr
    assert option in run.stderr and run.stdout == ""


# --------------------------------------------------------------------------- archives: one line naming the member
def test_archive_members_that_are_not_arrays_are_named(tmp_path):
    npz = tmp_path / "notes.npz"
    np.savez(npz, time=np.arange(100) / 10.0, gx=X[:100])
    with zipfile.ZipFile(npz, "a") as archive:
        archive.writestr("notes.txt", "taken on the roof")
    mat = tmp_path / "sparse.mat"
    scipy.io.savemat(mat, {"time": np.arange(100) / 10.0, "gx": scipy.sparse.csc_matrix(X[:100, None])})
    for path, fragment in ((npz, "notes.npz: member 'notes.txt' of the .npz archive is not a .npy array"),
                           (mat, "sparse.mat: variable 'gx' is a sparse matrix; save it full (full(gx))")):
        run = run_avar("compute", path)
        assert run.code == 1 and _one_line(run) and fragment in run.stderr, run.stderr


def test_a_mat_file_says_which_variables_it_took_and_never_renames_time(tmp_path):
    several = tmp_path / "several.mat"
    scipy.io.savemat(several, {"time": np.arange(500) / 10.0, "gx": X[:500], "temp": X[500:1000]})
    run = run_avar("compute", several, "--column", "gx")
    assert run.code == 0, run.stderr
    assert "several.mat: time from variable 'time'; data from 'gx'" in run.stderr
    labelled = tmp_path / "labelled.mat"  # the time vector and a char variable: once read as data 'gyro' at 1 Hz
    scipy.io.savemat(labelled, {"time": np.arange(500) / 10.0, "label": "gyro"})
    with pytest.raises(ValueError, match="labelled.mat: a MATLAB file holds the time vector 'time' and the text "
                                         "'label', but no data"):
        avar.read(labelled)


# --------------------------------------------------------------------------- files cut short
def test_a_csv_being_appended_is_read_up_to_its_last_complete_line(tmp_path):
    path = tmp_path / "growing.csv"
    path.write_text(TABLE + "20.0,0.12")  # the writer stopped mid-number of "0.1234"
    with pytest.warns(UserWarning, match=r"growing.csv: the last line \(line 2,002\) has no line end, as in a file "
                                         r"still being written; read up to line 2,001"):
        recording = avar.read(path)
    np.testing.assert_array_equal(recording["gx"], X)
    named = path.rename(tmp_path / "growing\x1b[2J.csv")  # the warning names the file: escaped like any name
    run = run_avar("compute", named, "--output", tmp_path / "av.csv")
    assert run.code == 0 and "\x1b" not in run.stderr
    assert "avar: warning: " in run.stderr and "growing\\x1b[2J.csv: the last line (line 2,002)" in run.stderr
    np.testing.assert_allclose(pd.read_csv(tmp_path / "av.csv")["AVar"], avar.avar(X, rate=100.0).allan, rtol=1e-12)


def test_nul_bytes_after_a_table_are_named_with_their_line(tmp_path):
    path = tmp_path / "crashed.csv"
    path.write_bytes(TABLE.encode() + bytes(1 << 20))  # a preallocated log: 1 MiB of zeros after the table
    run = run_avar("compute", path)
    assert run.code == 1 and _one_line(run), run.stderr
    assert "crashed.csv: line 2,002 holds NUL bytes (\\0), not text" in run.stderr
    assert "cut the file before line 2,002" in run.stderr


def test_a_symbolic_link_loop_is_named_as_such(tmp_path):
    os.symlink(tmp_path / "b.csv", tmp_path / "a.csv")
    os.symlink(tmp_path / "a.csv", tmp_path / "b.csv")
    run = run_avar("compute", tmp_path / "a.csv")
    assert run.code == 1 and _one_line(run)
    assert "a.csv: a loop of symbolic links" in run.stderr and "no such file" not in run.stderr


# --------------------------------------------------------------------------- the statistics' own messages
@pytest.mark.parametrize("statistic", DEVIATION_STATISTICS)
def test_empty_input_says_no_samples_and_names_the_statistic(statistic):
    with pytest.raises(ValueError, match=f"data holds no samples \\(an empty series\\); {statistic} needs freq data"):
        getattr(avar, statistic)(np.zeros(0), data_type="freq")


def test_theoh_errors_name_theoh():
    with pytest.raises(ValueError, match=r"taus \[1000000000.0\] are outside the valid range \[1.5, 1498.5\] s of "
                                         r"theoh with 2000 phase points") as outside:
        avar.theoh(X, data_type="phase", taus=[1e9])
    with pytest.raises(ValueError, match=r"theoh taus must be 0.75 m / rate with m even") as odd:
        avar.theoh(X, data_type="phase", taus=[600.75])
    assert "theo1" not in str(outside.value) + str(odd.value)


def test_tie_rms_of_frequency_data_at_m_equal_n_is_exactly_zero():
    result = avar.tierms(X, data_type="freq", taus="all")
    assert result.averaging_factors[-1] == X.size and result.n[-1] == 1
    assert result.deviation[-1] == 0.0 and result.variance[-1] == 0.0
    assert result.deviation[-2] > 0  # m = N - 1 has two terms that do not cancel
