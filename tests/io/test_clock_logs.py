"""avar.read_clock_log on the clock logs people have: each sample gives its exact values, times and rate.

The samples in tests/data/clock_logs/ were written from each format's documentation (README.md
there lists the sources). Malformed lines give one line naming the file, the line and the field
(or are counted and skipped in free-text logs such as ptp4l's).
"""

from __future__ import annotations

import gzip
import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import avar
from avar.io.clocks.detect import detect
from avar.io.clocks.result import ClockLogError
from avar.io.clocks.table import load_text

DATA = Path(__file__).resolve().parents[1] / "data" / "clock_logs"
SAMPLES = {
    "tracking.log": ("chrony-tracking", "chrony tracking.log"),
    "statistics.log": ("chrony-statistics", "chrony statistics.log"),
    "measurements.log": ("chrony-measurements", "chrony measurements.log"),
    "loopstats": ("ntpd-loopstats", "ntpd loopstats"),
    "peerstats": ("ntpd-peerstats", "ntpd peerstats"),
    "ptp4l.log": ("linuxptp", "linuxptp ptp4l"),
    "phc2sys.log": ("linuxptp", "linuxptp phc2sys"),
    "igs_sample.clk": ("rinex-clock", "RINEX clock 3.04"),
    "stable32_phase_mjd.dat": ("stable32", "Stable32 data file"),
    "stable32_freq.txt": ("stable32", "Stable32 data file"),
}


def edited(tmp_path, name, line, old, new):
    """A copy of sample ``name`` whose 1-based ``line`` has ``old`` replaced by ``new``."""
    lines = (DATA / name).read_text().splitlines(keepends=True)
    assert old in lines[line - 1], lines[line - 1]
    lines[line - 1] = lines[line - 1].replace(old, new, 1)
    path = tmp_path / name
    path.write_text("".join(lines))
    return path


def one_line_error(path, line, field):
    """The pattern of a malformed line's error: file, line, field."""
    return rf"^{re.escape(str(path))}, line {line}: .*{re.escape(field)}"


# --- each reader, each sample: exact values, times, rate --------------------------------------


def test_chrony_tracking():
    log = avar.read_clock_log(DATA / "tracking.log")
    assert log.values.tolist() == [-8.621e-06, -4.0e-06, 2.0e-06, 1.25e-06, -3.3e-07, 5.1e-07, -1.2e-06, 8.0e-07,
                                   2.2e-07, -6.0e-08]
    assert log.times.tolist() == [0, 64, 128, 192, 256, 384, 448, 512, 576, 640]
    assert (log.rate, log.data_type, log.source) == (1 / 64, "phase", "chrony tracking.log")
    assert log.column.startswith("chrony tracking.log: Offset (s), the estimated offset of the system clock")
    assert log.column.endswith("(the default)")
    assert (log.gaps.count, log.gaps.positions.tolist(), log.gaps.lengths.tolist()) == (1, [4], [128.0])
    assert log.skipped == {"banner lines ('=' rules and the column header)": 6}
    assert log.start == pd.Timestamp("2017-08-22 13:22:36", tz="UTC")
    assert log.lines.tolist() == [4, 5, 6, 7, 8, 9, 13, 14, 15, 16]
    assert list(log.columns) == ["St", "Freq ppm", "Skew ppm", "Offset", "Co", "Offset sd", "Rem. corr.",
                                 "Root delay", "Root disp.", "Max. error"]
    assert log.columns["Root delay"].tolist() == [1.534e-02] * 10
    freq = avar.read_clock_log(DATA / "tracking.log", column="freq ppm")
    assert freq.data_type == "freq"
    assert freq.values.tolist() == [f / 1e6 for f in (-3.541, -3.540, -3.539, -3.538, -3.540, -3.541, -3.539,
                                                     -3.538, -3.537, -3.538)]
    assert freq.column.startswith("chrony tracking.log: Freq ppm (ppm, read as a fraction)")
    assert freq.column.endswith("(asked for)")


def test_chrony_statistics_takes_the_most_frequent_source_and_lists_the_others():
    log = avar.read_clock_log(DATA / "statistics.log")
    assert log.values.tolist() == [-3.247e-06, -2.0e-06, 1.5e-06, 4.0e-07, -9.0e-07, 2.5e-06]
    assert log.times.tolist() == [0, 64, 128, 192, 256, 320]
    assert log.rate == 1 / 64
    assert dict(log.available) == {"203.0.113.15": 6, "198.51.100.7": 3}
    assert log.selected.startswith("203.0.113.15 (the most frequent of 2 sources: 6 of 9 records; others: 198.51")
    other = avar.read_clock_log(DATA / "statistics.log", source="198.51.100.7")
    assert other.values.tolist() == [1.1e-04, 1.23e-04, 9.8e-05]
    assert other.times.tolist() == [0, 114, 244]
    assert other.selected.startswith("198.51.100.7 (asked for")
    rate = avar.read_clock_log(DATA / "statistics.log", column="Diff freq")
    assert (rate.data_type, rate.values.tolist()) == ("freq", [1.874e-07] * 6)


def test_chrony_measurements():
    log = avar.read_clock_log(DATA / "measurements.log")
    assert log.values.tolist() == [-4.966e-03, -4.900e-03, -4.950e-03, -4.870e-03, -4.910e-03]
    assert log.times.tolist() == [0, 64, 128, 192, 256]
    assert dict(log.available) == {"203.0.113.15": 5, "198.51.100.7": 2}
    assert log.columns["Peer del."].tolist() == [2.296e-01, 2.290e-01, 2.301e-01, 2.288e-01, 2.295e-01]
    delay = avar.read_clock_log(DATA / "measurements.log", column="Peer del.", source="198.51.100.7")
    assert (delay.values.tolist(), delay.times.tolist()) == ([3.100e-02, 3.050e-02], [0, 128])
    with pytest.raises(ClockLogError, match=r"source='192.0.2.9' names no source of the file; it holds "
                                            r"203.0.113.15 \(5\), 198.51.100.7 \(2\)"):
        avar.read_clock_log(DATA / "measurements.log", source="192.0.2.9")


def test_ntpd_loopstats_across_midnight():
    log = avar.read_clock_log(DATA / "loopstats")
    assert log.values.tolist() == [6.019e-06, 4.5e-06, -1.25e-06, 8.75e-07, 2.0e-06, -3.125e-06, 1.5e-06, 2.5e-07]
    assert log.times.tolist() == [0, 64, 128, 192, 256, 320, 448, 512]
    assert (log.rate, log.gaps.count, log.gaps.positions.tolist()) == (1 / 64, 1, [5])
    assert log.start == pd.Timestamp("2023-02-25 23:55:44.123", tz="UTC")  # MJD 60000, 86144.123 s
    freq = avar.read_clock_log(DATA / "loopstats", column="frequency")
    assert freq.data_type == "freq"
    assert freq.values.tolist() == [f / 1e6 for f in (13.778190, 13.778200, 13.778150, 13.778100, 13.778125,
                                                     13.778180, 13.778160, 13.778140)]


def test_ntpd_peerstats():
    log = avar.read_clock_log(DATA / "peerstats")
    assert log.values.tolist() == [-1.2e-05, -1.15e-05, -1.075e-05, -1.125e-05, -1.25e-05, -1.1e-05]
    assert (log.times.tolist(), log.rate) == ([0, 16, 32, 48, 64, 80], 1 / 16)
    assert dict(log.available) == {"127.127.20.0": 6, "192.0.2.1": 2}
    server = avar.read_clock_log(DATA / "peerstats", source="192.0.2.1")
    assert (server.values.tolist(), server.times.tolist()) == ([0.001605376, 0.001598], [0, 64])
    assert server.columns["delay"].tolist() == [0.012, 0.012]


def test_ptp4l_keeps_the_locked_samples_and_counts_the_rest():
    log = avar.read_clock_log(DATA / "ptp4l.log")
    assert log.values.tolist() == [-2.89e-06, -1.56e-07, 1.022e-06, 2.41e-07, -2.3e-08, 3.18e-07, -8.7e-08, 1.2e-08]
    assert log.times.tolist() == [0, 0.999, 1.999, 3.0, 3.999, 7.0, 7.999, 8.999]
    assert (log.rate, log.gaps.count, log.gaps.positions.tolist()) == (1.0, 1, [4])
    assert log.skipped == {"lines of other kinds": 6, "servo state s0 (unlocked)": 1, "servo state s1 (clock step)": 1}
    assert log.column.startswith("linuxptp ptp4l: offset (ns, read as s), the master offset")
    assert log.columns["delay"].tolist()[:2] == [9320, 9318]
    assert log.start is None
    every = avar.read_clock_log(DATA / "ptp4l.log", states="all")
    assert every.values[:3].tolist() == [4.21e-06, 3.915e-06, -2.89e-06]
    assert every.columns["servo state"].tolist()[:3] == [0, 1, 2]
    freq = avar.read_clock_log(DATA / "ptp4l.log", column="freq")
    assert (freq.data_type, freq.values[:2].tolist()) == ("freq", [-3.16e-05, -3.049e-05])


def test_phc2sys():
    log = avar.read_clock_log(DATA / "phc2sys.log")
    assert log.values.tolist() == [8.88e-07, -1.2e-08, 3.1e-07, -9.5e-08, 4.1e-08]
    assert (log.times.tolist(), log.rate) == ([0, 1, 2, 3, 4], 1.0)
    assert log.selected.startswith("phc2sys CLOCK_REALTIME phc (the only servo")
    assert log.skipped["lines of other kinds"] == 4


def test_rinex_clock():
    log = avar.read_clock_log(DATA / "igs_sample.clk")
    assert log.values.tolist() == [-1.234567890123e-04, -1.234567812345e-04, -1.234567734567e-04,
                                   -1.234567656789e-04, -1.234567579011e-04, -1.234567501233e-04]
    assert (log.times.tolist(), log.rate, log.source) == ([0, 30, 60, 90, 120, 150], 1 / 30, "RINEX clock 3.04")
    assert dict(log.available) == {"ALGO00CAN": 4, "G01": 6, "G02": 5}
    assert log.selected.startswith("satellite G01 (the most frequent of 3 clocks")
    assert log.start == pd.Timestamp("2020-01-01 00:00:00")
    g02 = avar.read_clock_log(DATA / "igs_sample.clk", satellite="G02")
    assert g02.times.tolist() == [0, 30, 60, 120, 150]
    assert (g02.gaps.count, g02.to_series().attrs["missing"]) == (1, 1)
    station = avar.read_clock_log(DATA / "igs_sample.clk", station="ALGO00CAN", column="clock rate")
    assert (station.data_type, station.values.tolist()) == ("freq", [3.703703703704e-15] * 4)
    assert station.columns["clock bias"].tolist()[0] == 1.111111111111e-07
    with pytest.raises(ClockLogError, match="satellite='ALGO00CAN' names a station clock"):
        avar.read_clock_log(DATA / "igs_sample.clk", satellite="ALGO00CAN")


def test_rinex_default_is_the_first_of_the_clocks_with_most_records(tmp_path):
    last_g01 = "AS G01       2020 01 01 00 02 30.000000  2   -1.234567501233E-04  1.000000000000E-11\n"
    text = (DATA / "igs_sample.clk").read_text().replace(last_g01, "") + "DR G01       2020 01 01 00 02 30.000000  0\n"
    (tmp_path / "tie.clk").write_text(text)
    log = avar.read_clock_log(tmp_path / "tie.clk")  # G01 and G02 both 5 records: G01 is first
    assert log.selected.startswith("satellite G01") and dict(log.available) == {"ALGO00CAN": 4, "G01": 5, "G02": 5}
    assert log.skipped == {"DR (discontinuity) records": 1}


def test_stable32_files():
    log = avar.read_clock_log(DATA / "stable32_phase_mjd.dat")
    assert log.values.tolist() == [1.234e-09, 1.301e-09, 1.288e-09, 1.402e-09, 1.455e-09, 1.437e-09, 1.512e-09,
                                   1.598e-09]
    assert (log.times.tolist(), log.rate) == ([10800.0 * k for k in range(8)], 1 / 10800)
    assert log.column == ("Stable32 data file: phase (s), column 2 of 2, after the MJD time tags; phase as the header "
                          "says (the default)")
    assert log.start == pd.Timestamp("2017-09-04", tz="UTC") and log.skipped == {"comment lines": 2}
    freq = avar.read_clock_log(DATA / "stable32_freq.txt", rate=0.1)
    assert (freq.data_type, freq.rate, freq.times.tolist()[:3]) == ("freq", 0.1, [0.0, 10.0, 20.0])
    assert freq.values.tolist() == [2.1e-11, -1.3e-11, 8e-12, 1.9e-11, -4e-12, -2.2e-11, 1.1e-11, 3e-12]
    assert "frequency (s/s), the only column, no time tags: given rate 0.1 Hz" in freq.column
    assumed = avar.read_clock_log(DATA / "stable32_freq.txt", data_type="phase")
    assert (assumed.data_type, assumed.rate) == ("phase", 1.0)


# --- detection: by content, not by name --------------------------------------------------------


@pytest.mark.parametrize("name", sorted(SAMPLES))
def test_detection_picks_the_reader_by_content(name, tmp_path):
    kind, source = SAMPLES[name]
    assert detect(load_text(DATA / name)) == kind
    renamed = tmp_path / "log.txt"  # a neutral name: the content decides
    shutil.copy(DATA / name, renamed)
    assert avar.read_clock_log(renamed).source == source


@pytest.mark.parametrize("name", ["tracking.log", "statistics.log", "measurements.log"])
def test_a_chrony_log_cut_after_its_banner_is_found_by_its_records(name, tmp_path):
    path = tmp_path / "log"
    path.write_text("".join((DATA / name).read_text().splitlines(keepends=True)[3:]))
    assert avar.read_clock_log(path).source == SAMPLES[name][1]


def test_linuxptp_lines_far_into_a_syslog_are_found(tmp_path):
    path = tmp_path / "syslog"
    path.write_text("Mar  1 09:00:00 host kernel: [    0.000000] Linux version 6.1\n" * 2000
                    + (DATA / "ptp4l.log").read_text())
    log = avar.read_clock_log(path)
    assert log.n == 8 and log.skipped["lines of other kinds"] == 2006


def test_chrony_log_without_its_banner_and_gzip_compressed(tmp_path):
    lines = (DATA / "tracking.log").read_text().splitlines(keepends=True)
    cut = tmp_path / "tracking.log.1.gz"  # rotated after the first banner
    with gzip.open(cut, "wt") as handle:
        handle.writelines(lines[3:9])
    log = avar.read_clock_log(cut)
    assert log.source == "chrony tracking.log" and log.values.tolist()[:2] == [-8.621e-06, -4.0e-06]
    assert log.skipped == {}


@pytest.mark.parametrize("name", sorted(SAMPLES))
def test_oadev_runs_on_each_sample(name):
    log = avar.read_clock_log(DATA / name)
    dev = avar.oadev(log.values, rate=log.rate, data_type=log.data_type)
    assert dev.deviation.size >= 1 and np.all(np.isfinite(dev.deviation))


# --- malformed lines: one line naming the file, the line and the field --------------------------


@pytest.mark.parametrize(("name", "line", "old", "new", "field"), [
    ("tracking.log", 5, "-4.000e-06", "-4.000e-O6", "field 'Offset' is not a number: '-4.000e-O6'"),
    ("tracking.log", 6, "13:24:44", "13:24:4x", "field 'Date (UTC) Time' is not a date and time"),
    ("statistics.log", 7, " 1.500e-06", " 1.500e=06", "field 'Est offset' is not a number"),
    ("measurements.log", 7, " -4.950e-03  2.301e-01  1.577e-05  1.615e-01  7.446e-03 CB00717B 4B D K", "",
     "11 fields where a chrony measurements.log line has at least 12: field 'Offset' is missing"),
    ("loopstats", 3, "13.778150", "13.77815O", "field 'frequency' is not a number"),
    ("peerstats", 4, "-0.000010750", "-0.0000107.50", "field 'offset' is not a number"),
    ("igs_sample.clk", 20, "-1.234567812345E-04", "-1.234567812345E-0X", "field 'clock bias' is not a number"),
    ("igs_sample.clk", 16, "2020 01 01 00 00  0.000000  2   -1.2", "2020 13 01 00 00  0.000000  2   -1.2",
     "field 'epoch' is not a date and time"),
    ("igs_sample.clk", 15, " 3.703703703704E-15", " 3.7037037O3704E-15", "field 'clock rate' is not a number"),
    ("stable32_phase_mjd.dat", 4, "1.301e-09", "1.3O1e-09", "field 'column 2' is not a number"),
    ("stable32_phase_mjd.dat", 5, "58000.250 1.288e-09", "58000.250", "1 field, where a Stable32 data file has 2"),
])
def test_a_malformed_line_is_one_line_naming_file_line_and_field(tmp_path, name, line, old, new, field):
    path = edited(tmp_path, name, line, old, new)
    with pytest.raises(ClockLogError, match=one_line_error(path, line, field)) as error:
        avar.read_clock_log(path)
    assert "\n" not in str(error.value)


def test_a_malformed_ptp4l_line_is_counted_and_skipped(tmp_path):
    path = edited(tmp_path, "ptp4l.log", 10, "master offset       -156 s2", "master offset       -1x6 s2")
    log = avar.read_clock_log(path)
    assert log.skipped["offset lines that do not parse"] == 1
    assert log.n == 7 and -1.56e-07 not in log.values.tolist()


def test_stamps_must_increase(tmp_path):
    path = edited(tmp_path, "loopstats", 4, "60000 86336.123", "60000 86272.123")
    with pytest.raises(ClockLogError, match=one_line_error(path, 4, "time stamp +0 s from the previous sample's "
                                                                    "(line 3): stamps must increase")):
        avar.read_clock_log(path)


def test_an_unfinished_last_line_is_counted(tmp_path):
    path = tmp_path / "tracking.log"
    path.write_text((DATA / "tracking.log").read_text() + "2017-08-22 13:34:20 203.0.113.15     2     -3.5")
    log = avar.read_clock_log(path)
    assert log.n == 10 and log.skipped["unfinished last line (no line end)"] == 1


# --- linuxptp through syslog and the journal, several servos ------------------------------------


def test_linuxptp_syslog_journal_and_several_servos(tmp_path):
    path = tmp_path / "messages"
    path.write_text(
        "Mar  1 10:00:00 host systemd[1]: Started Precision Time Protocol (PTP) service.\n"
        "Mar  1 10:00:01 host ptp4l: [100.000] master offset        -23 s2 freq   +1234 path delay       567\n"
        "Mar  1 10:00:01 host phc2sys[913]: [100.250] CLOCK_REALTIME phc offset  -12 s2 freq  -3456 delay    789\n"
        "Mar  1 10:00:02 host ptp4l[812]: [101.000] [ptp4l.0.config] master offset  7 s2 freq +1240 path delay 566\n"
        "Mar  1 10:00:02 host phc2sys[913]: [101.250] CLOCK_REALTIME phc offset    5 s2 freq  -3450 delay    790\n"
        "Mar  1 10:00:03 host ptp4l[812]: [102.000] master offset        -4 s3 freq   +1236 path delay       567\n"
        "Mar  1 10:00:03 host ptp4l[812]: master offset        -4 s2 freq   +1236 path delay       567\n")
    log = avar.read_clock_log(path)
    assert log.values.tolist() == [-2.3e-08, 7e-09, -4e-09] and log.times.tolist() == [0, 1, 2]
    assert dict(log.available) == {"ptp4l master": 3, "phc2sys CLOCK_REALTIME phc": 2}
    assert log.skipped == {"lines of other kinds": 1, "offset lines without a monotonic time stamp": 1}
    phc = avar.read_clock_log(path, source="phc2sys")
    assert (phc.values.tolist(), phc.columns["delay"].tolist()) == ([-1.2e-08, 5e-09], [789, 790])
    locked = avar.read_clock_log(path, states="s2")
    assert locked.n == 2 and locked.skipped["servo state s3 (locked stable)"] == 1


# --- arguments, unknown files, the Series ---------------------------------------------------------


def test_kind_forces_a_reader_and_arguments_are_checked(tmp_path):
    assert avar.read_clock_log(DATA / "tracking.log", kind="tracking").source == "chrony tracking.log"
    with pytest.raises(ValueError, match="kind must be one of chrony-tracking"):
        avar.read_clock_log(DATA / "tracking.log", kind="nmea")
    with pytest.raises(TypeError, match="a chrony tracking.log takes no selection argument; got satellite="):
        avar.read_clock_log(DATA / "tracking.log", satellite="G01")
    with pytest.raises(ClockLogError, match="has no field 'Stratum'; its time error and frequency fields are "
                                            "'Freq ppm' \\(ppm\\), 'Offset' \\(s\\)"):
        avar.read_clock_log(DATA / "tracking.log", column="Stratum")
    with pytest.raises(ClockLogError, match="field 'St' of chrony tracking.log .* is neither a time error nor"):
        avar.read_clock_log(DATA / "tracking.log", column="st")
    unknown = tmp_path / "notes.txt"
    unknown.write_text("hello world\nsecond line\n")
    with pytest.raises(ClockLogError, match=r"notes.txt: is not a clock log avar knows \(first line 'hello world'\)"):
        avar.read_clock_log(unknown)
    with pytest.raises(ClockLogError, match="no such file"):
        avar.read_clock_log(tmp_path / "missing.log")
    (tmp_path / "empty.log").write_text("\n")
    with pytest.raises(ClockLogError, match="empty.log: is empty"):
        avar.read_clock_log(tmp_path / "empty.log")
    (tmp_path / "banner.log").write_text("".join((DATA / "tracking.log").read_text().splitlines(keepends=True)[:3]))
    with pytest.raises(ClockLogError, match="holds no chrony tracking.log records"):
        avar.read_clock_log(tmp_path / "banner.log")


def test_to_series_gives_a_regular_index_with_the_gaps_as_nan():
    log = avar.read_clock_log(DATA / "tracking.log")
    series = log.to_series()
    assert series.index.tolist() == [64.0 * k for k in range(11)]
    assert np.isnan(series.iloc[5]) and series.attrs["missing"] == 1 and series.name == "Offset"
    assert series.dropna().tolist() == log.values.tolist()
    res = avar.avar(series, nan_policy="omit")
    assert res.freq == 1 / 64
    jittered = avar.read_clock_log(DATA / "ptp4l.log").to_series()
    assert jittered.index.tolist() == [float(k) for k in range(10)] and jittered.attrs["missing"] == 2


def test_the_log_is_read_only_and_describes_itself():
    log = avar.read_clock_log(DATA / "statistics.log")
    with pytest.raises(ValueError):
        log.values[0] = 1.0
    text = log.describe()
    assert "statistics.log: chrony statistics.log, 6 samples of phase (s)" in text
    assert "source: 203.0.113.15 (the most frequent" in text and str(log) == text
