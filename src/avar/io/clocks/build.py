"""From a parsed log to a :class:`~avar.io.clocks.result.ClockLog`: the column, its units, the stamps.

Each format's reader returns a :class:`Parsed`: the numeric fields of the samples (file units),
what each field is (:class:`Field`), the default one, the time of each sample and its file line.
:func:`build_log` takes the column asked for (or the default), scales it to seconds or to a
fraction by its unit, checks that the stamps increase and finds the rate and the gaps.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from avar.io.clocks.result import ClockLog, find_gaps
from avar.io.clocks.table import fail

#: Units of the fields that are a clock series: unit -> (data_type, divisor to s or to a fraction).
#: (Dividing by an exact power of ten rounds once: -2890 ns is -2.89e-06 s, not -2.8900000000000003e-06.)
CLOCK_UNITS = {"s": ("phase", 1.0), "ns": ("phase", 1e9), "ppm": ("freq", 1e6), "ppb": ("freq", 1e9),
               "s/s": ("freq", 1.0)}


class Field(NamedTuple):
    """What a numeric field of a log holds: its unit (``"s"``, ``"ns"``, ``"ppm"``, ``"ppb"``, ``"s/s"``
    are clock series; any other, such as ``"count"``, is not) and a few words on its meaning."""

    unit: str
    meaning: str


class Parsed(NamedTuple):
    """A log as its format's reader parsed it, before a column is chosen.

    Attributes
    ----------
    source : str
        The format (``"chrony tracking.log"``).
    frame : pandas.DataFrame
        The numeric fields of the samples taken, float64 in the file's units, a row per sample.
    fields : Mapping[str, Field]
        What each column of ``frame`` holds.
    default : str
        The column taken when none is asked for.
    seconds : ndarray of float64
        Each sample's time (s from any origin).
    lines : ndarray of int64
        Each sample's file line (1-based).
    start : pandas.Timestamp or None
        The first sample's date and time, when the format gives one.
    selected : str or None
        The source taken among several, and why.
    available : Mapping[str, int]
        Every source and its record count.
    skipped : Mapping[str, int]
        Lines left out, by reason.
    """

    source: str
    frame: pd.DataFrame
    fields: Mapping[str, Field]
    default: str
    seconds: np.ndarray
    lines: np.ndarray
    start: Any = None
    selected: str | None = None
    available: Mapping[str, int] = {}
    skipped: Mapping[str, int] = {}


def _key(name: str) -> str:
    return re.sub(r"\s+", " ", str(name).strip().lower())


def choose_column(parsed: Parsed, column: Any, path: Path) -> str:
    """The field of ``parsed`` named ``column`` (case and spacing aside), or the default one."""
    if column is None:
        return parsed.default
    found = [name for name in parsed.fields if _key(name) == _key(column)]
    listing = ", ".join(f"'{name}' ({field.unit})" for name, field in parsed.fields.items()
                        if field.unit in CLOCK_UNITS)
    if not found:
        raise fail(path, None, f"{parsed.source} has no field {column!r}; its time error and frequency fields are "
                               f"{listing}")
    name = found[0]
    if parsed.fields[name].unit not in CLOCK_UNITS:
        raise fail(path, None, f"field '{name}' of {parsed.source} ({parsed.fields[name].meaning}) is neither a time "
                               f"error nor a frequency; choose one of {listing}")
    return name


def build_log(parsed: Parsed, path: Path, column: Any = None) -> ClockLog:
    """The :class:`ClockLog` of ``parsed``'s column ``column`` (None: the default).

    Raises
    ------
    ClockLogError
        No such column, a column that is neither phase nor frequency, fewer than two samples,
        a missing value, or stamps that do not increase (the message names the line).
    """
    name = choose_column(parsed, column, path)
    unit, meaning = parsed.fields[name]
    data_type, divisor = CLOCK_UNITS[unit]
    raw = parsed.frame[name].to_numpy(dtype=np.float64)
    lines = np.asarray(parsed.lines, dtype=np.int64)
    if np.isnan(raw).any():
        raise fail(path, int(lines[np.flatnonzero(np.isnan(raw))[0]]), f"field '{name}' is missing")
    if raw.size < 2:
        raise fail(path, None, f"holds {raw.size} sample(s) of {parsed.source} field '{name}'"
                               f"{f' from {parsed.selected}' if parsed.selected else ''}; a clock series needs at "
                               "least 2")
    seconds = np.asarray(parsed.seconds, dtype=np.float64)
    steps = np.diff(seconds)
    back = np.flatnonzero(~(steps > 0))
    if back.size:
        i = int(back[0])
        raise fail(path, int(lines[i + 1]), f"time stamp {steps[i]:+.6g} s from the previous sample's (line "
                                            f"{int(lines[i])}): stamps must increase"
                                            f"{f' ({back.size} such steps)' if back.size > 1 else ''}")
    times = seconds - seconds[0]
    found = find_gaps(times)
    why = "the default" if column is None else "asked for"
    units = unit if divisor == 1.0 else f"{unit}, read as {'s' if data_type == 'phase' else 'a fraction'}"
    frame = parsed.frame.set_axis(pd.Index(times, name="time (s)"), axis=0)
    return ClockLog(times=times, values=raw / divisor, data_type=data_type,
                    column=f"{parsed.source}: {name} ({units}), {meaning} ({why})", rate=1.0 / found.median_step,
                    gaps=found.gaps, source=parsed.source, columns=frame, path=str(path), start=parsed.start,
                    selected=parsed.selected, available=dict(parsed.available), skipped=dict(parsed.skipped),
                    lines=lines)


def numeric_frame(columns: Mapping[str, np.ndarray]) -> pd.DataFrame:
    """A float64 frame of equal-length columns, in order."""
    return pd.DataFrame({name: np.asarray(values, dtype=np.float64) for name, values in columns.items()})
