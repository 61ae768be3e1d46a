"""chrony's ``tracking.log``, ``statistics.log`` and ``measurements.log`` (``log`` directive, chrony.conf(5)).

chronyd writes a banner (a line of ``=``, the column header, a line of ``=``) at the top of
each log and again every so many lines (``logbanner``, 32 by default); the banner lines are
skipped and counted. A record is whitespace-separated: the date and time (UTC, to the second),
an IP address (or reference ID), then the numbers of the log's columns:

* ``tracking.log`` (one line per clock update): stratum, ``Freq ppm``, ``Skew ppm``, ``Offset``
  (s, the estimated offset of the system clock, positive when it is fast of UTC: the default
  column), leap status, combined sources, ``Offset sd``, ``Rem. corr.``, ``Root delay``,
  ``Root disp.``, ``Max. error``;
* ``statistics.log`` (one line per source per regression): ``Std dev'n``, ``Est offset`` (s,
  the default), ``Offset sd``, ``Diff freq`` (s/s), ``Est skew``, ``Stress``, ``Ns``, ``Bs``,
  ``Nr``, ``Asym``;
* ``measurements.log`` (``measurements`` and ``rawmeasurements``: one line per NTP sample):
  leap, stratum, the RFC 5905 test bits, local and remote poll, score, ``Offset`` (s, theta:
  positive when the local clock is slow of the source; the default), ``Peer del.``,
  ``Peer disp.``, ``Root del.``, ``Root disp.``, reference ID, mode and time stamp sources.

Several sources interleave in statistics and measurements logs: one is taken (``source=``, by
default the most frequent) and the others are listed. Offsets are taken as written (the sign
conventions differ between the logs, as above; a deviation does not depend on the sign).
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np
import pandas as pd

from avar.io.clocks.build import Field, Parsed, numeric_frame
from avar.io.clocks.table import Table, Text, fail, is_number, numbers, pick_source, split_fields

_STAMP = ("Date", "Time", "IP Address")
TRACKING = {
    "St": Field("count", "the stratum of the local system"),
    "Freq ppm": Field("ppm", "the frequency of the system clock, positive when it runs fast"),
    "Skew ppm": Field("ppm bound", "the error bound of the frequency"),
    "Offset": Field("s", "the estimated offset of the system clock, positive when it is fast of UTC"),
    "L": None,
    "Co": Field("count", "the number of combined sources"),
    "Offset sd": Field("s sd", "the standard deviation of the combined offset"),
    "Rem. corr.": Field("s", "the offset correction remaining from the previous update, positive when the clock "
                             "is slow of UTC"),
    "Root delay": Field("s", "the network path delay to the reference clock"),
    "Root disp.": Field("s", "the dispersion accumulated back to the reference clock"),
    "Max. error": Field("s", "the maximum estimated error of the system clock since the previous update"),
}
STATISTICS = {
    "Std dev'n": Field("s sd", "the standard deviation of the source's measurements"),
    "Est offset": Field("s", "the source's estimated offset, positive when the local clock is fast of it"),
    "Offset sd": Field("s sd", "the standard deviation of the offset estimate"),
    "Diff freq": Field("s/s", "the rate at which the local clock gains on the source, relative to the "
                              "correction applied"),
    "Est skew": Field("s/s bound", "the error of the rate estimate"),
    "Stress": Field("ratio", "|old rate - new rate| / old rate error"),
    "Ns": Field("count", "the number of measurements in the regression"),
    "Bs": Field("count", "the new starting index"),
    "Nr": Field("count", "the number of runs"),
    "Asym": Field("ratio", "the asymmetry of the network jitter"),
}
MEASUREMENTS = {
    "L": None, "St": Field("count", "the stratum of the source"), "123": None, "567": None, "ABCD": None,
    "LP": Field("log2 s", "the local poll"), "RP": Field("log2 s", "the remote poll"),
    "Score": Field("score", "the poll score"),
    "Offset": Field("s", "the offset of the local clock from the source (RFC 5905 theta), positive when the "
                         "local clock is slow"),
    "Peer del.": Field("s", "the peer delay (RFC 5905 delta)"),
    "Peer disp.": Field("s", "the peer dispersion (RFC 5905 epsilon)"),
    "Root del.": Field("s", "the root delay (RFC 5905 DELTA)"),
    "Root disp.": Field("s", "the root dispersion (RFC 5905 EPSILON)"),
    "Refid": None, "Mode": None, "Tx": None, "Rx": None,
}
#: kind -> (file name, fields after the stamp, default column, the header's words that name it)
LOGS = {
    "chrony-tracking": ("tracking.log", TRACKING, "Offset", "Freq ppm"),
    "chrony-statistics": ("statistics.log", STATISTICS, "Est offset", "Std dev'n"),
    "chrony-measurements": ("measurements.log", MEASUREMENTS, "Offset", "123 567"),
}


def is_banner(line: str) -> bool:
    """A banner line: a rule of ``=`` or the column header (``   Date (UTC) Time ...``)."""
    stripped = line.lstrip()
    return stripped.startswith("=") or stripped.startswith("Date (UTC)")


def kind_of_header(line: str) -> str | None:
    """The chrony log whose column header ``line`` is, or None."""
    if not line.lstrip().startswith("Date (UTC)"):
        return None
    return next((kind for kind, (*_, words) in LOGS.items() if words in line), None)


def kind_of_record(fields: list[str]) -> str | None:
    """The chrony log a record (split on whitespace, after the date and time) belongs to, by its shape.

    >>> kind_of_record("2017-08-22 13:22:36 203.0.113.15 2 -3.541 0.075 -8.621e-06 N 2".split())
    'chrony-tracking'
    """
    leaps = ("N", "+", "-", "?")
    if len(fields) >= 16 and fields[3] in leaps and re.fullmatch(r"[01]{3}", fields[5]):
        return "chrony-measurements"
    if len(fields) >= 7 and fields[3].isdigit() and (len(fields) == 7 or fields[7] in leaps):
        return "chrony-tracking"
    if 10 <= len(fields) <= 13 and all(map(is_number, fields[3:])):
        return "chrony-statistics"
    return None


def _seconds(table: Table, text: Text) -> np.ndarray:
    """Each record's time (s from the first record's), from its date and time fields."""
    joined = table.cells["Date"] + " " + table.cells["Time"]
    stamps = pd.to_datetime(joined, format="%Y-%m-%d %H:%M:%S", errors="coerce")
    bad = stamps.isna().to_numpy()
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise fail(text.path, int(table.lines[i]), f"field 'Date (UTC) Time' is not a date and time "
                                                   f"(YYYY-MM-DD HH:MM:SS): {joined.iloc[i]!r}")
    ns = stamps.to_numpy(dtype="datetime64[ns]").astype(np.int64)
    return (ns - ns[0]) / 1e9


def read_chrony(text: Text, kind: str, source: Any = None) -> Parsed:
    """A chrony log of ``kind`` (``"chrony-tracking"``, ``"-statistics"``, ``"-measurements"``).

    ``source`` (statistics and measurements logs) picks the source (an IP address or reference
    ID); by default the most frequent.

    Examples
    --------
    >>> import os, tempfile
    >>> from avar.io.clocks.table import load_text
    >>> path = os.path.join(tempfile.mkdtemp(), "statistics.log")
    >>> with open(path, "w") as f:
    ...     _ = f.write("2017-08-22 13:22:36 203.0.113.15 6.261e-06 -3.247e-06 2.220e-06 1.874e-07 "
    ...                 "1.080e-07 7.8e-02 16 0 8 0.00\\n"
    ...                 "2017-08-22 13:23:40 203.0.113.15 6.261e-06 -2.000e-06 2.220e-06 1.874e-07 "
    ...                 "1.080e-07 7.8e-02 16 0 8 0.00\\n")
    >>> parsed = read_chrony(load_text(path), "chrony-statistics")
    >>> parsed.frame["Est offset"].tolist(), parsed.seconds.tolist()
    ([-3.247e-06, -2e-06], [0.0, 64.0])
    """
    name, fields, default, _ = LOGS[kind]
    if kind == "chrony-tracking" and source is not None:
        raise TypeError("source= picks a source of a statistics or measurements log; tracking.log has one series")
    rows, banner, blank = [], 0, 0
    for i, line in enumerate(text.lines):  # records start with a digit (the date): the test is that cheap
        if line[:1].isdigit():
            rows.append(i)
        elif is_banner(line):
            banner += 1
        elif line.strip():
            rows.append(i)  # not a record either: the parser names it
        else:
            blank += 1
    names = [*_STAMP, *fields]
    required = len(_STAMP) + list(fields).index(default) + 1
    numeric = {key: field for key, field in fields.items() if field is not None}
    table = split_fields(text, rows, names, required, f"chrony {name}", numeric)
    if not len(table.lines):
        raise fail(text.path, None, f"holds no chrony {name} records (only banner lines)")
    seconds = _seconds(table, text)
    keys = table.cells["IP Address"].to_numpy()
    if kind == "chrony-tracking":
        mask = np.ones(len(keys), dtype=bool)
        references = pick_source(keys, None, "reference", text.path).available
        selected = "the system clock (its references: " + ", ".join(f"{k} in {n} updates" for k, n in
                                                                    references.items()) + ")"
        available: dict[str, int] = {}
    else:
        mask, selected, available = pick_source(keys, source, "source", text.path)
    table = Table(table.cells[mask], table.lines[mask], table.unfinished)
    columns = {key: numbers(table, key, text.path, optional=key != default) for key in numeric}
    first = table.cells.iloc[0]
    skipped = {"banner lines ('=' rules and the column header)": banner} if banner else {}
    if blank:
        skipped["blank lines"] = blank
    if table.unfinished:
        skipped["unfinished last line (no line end)"] = 1
    return Parsed(f"chrony {name}", numeric_frame(columns), numeric, default, seconds[mask], table.lines,
                  start=pd.Timestamp(f"{first['Date']} {first['Time']}", tz="UTC"), selected=selected,
                  available=available, skipped=skipped)
