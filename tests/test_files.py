"""Reading series from files for the command line."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from avar.files import InputFileError, read_series


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_header_and_separators(tmp_path):
    for name, text in (
        ("comma.csv", "a,b\n1,2\n3,4\n5,6\n7,8\n"),
        ("semicolon.csv", "a;b\n1;2\n3;4\n5;6\n7;8\n"),
        ("tab.tsv", "a\tb\n1\t2\n3\t4\n5\t6\n7\t8\n"),
        ("space.txt", "a  b\n1  2\n3 4\n5   6\n7 8\n"),
    ):
        table = read_series(write(tmp_path, name, text))
        assert list(table.columns) == ["a", "b"], name
        np.testing.assert_array_equal(table.columns["b"], [2, 4, 6, 8])
        assert table.freq is None


def test_no_header_names_columns(tmp_path):
    one = read_series(write(tmp_path, "one.txt", "1.5\n2.5\n3.5\n4.5\n"))
    assert list(one.columns) == ["x"]
    two = read_series(write(tmp_path, "two.csv", "1,2\n3,4\n5,6\n7,8\n"))
    assert list(two.columns) == ["x1", "x2"]
    np.testing.assert_array_equal(two.columns["x1"], [1, 3, 5, 7])


def test_time_column_gives_the_rate(tmp_path):
    seconds = "\n".join(f"{t / 200:.3f},{np.sin(t)}" for t in range(1000))
    table = read_series(write(tmp_path, "t.csv", "time,gyro\n" + seconds + "\n"))
    assert list(table.columns) == ["gyro"]
    assert table.freq == pytest.approx(200.0, rel=1e-12)
    stamps = pd.date_range("2024-01-01", periods=50, freq="250ms")
    frame = pd.DataFrame({"timestamp": stamps.astype(str), "v": np.arange(50.0)})
    frame.to_csv(tmp_path / "d.csv", index=False)
    assert read_series(tmp_path / "d.csv").freq == pytest.approx(4.0)
    without_rate = read_series(tmp_path / "d.csv", rate_from_time=False)  # e.g. --freq given
    assert list(without_rate.columns) == ["v"] and without_rate.freq is None  # time is never data
    assert without_rate.time_column == "timestamp"


def test_time_column_must_be_regular_and_increasing(tmp_path):
    with pytest.raises(InputFileError, match="time column 'time' is irregular"):
        read_series(write(tmp_path, "i.csv", "time,v\n0,1\n1,2\n2,3\n4,4\n5,5\n"))
    with pytest.raises(InputFileError, match="must increase strictly"):
        read_series(write(tmp_path, "d.csv", "time,v\n0,1\n1,2\n1,3\n2,4\n"))


def test_npy_files(tmp_path):
    np.save(tmp_path / "a.npy", np.arange(10.0))
    np.save(tmp_path / "b.npy", np.ones((6, 3)))
    np.save(tmp_path / "c.npy", np.ones((2, 2, 2)))
    assert list(read_series(tmp_path / "a.npy").columns) == ["x"]
    assert list(read_series(tmp_path / "b.npy").columns) == ["x1", "x2", "x3"]
    with pytest.raises(InputFileError, match="1-D or 2-D"):
        read_series(tmp_path / "c.npy")


@pytest.mark.parametrize(
    "text, message",
    [
        ("", "the file is empty"),
        ("a,a\n1,2\n3,4\n5,6\n7,8\n", "duplicate column names"),
        ("time\n0\n1\n2\n3\n", "no data column besides the time column 'time'"),
        ("a\n1\n2\ninf\n4\n", r"column 'a' has 1 NaN/missing or infinite value\(s\); the first is in row 3 \(line 4\)"),
    ],
)
def test_bad_tables(tmp_path, text, message):
    with pytest.raises(InputFileError, match=message):
        read_series(write(tmp_path, "bad.csv", text))


def test_time_column_names_and_units(tmp_path):
    rows = "\n".join(f"{1_700_000_000_000_000_000 + 5_000_000 * k},{k % 3}" for k in range(100))
    ns = write(tmp_path, "ns.csv", "timestamp (ns),gx\n" + rows + "\n")
    assert read_series(ns, time_unit="ns").freq == pytest.approx(200.0, rel=1e-9)
    table = read_series(write(tmp_path, "u.csv", "Time [s],Gyro X [deg/s]\n0,1\n0.5,2\n1.0,3\n1.5,4\n"))
    assert list(table.columns) == ["Gyro X [deg/s]"] and table.freq == pytest.approx(2.0)
    # Epoch seconds printed with 6 decimals: rounding jitters the steps by ~1e-4 of a step.
    epoch = "\n".join(f"{1_700_000_000 + k / 100:.6f},{k}" for k in range(500))
    assert read_series(write(tmp_path, "e.csv", "time,v\n" + epoch + "\n")).freq == pytest.approx(100.0, rel=1e-6)


def test_comments_trailing_blank_lines_and_decimal_commas(tmp_path):
    table = read_series(write(tmp_path, "c.csv", "# logged by a sensor\na,b\n1,2\n3,4\n5,6\n7,8\n\n\n"))
    assert list(table.columns) == ["a", "b"] and len(table.columns) == 4
    euro = read_series(write(tmp_path, "eu.csv", "a;b\n0,5;1\n1,5;2\n2,5;3\n3,5;4\n"))
    np.testing.assert_array_equal(euro.columns["a"], [0.5, 1.5, 2.5, 3.5])
    with pytest.raises(InputFileError, match=r"row 2 \(line 3\)"):  # a blank line inside the data is missing
        read_series(write(tmp_path, "gap.csv", "a\n1\n\n3\n4\n5\n"))


def test_dates_must_be_iso_8601(tmp_path):
    with pytest.raises(InputFileError, match="neither numbers nor ISO 8601"):
        read_series(write(tmp_path, "dmy.csv", "date,v\n31/01/2024 10:00,1\n31/01/2024 10:01,2\n31/01/2024 10:02,3\n31/01/2024 10:03,4\n"))
