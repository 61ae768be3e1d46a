"""Time columns: which columns time the samples, in what unit, and the rate they give.

A column is a time column by its name (case-insensitive): ``time``, ``t``,
``timestamp``, ``stamp``, ``sec``, ``seconds``, ``datetime``, ``date``, ``epoch``,
``%time`` (``rostopic echo -p``), ``header.stamp``..., optionally followed by a unit
that sets the unit of its numbers: ``time_ms``, ``t_ns``, ``Time [s]``,
``timestamp (ns)``, ``time us``. A temperature-like column (``T``, ``temp``,
``temperature``, ``T [C]``, ``degC``...) is never time. A time column is never data.

Numbers without a unit in the name are seconds, except epoch stamps, whose size tells
their unit (> 1e17: ns, > 1e14: us, > 1e11: ms, as written by clocks since 1970).
Integers are differenced exactly in int64; ISO 8601 date-times are read by pandas.
"""

from __future__ import annotations

import re

import numpy as np
import pandas as pd

from avar._time_steps import analyze_steps, describe_gaps

#: Seconds per unit.
UNIT_SECONDS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
_UNIT_SPELLINGS = {
    "s": "s", "sec": "s", "secs": "s", "second": "s", "seconds": "s",
    "ms": "ms", "msec": "ms", "millis": "ms", "milliseconds": "ms",
    "us": "us", "usec": "us", "micros": "us", "microseconds": "us", "\u00b5s": "us", "\u03bcs": "us",
    "ns": "ns", "nsec": "ns", "nanos": "ns", "nanoseconds": "ns",
}  # fmt: skip
#: Bare names (without unit) of time columns.
TIME_NAMES = frozenset(
    {"time", "t", "timestamp", "timestamps", "time_stamp", "stamp", "sec", "secs", "seconds", "datetime", "date",
     "epoch", "%time", "elapsed", "header.stamp", "field.header.stamp"}
)
_UNIT = "|".join(sorted(map(re.escape, _UNIT_SPELLINGS), key=len, reverse=True))
_NAME = re.compile(rf"^(?P<base>.*?)(?:\s*[\[(]\s*(?P<bracket>{_UNIT})\s*[\])]|[_ ](?P<suffix>{_UNIT}))?$")
_TEMPERATURE = re.compile(r"^(temp|temperature|tmp)(\b|_|$)|celsius|kelvin|fahrenheit|degc|deg_c|\u00b0", re.I)
#: Epoch stamps: first value above this magnitude -> unit (checked in order).
EPOCH_UNITS = ((1e17, "ns"), (1e14, "us"), (1e11, "ms"))


def is_temperature(name: str) -> bool:
    """``T``, ``temp``, ``Temperature [C]``, ``imu_degC``... (never time).

    >>> [is_temperature(n) for n in ("T", "temp_imu", "T [C]", "t", "time", "gx")]
    [True, True, True, False, False, False]
    """
    stripped = name.strip()
    if re.match(r"^T(\b|_|$)", stripped):  # capital T: temperature, unless it carries a time unit
        match = _NAME.match(stripped.lower())
        return not (match and (match["bracket"] or match["suffix"]))
    return bool(_TEMPERATURE.search(stripped))


def time_unit_of(name: str) -> tuple[bool, str | None]:
    """Whether ``name`` names a time column, and the unit its name gives (or None).

    >>> [time_unit_of(n) for n in ("time", "timestamp_ms", "Time [s]", "timestamp (ns)", "t_ns", "T", "gx")]
    [(True, None), (True, 'ms'), (True, 's'), (True, 'ns'), (True, 'ns'), (False, None), (False, None)]
    """
    if is_temperature(name):
        return False, None
    match = _NAME.match(name.strip().lower())
    base = match["base"].strip() if match else ""
    unit = match["bracket"] or match["suffix"] if match else None
    if base in TIME_NAMES or base.endswith(".header.stamp"):
        return True, _UNIT_SPELLINGS[unit] if unit else None
    return False, None


def time_columns(names) -> list[str]:
    """The time columns among ``names``, in order."""
    return [name for name in names if time_unit_of(str(name))[0]]


def _clip(value: object, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


def to_seconds(values: pd.Series | np.ndarray, name: str, unit: str | None) -> tuple[np.ndarray, np.ndarray, str]:
    """Steps and times (s from the first sample) of a time column, and the unit used.

    Integers are differenced exactly in int64 before scaling; ``unit=None`` takes the
    name's unit, else the epoch size rule, else seconds.
    """
    given = time_unit_of(name)[1] if unit is None else unit
    series = pd.Series(values, copy=False)
    if series.dtype.kind not in "iufM":  # text: numbers with decimal commas, or date-times
        numbers = pd.to_numeric(series.astype("string").str.strip().str.replace(",", ".", regex=False), errors="coerce")
        if numbers.notna().all():
            series = numbers.astype(np.float64)
    kind = series.dtype.kind
    if kind in "iuf":
        array = series.to_numpy()
        if array.size and not np.isfinite(array.astype(np.float64)).all():
            row = int(np.flatnonzero(~np.isfinite(array.astype(np.float64)))[0])
            raise ValueError(f"time column {name!r} has a missing or non-finite value in row {row + 1}")
        used = given
        if used is None:
            first = abs(float(array[0])) if array.size else 0.0
            used = next((u for bound, u in EPOCH_UNITS if first > bound), "s")
        if kind in "iu":
            ticks = array.astype(np.int64)
            steps_ticks = np.diff(ticks)
            elapsed = (ticks - ticks[0]).astype(np.float64) * UNIT_SECONDS[used]
            return steps_ticks.astype(np.float64) * UNIT_SECONDS[used], elapsed, used
        elapsed = (array - array[0]) * UNIT_SECONDS[used]
        return np.diff(array) * UNIT_SECONDS[used], elapsed, used
    if kind == "M":
        ticks = series.to_numpy().astype("datetime64[ns]").astype(np.int64)
        return np.diff(ticks).astype(np.float64) * 1e-9, (ticks - ticks[0]).astype(np.float64) * 1e-9, "date-time"
    text = series.astype(str).str.strip()
    try:
        stamps = pd.to_datetime(text, format="ISO8601")
    except (ValueError, TypeError) as error:
        if "mixed time" in str(error).lower() or "tz-aware" in str(error).lower() or "offset" in str(error).lower():
            raise ValueError(
                f"time column {name!r} mixes time-zone offsets (first value {_clip(text.iloc[0])}); "
                "write every stamp with the same offset, or in UTC"
            ) from None
        raise ValueError(
            f"time column {name!r} holds neither numbers nor ISO 8601 date-times (e.g. 2024-01-31T12:00:00.010); "
            f"first value {_clip(text.iloc[0])}"
        ) from None
    if stamps.dtype == object:  # mixed offsets parse to an object column of Timestamps
        raise ValueError(
            f"time column {name!r} mixes time-zone offsets (first value {_clip(text.iloc[0])}); "
            "write every stamp with the same offset, or in UTC"
        )
    if stamps.isna().any():
        row = int(np.flatnonzero(stamps.isna().to_numpy())[0])
        raise ValueError(f"time column {name!r} has a missing date-time in row {row + 1}")
    if stamps.dt.tz is not None:
        stamps = stamps.dt.tz_convert("UTC").dt.tz_localize(None)
    ticks = stamps.to_numpy().astype("datetime64[ns]").astype(np.int64)
    elapsed = (ticks - ticks[0]).astype(np.float64) * 1e-9
    return np.diff(ticks).astype(np.float64) * 1e-9, elapsed, "date-time"


def rate_of(values, name: str, unit: str | None, gaps: str = "error", what: str = "") -> dict:
    """Rate, jitter and gaps of a time column (see :func:`avar._time_steps.analyze_steps`).

    Returns a dict of :class:`avar.Recording` fields. Gaps raise ValueError (with their
    count and the first row and time) unless ``gaps="ignore"``.
    """
    steps, elapsed, used = to_seconds(values, name, unit)
    prefix = f"{what}: " if what else ""
    try:
        found = analyze_steps(steps)
    except ValueError as error:
        raise ValueError(f"{prefix}time column {name!r}: {error}") from None
    gap_positions = found.gaps
    if gap_positions.size and gaps != "ignore":
        message = describe_gaps(gap_positions, steps, found.median_step, lambda i: float(elapsed[i]))
        raise ValueError(
            f"{prefix}time column {name!r} has {message}; cut the file at the gaps, or pass gaps='ignore' "
            "(--gaps ignore) to treat the samples as contiguous"
        )
    source = f"time column {name!r}" + ("" if used in ("s", "date-time") or unit is not None
                                        or time_unit_of(name)[1] else f" (stamps in {used}, by their size)")
    return {
        "rate": found.rate,
        "rate_source": source,
        "time_column": name,
        "jitter": found.jitter,
        "gap_rows": gap_positions + 1,
        "gap_steps": steps[gap_positions],
        "gaps_ignored": bool(gap_positions.size),
    }
