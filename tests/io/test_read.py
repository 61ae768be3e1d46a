"""avar.read on files as users write them: each layout gives the right channels and rate."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import avar
from avar.io.read import InputFileError, read

RNG = np.random.default_rng(7)


def write(tmp_path, name, text, encoding="utf-8"):
    path = tmp_path / name
    path.write_bytes(text.encode(encoding) if isinstance(text, str) else text)
    return path


def rows(times, *columns, sep=",", fmt="{!r}"):
    return "".join(sep.join([str(t), *(fmt.format(float(c[i])) for c in columns)]) + "\n" for i, t in enumerate(times))


# --- separators, headers, no headers ------------------------------------------------------


@pytest.mark.parametrize(
    "name, text",
    [
        ("comma.csv", "a,b\n1,2\n3,4\n5,6\n7,8\n"),
        ("semicolon.csv", "a;b\n1;2\n3;4\n5;6\n7;8\n"),
        ("tab.tsv", "a\tb\n1\t2\n3\t4\n5\t6\n7\t8\n"),
        ("space.txt", "a  b\n1  2\n3 4\n5   6\n7 8\n"),
        ("quoted.csv", '"a","b"\n1,2\n3,4\n5,6\n7,8\n'),
        ("crlf.csv", "a,b\r\n1,2\r\n3,4\r\n5,6\r\n7,8\r\n"),
    ],
)
def test_separators_and_headers(tmp_path, name, text):
    rec = read(write(tmp_path, name, text))
    assert rec.names == ("a", "b")
    np.testing.assert_array_equal(rec["b"], [2, 4, 6, 8])
    assert rec.freq == 1.0 and rec.time_column is None and "no time column" in rec.rate_source


def test_no_header_names_columns(tmp_path):
    assert read(write(tmp_path, "one.txt", "1.5\n2.5\n3.5\n4.5\n")).names == ("x",)
    two = read(write(tmp_path, "two.csv", "1,2\n3,4\n5,6\n7,8\n"))
    assert two.names == ("x1", "x2")
    np.testing.assert_array_equal(two["x1"], [1, 3, 5, 7])


def test_savetxt_comment_header_is_a_header(tmp_path):
    """numpy.savetxt(header=...) writes '# time gx gy': a header, not a comment, and time is time."""
    t = np.arange(3000) / 300.0
    gx, gy = RNG.standard_normal(3000), RNG.standard_normal(3000)
    path = tmp_path / "log.txt"
    np.savetxt(path, np.column_stack([t, gx, gy]), header="time gx gy")
    assert path.read_text().startswith("# time gx gy\n")
    rec = read(path)
    assert rec.names == ("gx", "gy")
    assert rec.freq == pytest.approx(300.0, rel=1e-12)
    assert rec.time_column == "time"
    np.testing.assert_array_equal(rec["gx"], np.loadtxt(path)[:, 1])
    # a free comment before a header row stays a comment
    other = read(write(tmp_path, "c.csv", "# logged by a sensor\na,b\n1,2\n3,4\n5,6\n7,8\n\n\n"))
    assert other.names == ("a", "b") and other.n == 4


def test_decimal_commas_with_semicolons_and_after_integer_rows(tmp_path):
    euro = read(write(tmp_path, "eu.csv", "a;b\n0,5;1\n1,5;2\n2,5;3\n3,5;4\n"))
    np.testing.assert_array_equal(euro["a"], [0.5, 1.5, 2.5, 3.5])
    # 70 kB of integer rows first: past what the layout sniffer sees
    late = read(write(tmp_path, "late.csv", "a;b\n" + "1;2\n" * 20_000 + "1,25;-2,5e-1\n" * 3))
    assert late.n == 20_003
    np.testing.assert_array_equal(late["a"][-4:], [1, 1.25, 1.25, 1.25])
    np.testing.assert_array_equal(late["b"][-1:], [-0.25])
    tabbed = read(write(tmp_path, "eu.tsv", "zeit\tgx\n0,00\t1,5\n0,01\t2,5\n0,02\t3,5\n0,03\t4,5\n"))
    np.testing.assert_array_equal(tabbed["gx"], [1.5, 2.5, 3.5, 4.5])


def test_trailing_semicolon_adds_no_column(tmp_path):
    rec = read(write(tmp_path, "t.csv", "x;\n1;\n2;\n3;\n4;\n"))
    assert rec.names == ("x",)
    headless = read(write(tmp_path, "h.csv", "1;2;\n3;4;\n5;6;\n7;8;\n"))
    assert headless.names == ("x1", "x2")
    with pytest.raises(InputFileError, match=r"line 3 has a value after the last column"):
        read(write(tmp_path, "spill.csv", "a;b;\n1;2;\n3;4;5\n5;6;\n7;8;\n"))


def test_utf8_bom_without_header_keeps_the_first_sample(tmp_path):
    rec = read(write(tmp_path, "bom.csv", b"\xef\xbb\xbf1.5,2\n2.5,3\n3.5,4\n4.5,5\n"))
    assert rec.names == ("x1", "x2") and rec.n == 4
    np.testing.assert_array_equal(rec["x1"], [1.5, 2.5, 3.5, 4.5])
    with_header = read(write(tmp_path, "bomh.csv", b"\xef\xbb\xbftime,v\n0,1\n1,2\n2,3\n3,4\n"))
    assert with_header.names == ("v",) and with_header.time_column == "time"


# --- time columns, units, rates -----------------------------------------------------------


@pytest.mark.parametrize(
    "header, scale",
    [("timestamp_ms", 1e3), ("timestamp (ns)", 1e9), ("t_ns", 1e9), ("time_us", 1e6), ("Time [s]", 1.0)],
)
def test_time_units_from_the_name(tmp_path, header, scale):
    t = np.arange(2000) / 200.0
    ticks = np.round(t * scale).astype(np.int64) + 1_700_000_000 * int(scale) if scale > 1 else t
    gx = RNG.standard_normal(2000)
    rec = read(write(tmp_path, "u.csv", f"{header},gx\n" + "".join(f"{k},{float(v)!r}\n" for k, v in zip(ticks, gx))))
    assert rec.names == ("gx",)  # a time column is never data
    assert rec.freq == pytest.approx(200.0, rel=1e-12)
    np.testing.assert_array_equal(rec["gx"], gx)


def test_t_ns_is_time_and_temperature_t_is_data(tmp_path):
    n = 1000
    stamps = 1_700_000_000_000_000_000 + np.arange(n, dtype=np.int64) * 2_500_000
    temp = 25 + np.arange(n) * 1e-3
    text = "t_ns,gx,T\n" + "".join(
        f"{s},{float(g)!r},{float(c)!r}\n" for s, g, c in zip(stamps, RNG.standard_normal(n), temp))
    rec = read(write(tmp_path, "a.csv", text))
    assert rec.names == ("gx", "T") and rec.time_column == "t_ns"
    assert rec.freq == pytest.approx(400.0, rel=1e-12)
    only_temperature = read(write(tmp_path, "b.csv", "T,gx\n" + rows(temp[:50], temp[:50])))
    assert only_temperature.names == ("T", "gx") and only_temperature.time_column is None


def test_epoch_nanoseconds_without_unit_in_the_name(tmp_path):
    stamps = 1_700_000_000_000_000_000 + np.arange(500, dtype=np.int64) * 10_000_000
    rec = read(write(tmp_path, "e.csv", "timestamp,v\n" + "".join(f"{s},{i}\n" for i, s in enumerate(stamps))))
    assert rec.freq == pytest.approx(100.0, rel=1e-12)
    assert "by their size" in rec.rate_source


def test_300_hz_stamped_to_the_millisecond(tmp_path):
    """Steps of 3, 3, 4 ms: accepted, 300 Hz (not the median's 333 Hz), jitter reported."""
    ms = np.round(np.arange(3000) * 1000 / 300).astype(np.int64)
    rec = read(write(tmp_path, "ms.csv", "time_ms,gx\n" + "".join(f"{m},{i % 7}\n" for i, m in enumerate(ms))))
    assert rec.freq == pytest.approx(300.0, rel=1e-3)
    steps = np.diff(ms) * 1e-3
    assert rec.jitter == pytest.approx(np.sqrt(np.mean((steps - 1 / 300) ** 2)), rel=1e-6)
    note = rec.rate_note()
    assert note.startswith("at 300 Hz from time column 'time_ms' (jitter 0.47") and note.endswith(" ms rms)")


def test_epoch_seconds_with_jitter(tmp_path):
    n = 5000
    t = 1_700_000_000.0 + np.arange(n) / 100.0 + RNG.normal(0, 2e-4, n)  # 0.2 ms rms jitter
    rec = read(write(tmp_path, "j.csv", "time,gx\n" + rows([f"{v:.6f}" for v in t], RNG.standard_normal(n))))
    assert rec.freq == pytest.approx(100.0, rel=1e-4)
    assert rec.jitter == pytest.approx(2e-4 * np.sqrt(2), rel=0.1)  # a step is the difference of two stamps


def test_iso_date_times(tmp_path):
    stamps = pd.date_range("2024-01-01", periods=50, freq="250ms")
    pd.DataFrame({"timestamp": stamps.astype(str), "v": np.arange(50.0)}).to_csv(tmp_path / "d.csv", index=False)
    rec = read(tmp_path / "d.csv")
    assert rec.freq == pytest.approx(4.0) and rec.names == ("v",)
    with pytest.raises(InputFileError, match=r"time column 'date' holds neither numbers nor ISO 8601"):
        read(write(tmp_path, "dmy.csv", "date,v\n31/01/2024 10:00,1\n31/01/2024 10:01,2\n31/01/2024 10:02,3\n31/01/2024 10:03,4\n"))


def test_mixed_time_zone_offsets_name_the_column(tmp_path):
    text = "stamp,v\n" + "".join(f"2024-01-01T00:00:0{i}{'+01:00' if i != 2 else '+02:00'},{i}\n" for i in range(6))
    with pytest.raises(InputFileError, match=r"time column 'stamp' mixes time-zone offsets"):
        read(write(tmp_path, "tz.csv", text))
    same = "stamp,v\n" + "".join(f"2024-01-01T00:00:0{i}+01:00,{i}\n" for i in range(6))
    assert read(write(tmp_path, "tz1.csv", same)).freq == pytest.approx(1.0)


def test_gaps_are_refused_with_where_then_ignored(tmp_path):
    t = np.arange(1000) / 100.0
    t[600:] += 0.5  # a 0.51 s step before row 601
    t[800:] += 1.0
    path = write(tmp_path, "gap.csv", "time,gx\n" + rows([f"{v:.2f}" for v in t], np.arange(1000.0)))
    with pytest.raises(InputFileError, match=r"2 gap\(s\).*between samples 600 and 601 \(row 601 at t = 6\.5 s\)"):
        read(path)
    rec = read(path, gaps="ignore")
    assert rec.gaps_ignored and rec.gap_rows.tolist() == [600, 800]
    np.testing.assert_allclose(rec.gap_steps, [0.51, 1.01])
    assert rec.freq == pytest.approx(100.0, rel=1e-9)  # from the contiguous steps
    assert "2 gap(s) ignored" in rec.rate_note()


def test_time_must_increase(tmp_path):
    with pytest.raises(InputFileError, match=r"does not increase strictly: sample 3"):
        read(write(tmp_path, "d.csv", "time,v\n0,1\n1,2\n1,3\n2,4\n"))


def test_freq_overrides_the_time_column_which_stays_out(tmp_path):
    rec = read(write(tmp_path, "f.csv", "time,v\n0,1\n1,2\n2,3\n3,4\n"), rate=25)
    assert rec.freq == 25.0 and rec.names == ("v",) and rec.rate_source == "given"


def test_rostopic_csv_both_time_columns_stay_out(tmp_path):
    stamps = 1_700_000_000_000_000_000 + np.arange(100, dtype=np.int64) * 5_000_000
    text = "%time,field.header.stamp,field.angular_velocity.x\n" + "".join(
        f"{s + 777},{s},{i * 0.5}\n" for i, s in enumerate(stamps))
    rec = read(write(tmp_path, "r.csv", text))
    assert rec.names == ("field.angular_velocity.x",)
    assert rec.freq == pytest.approx(200.0, rel=1e-12)


# --- numbers and files ------------------------------------------------------------------


def test_integers_beyond_2_53_stay_exact(tmp_path):
    big = 2**60
    values = [big + i * i for i in range(64)]
    rec = read(write(tmp_path, "i.csv", "v\n" + "".join(f"{v}\n" for v in values)))
    assert rec["v"].dtype == np.int64 and rec["v"].tolist() == values
    res = avar.avar(rec["v"])
    exact = avar.avar(np.array([i * i for i in range(64)], dtype=np.float64))
    np.testing.assert_allclose(res.allan, exact.allan, rtol=1e-12)


def test_npy_plain_and_structured(tmp_path):
    np.save(tmp_path / "a.npy", np.arange(10.0))
    np.save(tmp_path / "b.npy", np.ones((10, 3)))
    np.save(tmp_path / "c.npy", np.ones((2, 2, 2)))
    assert read(tmp_path / "a.npy").names == ("x",)
    assert read(tmp_path / "b.npy").names == ("x1", "x2", "x3")
    with pytest.raises(InputFileError, match=r"1-D or 2-D"):
        read(tmp_path / "c.npy")
    table = np.zeros(500, dtype=[("t_ns", "i8"), ("gx", "f8"), ("gy", "f4")])
    table["t_ns"] = np.arange(500) * 4_000_000
    table["gx"] = RNG.standard_normal(500)
    np.save(tmp_path / "s.npy", table)
    rec = read(tmp_path / "s.npy")
    assert rec.names == ("gx", "gy") and rec.freq == pytest.approx(250.0, rel=1e-12)
    np.testing.assert_array_equal(rec["gx"], table["gx"])


def test_npz_archives_of_named_columns_or_an_array_and_its_names(tmp_path):
    t = np.arange(500) * 0.01
    gx, gy = RNG.standard_normal(500), RNG.standard_normal(500)
    np.savez(tmp_path / "keys.npz", time=t, gx=gx, gy=gy)  # a column per key; time times them
    rec = read(tmp_path / "keys.npz")
    assert rec.names == ("gx", "gy") and rec.freq == pytest.approx(100.0, rel=1e-12)
    np.testing.assert_array_equal(rec["gy"], gy)
    names = np.array(["Gyro. X", "Gyro. Y", "Gyro. Z", "Accel. X", "Accel. Y", "Accel. Z"])
    data = RNG.standard_normal((400, 6))
    np.savez_compressed(tmp_path / "named.npz", data=data, columns=names)  # as the ADIS16405 logs come
    rec = read(tmp_path / "named.npz", rate=100.0)
    assert rec.names == tuple(names) and rec.freq == 100.0
    np.testing.assert_array_equal(rec["Accel. Z"], data[:, 5])
    np.savez(tmp_path / "timed.npz", time=np.arange(400) / 50.0, data=data, columns=names)  # a time beside
    rec = read(tmp_path / "timed.npz")
    assert rec.names == tuple(names) and rec.freq == pytest.approx(50.0, rel=1e-12)
    np.savez(tmp_path / "plain.npz", np.ones((50, 2)))  # one unnamed array: as .npy
    assert read(tmp_path / "plain.npz").names == ("x1", "x2")
    for name, arrays, message in [
        ("two.npz", dict(a=np.ones((9, 2)), b=np.ones((9, 2))), r"holds a float64\[9, 2\], b float64\[9, 2\]"),
        ("rows.npz", dict(t=np.ones(8), data=np.ones((9, 2))), r"holds t float64\[8\], data float64\[9, 2\]"),
        ("ragged.npz", dict(a=np.ones(9), b=np.ones(8)), r"equal-length 1-D arrays"),
        ("badnames.npz", dict(data=np.ones((9, 2)), columns=np.array(["x"])), r"1 column name\(s\) \['x'\] for 2"),
        ("objects.npz", dict(data=np.array([{"a": 1}], dtype=object)), r"member .data.npy. holds Python objects"),
    ]:
        np.savez(tmp_path / name, **arrays)
        with pytest.raises(InputFileError, match=message):
            read(tmp_path / name)
    (tmp_path / "broken.npz").write_bytes(b"PK\x03\x04 not a zip")
    with pytest.raises(InputFileError, match=r"broken.npz: not a readable .npz archive"):
        read(tmp_path / "broken.npz")


def refuses_a_cut_copy(path, size: int, message: str, **options) -> None:
    """The first ``size`` bytes of ``path`` as ``cut<suffixes>``: an error naming that file."""
    cut = path.with_name("cut" + "".join(path.suffixes))
    cut.write_bytes(path.read_bytes()[:size])
    with pytest.raises(InputFileError, match=rf"{cut.name}: {message}"):
        read(cut, **options)


@pytest.mark.parametrize("suffix", [".gz", ".bz2", ".xz"])
@pytest.mark.parametrize("progress", [False, True])
def test_compressed_text_reads_as_its_text(tmp_path, suffix, progress):
    frame = pd.DataFrame({"time": np.arange(3000) / 100.0, "gx": RNG.standard_normal(3000),
                          "gy": np.arange(3000) * 7})
    frame.to_csv(tmp_path / "log.csv", index=False)
    frame.to_csv(tmp_path / f"log.csv{suffix}", index=False)  # pandas compresses by the suffix
    plain, packed = read(tmp_path / "log.csv"), read(tmp_path / f"log.csv{suffix}", progress=progress)
    assert packed.names == plain.names == ("gx", "gy") and packed.freq == plain.freq
    np.testing.assert_array_equal(packed["gx"], plain["gx"])
    assert packed["gy"].dtype == np.int64
    whole = (tmp_path / f"log.csv{suffix}").stat().st_size
    refuses_a_cut_copy(tmp_path / f"log.csv{suffix}", whole // 2, r"a damaged (gzip|bz2|lzma) file", progress=progress)


def test_parquet_tables_by_their_magic_bytes(tmp_path):
    pytest.importorskip("pyarrow")
    times = pd.date_range("2026-01-01", periods=2000, freq="5ms", tz="Europe/Paris")
    frame = pd.DataFrame({"time": times, "gx": RNG.standard_normal(2000), "count": np.arange(2000)})
    frame.to_parquet(tmp_path / "imu.parquet")
    frame.to_parquet(tmp_path / "imu.dat")  # found by its first bytes, not its name
    for name in ("imu.parquet", "imu.dat"):
        rec = read(tmp_path / name)
        assert rec.names == ("gx", "count") and rec.freq == pytest.approx(200.0, rel=1e-12)
        np.testing.assert_array_equal(rec["gx"], frame["gx"].to_numpy())
        assert rec["count"].dtype == np.int64
    frame.assign(label="a").to_parquet(tmp_path / "text.parquet")
    with pytest.raises(InputFileError, match=r"column 'label' has dtype .*, not numbers or times"):
        read(tmp_path / "text.parquet")
    refuses_a_cut_copy(tmp_path / "imu.parquet", 300, r"not a readable Parquet file")


def test_matlab_files_of_vectors_or_a_named_matrix(tmp_path):
    from scipy.io import savemat

    t, data = np.arange(600) / 50.0, RNG.standard_normal((600, 3))
    savemat(tmp_path / "named.mat", {"time": t.reshape(-1, 1), "data": data,
                                     "names": np.array(["gx", "gy", "gz"], dtype=object)})  # a cell array
    rec = read(tmp_path / "named.mat")
    assert rec.names == ("gx", "gy", "gz") and rec.freq == pytest.approx(50.0, rel=1e-12)
    np.testing.assert_array_equal(rec["gz"], data[:, 2])
    savemat(tmp_path / "vectors.mat", {"time": t, "ax": data[:, 0]})  # 1 x N row vectors
    rec = read(tmp_path / "vectors.mat")
    assert rec.names == ("ax",) and rec.freq == pytest.approx(50.0, rel=1e-12)
    savemat(tmp_path / "struct.mat", {"log": {"gx": data[:, 0]}})
    with pytest.raises(InputFileError, match=r"variable\(s\) \['log'\] are cell arrays or structs"):
        read(tmp_path / "struct.mat")
    refuses_a_cut_copy(tmp_path / "named.mat", 200, r"not a readable MATLAB file")


def test_imu_from_named_columns(tmp_path):
    n = 400
    data = RNG.standard_normal((n, 6))
    frame = pd.DataFrame(data, columns=["gx", "gy", "gz", "ax", "ay", "az"])
    frame.insert(0, "time", np.arange(n) / 100.0)
    frame.to_csv(tmp_path / "imu.csv", index=False)
    imu = read(tmp_path / "imu.csv", gyro=["gx", "gy", "gz"], accel=["ax", "ay", "az"])
    assert isinstance(imu, avar.IMU) and imu.freq == pytest.approx(100.0)
    np.testing.assert_array_equal(imu.data, data)
    with pytest.raises(ValueError, match=r"columns cannot be combined with gyro/accel"):
        read(tmp_path / "imu.csv", columns=["gx"], gyro=["gy"])
    with pytest.raises(InputFileError, match=r"\['time'\] are time columns; a time column is never data"):
        read(tmp_path / "imu.csv", columns=["time", "gx"])


@pytest.mark.parametrize(
    "content, message",
    [
        (b'a,b\n"1,2\n3,4\n5,6\n7,8\n', "not a readable CSV"),
        (b"a,b\n1,2\n3,oops\n5,6\n7,8\n", r"column 'b' is not numeric: row 2 \(line 3\) holds 'oops'"),
        (b"a\n1\n2\n3\n", r"3 sample\(s\); the Allan variance needs at least 4"),
        (b"a\n1\n2\nnan\n4\n\n6\n", r"column 'a' has 2 missing or non-finite value\(s\); the first is in row 3 \(line 4\)"),
        (b"a,a\n1,2\n3,4\n5,6\n7,8\n", r"duplicate column names \['a'\]"),
        (b"# only a comment\n\n", r"holds no data"),
    ],
)
def test_bad_files_say_what_and_where(tmp_path, content, message):
    with pytest.raises(InputFileError, match=message):
        read(write(tmp_path, "bad.csv", content))


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(InputFileError, match=r"no such file"):
        read(tmp_path / "nothing.csv")
    with pytest.raises(InputFileError, match=r"is a directory"):
        read(tmp_path)


def test_a_million_digit_cell_is_not_echoed_whole(tmp_path):
    for cell in ("9" * 1_000_000, "x" * 1_000_000):
        with pytest.raises(InputFileError) as info:
            read(write(tmp_path, "big.csv", "a\n1\n2\n" + cell + "\n4\n5\n"))
        message = str(info.value)
        assert len(message) < 400 and "row 3 (line 4)" in message and "1000000 characters" in message
