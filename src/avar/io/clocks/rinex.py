"""RINEX clock files (``.clk``; "RINEX Extensions to Handle Clock Information", versions 2.00 to 3.04).

The header ends at ``END OF HEADER``; its first line (``RINEX VERSION / TYPE``) holds the
version and the file type ``C``. A data record is::

    AS G01       2020 01 01 00 00  0.000000  2   -1.234567890123E-04  1.000000000000E-11

the data type (``AR`` receiver or station clock, ``AS`` satellite clock, ``CR`` calibration,
``DR`` discontinuity, ``MS`` monitor), the clock's name (4 characters up to version 3.02, 9 in
3.04), the epoch (year, month, day, hour, minute, second), the number of values (1 to 6), then
the ``clock bias`` (s: the default column, as phase) and its sigma; when there are more than
two values a continuation line holds the ``clock rate`` (s/s, as fractional frequency) and its
sigma, the ``clock acceleration`` (1/s) and its sigma. The fields are read by whitespace, which
fits every version's layout.

A file holds one series per satellite (``AS``) and per station (``AR``): one is taken
(``satellite="G05"`` or ``station="ALGO00CAN"``; by default the first of those with the most
records) and all are listed; ``CR``, ``DR`` and ``MS`` records are counted and skipped.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from avar.io.clocks.build import Field, Parsed, numeric_frame
from avar.io.clocks.table import Table, Text, fail, numbers, pick_source, split_fields

RECORD = ("type", "name", "year", "month", "day", "hour", "minute", "second", "values", "clock bias", "bias sigma")
CONTINUATION = ("clock rate", "rate sigma", "clock acceleration", "acceleration sigma")
FIELDS = {
    "clock bias": Field("s", "the clock bias"),
    "bias sigma": Field("s sigma", "the clock bias sigma"),
    "clock rate": Field("s/s", "the clock rate"),
    "rate sigma": Field("s/s sigma", "the clock rate sigma"),
    "clock acceleration": Field("1/s", "the clock acceleration"),
    "acceleration sigma": Field("1/s sigma", "the clock acceleration sigma"),
}
TYPES = {"AR": "station", "AS": "satellite", "CR": "calibration", "DR": "discontinuity", "MS": "monitor"}


class Version(NamedTuple):
    """What a RINEX file's first line says: its format version and file type (``"C"``: clock data)."""

    version: str
    file_type: str


def version_of(line: str) -> Version | None:
    """The :class:`Version` of a ``RINEX VERSION / TYPE`` line, or None for another line.

    >>> version_of("     3.04           C                   G                        RINEX VERSION / TYPE")
    Version(version='3.04', file_type='C')
    """
    if "RINEX VERSION / TYPE" not in line:
        return None
    fields = line.split()
    return Version(fields[0], fields[1][:1]) if len(fields) >= 2 else None


def _header_end(text: Text) -> int:
    for i, line in enumerate(text.lines):
        if "END OF HEADER" in line[60:] or line.strip() == "END OF HEADER":
            return i
    raise fail(text.path, None, "has no 'END OF HEADER' line: not a complete RINEX clock file")


def _choose(table: Table, satellite: Any, station: Any, path) -> tuple[np.ndarray, str, dict[str, int]]:
    """The records of the clock asked for (or of the first with the most records) among AS and AR records."""
    if satellite is not None and station is not None:
        raise TypeError("pass satellite= or station=, not both")
    kinds = table.cells["type"].to_numpy(dtype=object)
    clocks = np.isin(kinds, ["AS", "AR"])
    names = table.cells["name"].to_numpy(dtype=object)[clocks]
    argument, wanted = ("station", station) if station is not None else ("satellite", satellite)
    mask, selected, available = pick_source(names, wanted, "clock", path, argument=argument)
    kind = TYPES[kinds[clocks][mask][0]]
    if wanted is not None and kind != argument:
        raise fail(path, None, f"{argument}={wanted!r} names a {kind} clock (AR records are stations, AS satellites)")
    full = np.zeros(len(kinds), dtype=bool)
    full[np.flatnonzero(clocks)[mask]] = True
    return full, f"{kind} {selected}", available


def read_rinex(text: Text, satellite: Any = None, station: Any = None) -> Parsed:
    """One clock's bias (and rate, with its continuation lines) from a RINEX clock file.

    Examples
    --------
    >>> import os, tempfile
    >>> from avar.io.clocks.table import load_text
    >>> path = os.path.join(tempfile.mkdtemp(), "igs.clk")
    >>> with open(path, "w") as f:
    ...     _ = f.write("     3.04           C                   G                        RINEX VERSION / TYPE\\n"
    ...                 "                                                                 END OF HEADER\\n"
    ...                 "AS G01       2020 01 01 00 00  0.000000  2   -1.234567890123E-04  1.0E-11\\n"
    ...                 "AS G01       2020 01 01 00 00 30.000000  2   -1.234567890000E-04  1.0E-11\\n")
    >>> parsed = read_rinex(load_text(path))
    >>> parsed.frame["clock bias"].tolist() == [-1.234567890123e-04, -1.23456789e-04]   # parsed exactly
    True
    >>> parsed.seconds.tolist(), parsed.selected
    ([0.0, 30.0], 'satellite G01 (the only clock)')
    """
    head = version_of(text.lines[0]) if text.lines else None
    if head is None or head.file_type != "C":
        raise fail(text.path, 1, "is not a RINEX clock file (its first line is no 'RINEX VERSION / TYPE' of type C)")
    end = _header_end(text)
    body = np.arange(end + 1, len(text.lines))
    first = np.array([text.lines[i][:2] for i in body], dtype=object)
    blank = np.array([not text.lines[i].strip() for i in body], dtype=bool)
    records = np.isin(first, list(TYPES))
    continuation = ~records & ~blank
    if body.size and continuation[0]:
        raise fail(text.path, int(body[0]) + 1, f"field 'type' is not a clock data type ({', '.join(TYPES)}): "
                                                f"{text.lines[body[0]][:2]!r}")
    owner = np.cumsum(records) - 1  # the record each line belongs to
    table = split_fields(text, body[records], RECORD, RECORD.index("values") + 1, "RINEX clock record",
                         RECORD[2:])
    if not len(table.lines):
        raise fail(text.path, None, "holds no clock data records after its header")
    counts = numbers(table, "values", text.path)
    extra = split_fields(text, body[continuation], CONTINUATION, 1, "RINEX clock continuation", CONTINUATION)
    more = np.full((len(table.lines), len(CONTINUATION)), np.nan)
    if len(extra.lines):
        values = np.column_stack([numbers(extra, name, text.path, optional=True) for name in CONTINUATION])
        more[owner[continuation]] = values
    mask, selected, available = _choose(table, satellite, station, text.path)
    others = pd.Series(table.cells["type"].to_numpy()[~np.isin(table.cells["type"].to_numpy(), ["AS", "AR"])])
    skipped = {f"{kind} ({TYPES[kind]}) records": int(n) for kind, n in others.value_counts(sort=False).items()}
    if blank.any():
        skipped["blank lines"] = int(blank.sum())
    table, more, counts = Table(table.cells[mask], table.lines[mask]), more[mask], counts[mask]
    stamp = {key: numbers(table, key, text.path) for key in ("year", "month", "day", "hour", "minute", "second")}
    whole = pd.DataFrame({key: stamp[key].astype(np.int64) for key in ("year", "month", "day", "hour", "minute")})
    epochs = pd.to_datetime(whole, errors="coerce")
    if epochs.isna().any():
        i = int(np.flatnonzero(epochs.isna().to_numpy())[0])
        raise fail(text.path, int(table.lines[i]), f"field 'epoch' is not a date and time: {whole.iloc[i].tolist()}")
    ns = epochs.to_numpy(dtype="datetime64[ns]").astype(np.int64)
    seconds = (ns - ns[0]) / 1e9 + (stamp["second"] - stamp["second"][0])
    columns = {"clock bias": numbers(table, "clock bias", text.path),
               "bias sigma": np.where(counts >= 2, numbers(table, "bias sigma", text.path, optional=True), np.nan),
               **{name: more[:, k] for k, name in enumerate(CONTINUATION)}}
    start = pd.Timestamp(epochs.iloc[0]) + pd.Timedelta(seconds=float(stamp["second"][0]))
    return Parsed(f"RINEX clock {head.version}", numeric_frame(columns), FIELDS, "clock bias", seconds, table.lines,
                  start=start, selected=selected, available=available, skipped=skipped)
