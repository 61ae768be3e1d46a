"""ntpd's ``loopstats`` and ``peerstats`` (the ``statistics`` command; ntp's "Monitoring Options", monopt.html).

Each line starts with the date (Modified Julian Day) and the time (seconds past UTC midnight):

* ``loopstats`` (one line per clock update): ``offset`` (s, the default column), ``frequency``
  (ppm: read as fractional frequency x 1e-6 with ``column="frequency"``), ``jitter`` (s, rms),
  ``wander`` (ppm, the frequency's Allan deviation) and the ``time constant`` of the clock
  discipline; the older five-field lines hold offset, frequency and time constant only;
* ``peerstats`` (one line per valid update of a peer): the peer address, its status word
  (hex), ``offset``, ``delay``, ``dispersion`` and ``jitter`` (all s; older lines have no
  jitter). Several peers interleave: one is taken (``source=``, by default the most frequent)
  and the others are listed.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from avar.io.clocks.build import Field, Parsed, numeric_frame
from avar.io.clocks.table import Table, Text, fail, numbers, pick_source, split_fields

_STAMP = ("MJD", "seconds")
LOOPSTATS = {
    "offset": Field("s", "the clock offset"),
    "frequency": Field("ppm", "the frequency offset"),
    "jitter": Field("s rms", "the rms jitter"),
    "wander": Field("ppm adev", "the frequency wander (Allan deviation)"),
    "time constant": Field("log2 s", "the time constant of the clock discipline"),
}
#: The loopstats of ntp 4.1 and before: three values per line.
LOOPSTATS_OLD = {name: LOOPSTATS[name] for name in ("offset", "frequency", "time constant")}
PEERSTATS = {
    "peer address": None,
    "status": None,
    "offset": Field("s", "the peer's clock offset"),
    "delay": Field("s", "the round-trip delay"),
    "dispersion": Field("s", "the dispersion"),
    "jitter": Field("s rms", "the rms jitter"),
}
#: Modified Julian Day 0.
MJD_EPOCH = pd.Timestamp("1858-11-17", tz="UTC")


def _seconds(table: Table, text: Text) -> tuple[np.ndarray, pd.Timestamp]:
    """Each record's time (s from the first record's) and the first record's date and time."""
    days = numbers(table, "MJD", text.path)
    seconds = numbers(table, "seconds", text.path)
    bad = (days != np.round(days)) | (seconds < 0) | (seconds >= 86401)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        field, value = ("MJD", days[i]) if days[i] != round(days[i]) else ("seconds", seconds[i])
        raise fail(text.path, int(table.lines[i]), f"field '{field}' is out of range: {float(value)!r} (MJD is a whole "
                                                   "day number, seconds are 0 to 86400 past midnight)")
    start = MJD_EPOCH + pd.Timedelta(days=int(days[0])) + pd.Timedelta(seconds=float(seconds[0]))
    return (days - days[0]) * 86400.0 + (seconds - seconds[0]), start


def read_ntpd(text: Text, kind: str, source: Any = None) -> Parsed:
    """An ntpd ``loopstats`` (``kind="ntpd-loopstats"``) or ``peerstats`` (``"ntpd-peerstats"``) file.

    ``source`` (peerstats) picks the peer by address; by default the most frequent.

    Examples
    --------
    >>> import os, tempfile
    >>> from avar.io.clocks.table import load_text
    >>> path = os.path.join(tempfile.mkdtemp(), "loopstats")
    >>> with open(path, "w") as f:
    ...     _ = f.write("50935 86336.031 0.000006019 13.778190 0.000351733 0.013380 6\\n"
    ...                 "50936 0.031 0.000004500 13.778200 0.000351733 0.013380 6\\n")
    >>> parsed = read_ntpd(load_text(path), "ntpd-loopstats")
    >>> parsed.seconds.tolist(), parsed.frame["frequency"].tolist(), str(parsed.start)
    ([0.0, 64.0], [13.77819, 13.7782], '1998-05-02 23:58:56.031000+00:00')
    """
    rows = [i for i, line in enumerate(text.lines) if line.strip()]
    blank = len(text.lines) - len(rows)
    if not rows:
        raise fail(text.path, None, "holds no records")
    if kind == "ntpd-loopstats":
        if source is not None:
            raise TypeError("source= picks a peer of a peerstats file; loopstats has one series")
        fields = LOOPSTATS_OLD if len(text.lines[rows[0]].split()) == 5 else LOOPSTATS
        table = split_fields(text, rows, [*_STAMP, *fields], len(_STAMP) + len(fields), "ntpd loopstats",
                             [*_STAMP, *fields])
        selected, available = None, {}
    else:
        fields = PEERSTATS
        table = split_fields(text, rows, [*_STAMP, *fields], len(_STAMP) + len(fields) - 1, "ntpd peerstats",
                             [*_STAMP, "offset", "delay", "dispersion", "jitter"])
        mask, selected, available = pick_source(table.cells["peer address"].to_numpy(), source, "peer", text.path)
        table = Table(table.cells[mask], table.lines[mask], table.unfinished)
    seconds, start = _seconds(table, text)
    numeric = {key: field for key, field in fields.items() if field is not None}
    columns = {key: numbers(table, key, text.path, optional=key == "jitter") for key in numeric}
    skipped = {"blank lines": blank} if blank else {}
    if table.unfinished:
        skipped["unfinished last line (no line end)"] = 1
    return Parsed(f"ntpd {kind.split('-')[1]}", numeric_frame(columns), numeric, "offset", seconds, table.lines,
                  start=start, selected=selected, available=available, skipped=skipped)
