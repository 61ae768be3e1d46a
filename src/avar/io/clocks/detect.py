"""``read_clock_log()``: a clock log read by the reader its content calls for (or ``kind=``).

The format is found from the first lines, never from the file name: a ``RINEX VERSION / TYPE``
line of type ``C``; chrony's banner (its column header names the log) or, in a log cut after
its banner, the shape of a record (date, time, address, then the log's fields); a ptp4l, phc2sys
or ts2phc line anywhere (a syslog holds other lines too); ntpd records (a day number, seconds past midnight,
then seven numbers for loopstats or an address and a hex status for peerstats); else one or
two columns of numbers under ``#``/``;`` comments, a Stable32 data file.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from typing import Any

from avar.io.clocks import chrony, linuxptp, ntpd, rinex, stable32
from avar.io.clocks.build import Parsed, build_log
from avar.io.clocks.result import ClockLog
from avar.io.clocks.table import Text, clip, fail, is_number, load_text

#: kind -> (what it is, the reader, the selection arguments it takes)
KINDS: dict[str, tuple[str, Callable[..., Parsed], tuple[str, ...]]] = {
    "chrony-tracking": ("chrony tracking.log", lambda t, **k: chrony.read_chrony(t, "chrony-tracking", **k), ()),
    "chrony-statistics": ("chrony statistics.log",
                          lambda t, **k: chrony.read_chrony(t, "chrony-statistics", **k), ("source",)),
    "chrony-measurements": ("chrony measurements.log (measurements, rawmeasurements)",
                            lambda t, **k: chrony.read_chrony(t, "chrony-measurements", **k), ("source",)),
    "ntpd-loopstats": ("ntpd loopstats", lambda t, **k: ntpd.read_ntpd(t, "ntpd-loopstats", **k), ()),
    "ntpd-peerstats": ("ntpd peerstats", lambda t, **k: ntpd.read_ntpd(t, "ntpd-peerstats", **k), ("source",)),
    "linuxptp": ("ptp4l, phc2sys or ts2phc output", linuxptp.read_linuxptp, ("source", "states")),
    "rinex-clock": ("RINEX clock file (.clk)", rinex.read_rinex, ("satellite", "station")),
    "stable32": ("Stable32 data file (one or two columns)", stable32.read_stable32, ("data_type", "rate", "time_unit")),
}
#: Other spellings of the kinds.
ALIASES = {"tracking": "chrony-tracking", "statistics": "chrony-statistics", "measurements": "chrony-measurements",
           "rawmeasurements": "chrony-measurements", "measure": "chrony-measurements", "loopstats": "ntpd-loopstats",
           "peerstats": "ntpd-peerstats", "ptp4l": "linuxptp", "phc2sys": "linuxptp", "ts2phc": "linuxptp",
           "rinex": "rinex-clock", "clk": "rinex-clock"}
_MJD_RECORD = re.compile(r"^\s*\d{5}\s+\d{1,5}(?:\.\d*)?\s")
_CHRONY_RECORD = re.compile(r"^\d{4}-\d\d-\d\d \d\d:\d\d:\d\d\s")
_HEX = re.compile(r"^[0-9a-fA-F]{1,4}$")


def _ntpd_kind(fields: list[str]) -> str | None:
    """loopstats: 7 numbers (5 before ntp 4.2); peerstats: 2 numbers, an address, a hex status, 3 or 4 numbers."""
    if len(fields) in (5, 7) and all(map(is_number, fields)):
        return "ntpd-loopstats"
    if len(fields) in (7, 8) and not is_number(fields[2]) and _HEX.match(fields[3]) \
            and all(map(is_number, fields[4:])):
        return "ntpd-peerstats"
    return None


def detect(text: Text) -> str:
    """The kind of clock log ``text`` is, from its first lines.

    Raises
    ------
    ClockLogError
        None of the formats: the message quotes the first line and lists the formats.
    """
    lines = text.lines
    head = [line for line in lines[:200] if line.strip()]
    if head and (version := rinex.version_of(head[0])) is not None:
        if version.file_type != "C":
            raise fail(text.path, 1, f"is a RINEX file of type {version.file_type!r}, not clock data (type C)")
        return "rinex-clock"
    for line in head[:50]:
        if (kind := chrony.kind_of_header(line)) is not None:
            return kind
        if line.lstrip().startswith("Date (UTC)"):
            raise fail(text.path, lines.index(line) + 1, f"is a chrony log avar does not read (header "
                                                         f"{clip(line.strip(), 60)}); it reads tracking, statistics "
                                                         "and measurements logs")
    if re.search(linuxptp.PROGRAM, "\n".join(lines)):  # anywhere: a syslog may hold other lines first
        return "linuxptp"
    records = [line for line in head if not chrony.is_banner(line)]
    if records and _CHRONY_RECORD.match(records[0]) and (kind := chrony.kind_of_record(records[0].split())):
        return kind
    if records and _MJD_RECORD.match(records[0]) and (kind := _ntpd_kind(records[0].split())):
        return kind
    data = [line.split() for line in head if not stable32.is_comment(line)][:20]
    numeric = sum(all(map(is_number, fields)) for fields in data)  # a bad cell is the reader's to name
    if data and all(1 <= len(fields) <= 2 for fields in data) and 2 * numeric > len(data):
        return "stable32"
    first = head[0].strip() if head else ""
    raise fail(text.path, None, f"is not a clock log avar knows (first line {clip(first, 60)}); it reads "
                                + "; ".join(what for what, _, _ in KINDS.values()) + ". Pass kind= to force one: "
                                + ", ".join(KINDS))


def read_clock_log(path: str | os.PathLike, kind: str | None = None, column: str | None = None,
                   **selection: Any) -> ClockLog:
    """Read a clock log: time error (phase) or fractional frequency with its time stamps.

    Parameters
    ----------
    path : str or path-like
        The log (gzip, bzip2 or xz compressed logs are read as their text).
    kind : str, optional
        The format, found from the content when not given: ``"chrony-tracking"``,
        ``"chrony-statistics"``, ``"chrony-measurements"``, ``"ntpd-loopstats"``,
        ``"ntpd-peerstats"``, ``"linuxptp"``, ``"rinex-clock"`` or ``"stable32"`` (also
        ``"tracking"``, ``"loopstats"``, ``"ptp4l"``, ``"phc2sys"``, ``"rinex"``...).
    column : str, optional
        The field to take, by its name in the format (``"Freq ppm"``, ``"frequency"``,
        ``"Root delay"``...); by default the offset (phase): chrony tracking's ``Offset``,
        statistics' ``Est offset``, measurements' ``Offset``, ntpd's ``offset``, linuxptp's
        ``offset``, RINEX's ``clock bias``, Stable32's data column. Fields in ns are read as s,
        ppm and ppb as fractions.
    **selection
        Which series of a file holding several: ``source=`` (chrony statistics and measurements,
        ntpd peerstats: an address; linuxptp: ``"ptp4l master"``, ``"phc2sys CLOCK_REALTIME phc"``
        or one word of it), ``states=`` (linuxptp servo states kept: ``("s2", "s3")``, locked, by
        default; ``"all"``), ``satellite=`` / ``station=`` (RINEX clock), ``data_type=``,
        ``rate=`` (Hz) and ``time_unit=`` (Stable32).

    Returns
    -------
    ClockLog
        ``times`` (s since the first stamp), ``values``, ``data_type``, ``rate`` (Hz, 1 / the
        median step), ``gaps``, ``column`` (which field and why), ``columns`` (every numeric
        field), ``selected``/``available`` (the sources), ``skipped`` (lines left out, counted).

    Raises
    ------
    ClockLogError
        An unknown format, a malformed line (the message names the file, the line and the
        field), no such column or source, stamps that do not increase.
    TypeError
        A selection argument the format does not take.

    Examples
    --------
    >>> import os, tempfile
    >>> import avar
    >>> path = os.path.join(tempfile.mkdtemp(), "loopstats.20240101")
    >>> with open(path, "w") as f:
    ...     for k in range(4):
    ...         _ = f.write(f"60310 {64 * k}.000 {k * 1e-6:.9f} 13.778190 0.000351733 0.013380 6\\n")
    >>> log = avar.read_clock_log(path)
    >>> log.source, log.data_type, log.rate, log.values.tolist()
    ('ntpd loopstats', 'phase', 0.015625, [0.0, 1e-06, 2e-06, 3e-06])
    >>> avar.read_clock_log(path, column="frequency").values[:2].tolist()
    [1.377819e-05, 1.377819e-05]
    """
    text = load_text(path)
    if kind is None:
        kind = detect(text)
    else:
        key = str(kind).strip().lower()
        kind = ALIASES.get(key, key)
        if kind not in KINDS:
            raise ValueError(f"kind must be one of {', '.join(KINDS)} (or left out to detect it), got {kind!r}")
    _, reader, arguments = KINDS[kind]
    unknown = sorted(set(selection) - set(arguments))
    if unknown:
        takes = f"takes {', '.join(f'{a}=' for a in arguments)}" if arguments else "takes no selection argument"
        raise TypeError(f"{text.path}: a {KINDS[kind][0]} {takes}; got {', '.join(f'{a}=' for a in unknown)}")
    return build_log(reader(text, **selection), text.path, column)
