"""Stable32 data files: one column of phase (s) or fractional frequency, or a time tag and the data.

Stable32 (Hamilton Technical Services; its manual's "Read" function and file formats) reads
plain text with the data in the last of one or two columns, the first of two being a time tag,
usually an MJD. Header lines of comments (``#`` or ``;``) and blank lines are skipped and
counted. The file does not say whether it holds phase or frequency: ``data_type="phase"`` or
``"freq"`` says so; without it, a header that names one of them (``# phase data, tau0 = 1 s``)
decides, else phase is assumed and :attr:`ClockLog.column` says so.

Time tags between 15,000 and 100,000 are MJD (days; 1899 to 2132), other tags seconds
(``time_unit="mjd"`` or ``"s"`` decides). A file without time tags is sampled at ``rate=``
(Hz; 1 Hz, tau0 = 1 s, when not given).
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from avar.io.clocks.build import Field, Parsed, numeric_frame
from avar.io.clocks.ntpd import MJD_EPOCH
from avar.io.clocks.table import Text, fail, numbers, split_fields

DATA_TYPES = {"phase": "phase", "freq": "freq", "frequency": "freq"}
TIME_UNITS = {"mjd": "mjd", "days": "mjd", "s": "s", "seconds": "s"}
#: Time tags in this range are MJD (days).
MJD_RANGE = (15_000.0, 100_000.0)


def is_comment(line: str) -> bool:
    """A Stable32 header line: ``#`` or ``;`` first."""
    return line.lstrip().startswith(("#", ";"))


def _data_type(data_type: Any, header: str) -> tuple[str, str]:
    if data_type is not None:
        if str(data_type).lower() not in DATA_TYPES:
            raise ValueError(f"data_type must be 'phase' or 'freq', got {data_type!r}")
        return DATA_TYPES[str(data_type).lower()], "as data_type= says"
    said = {kind for kind, word in (("phase", r"\bphase"), ("freq", r"\bfreq")) if re.search(word, header, re.I)}
    if len(said) == 1:
        kind = said.pop()
        return kind, "as the header says"
    return "phase", "assumed (the file does not say; pass data_type='freq' for fractional frequency)"


def read_stable32(text: Text, data_type: Any = None, rate: Any = None, time_unit: Any = None) -> Parsed:
    """A Stable32 data file's data column, timed by its time tags or by ``rate`` (Hz).

    Examples
    --------
    >>> import os, tempfile
    >>> from avar.io.clocks.table import load_text
    >>> path = os.path.join(tempfile.mkdtemp(), "phase.dat")
    >>> with open(path, "w") as f:
    ...     _ = f.write("# phase data (s)\\n58000.000 1.5e-9\\n58000.125 1.7e-9\\n")
    >>> parsed = read_stable32(load_text(path))
    >>> parsed.frame["phase"].tolist(), parsed.seconds.tolist(), parsed.fields["phase"].meaning
    ([1.5e-09, 1.7e-09], [0.0, 10800.0], 'column 2 of 2, after the MJD time tags; phase as the header says')
    """
    comments = [line for line in text.lines if is_comment(line)]
    rows = [i for i, line in enumerate(text.lines) if line.strip() and not is_comment(line)]
    blank = len(text.lines) - len(rows) - len(comments)
    if not rows:
        raise fail(text.path, None, "holds no data lines")
    table = split_fields(text, rows, ["column 1", "column 2"], 1, "Stable32 data", ["column 1", "column 2"])
    widths = table.cells.notna().sum(axis=1).to_numpy()
    wrong = np.flatnonzero((widths > 2) | (widths != widths[0]))
    if wrong.size:
        i = int(wrong[0])
        found = f"{int(widths[i])} field{'s' if widths[i] != 1 else ''}"
        raise fail(text.path, int(table.lines[i]), f"{found}, where a Stable32 data file has {int(widths[0])} on "
                                                   "every line (one or two columns)")
    kind, why = _data_type(data_type, "\n".join(comments))
    name, unit = ("phase", "s") if kind == "phase" else ("frequency", "s/s")
    start = None
    if widths[0] == 1:
        if time_unit is not None:
            raise TypeError("time_unit= reads a time tag column; this file has a single column")
        given = 1.0 if rate is None else float(rate)
        if not np.isfinite(given) or given <= 0:
            raise ValueError(f"rate must be a positive number of Hz, got {rate!r}")
        values = numbers(table, "column 1", text.path)
        seconds = np.arange(values.size) / given
        where = f"the only column, no time tags: {'given' if rate is not None else 'assumed'} rate {given:g} Hz"
        fields = {name: Field(unit, f"{where}; {name} {why}")}
        columns = {name: values}
    else:
        if rate is not None:
            raise TypeError("rate= times a single-column file; this file's time tags give its rate")
        tags, values = numbers(table, "column 1", text.path), numbers(table, "column 2", text.path)
        if time_unit is None:
            unit_of_tags = "mjd" if MJD_RANGE[0] <= tags.min() and tags.max() < MJD_RANGE[1] else "s"
        elif str(time_unit).lower() in TIME_UNITS:
            unit_of_tags = TIME_UNITS[str(time_unit).lower()]
        else:
            raise ValueError(f"time_unit must be 'mjd' or 's', got {time_unit!r}")
        seconds = (tags - tags[0]) * (86400.0 if unit_of_tags == "mjd" else 1.0)
        if unit_of_tags == "mjd":
            start = MJD_EPOCH + np.timedelta64(int(round(tags[0] * 86400e6)), "us")
        label = "MJD" if unit_of_tags == "mjd" else "time"
        fields = {label: Field("days" if label == "MJD" else "s tag", f"the time tags ({label})"),
                  name: Field(unit, f"column 2 of 2, after the {label} time tags; {name} {why}")}
        columns = {label: tags, name: values}
    skipped = {"comment lines": len(comments)} if comments else {}
    if blank:
        skipped["blank lines"] = blank
    if table.unfinished:
        skipped["unfinished last line (no line end)"] = 1
    return Parsed("Stable32 data file", numeric_frame(columns), fields, name, seconds, table.lines, start=start,
                  skipped=skipped)
