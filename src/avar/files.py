"""Reading sensor series from files: CSV, whitespace-separated text, ``.npy``.

Used by the command line; every problem with a file raises
:class:`InputFileError` with a message that names the file and, where there
is one, the column and row.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from avar._validation import MIN_SAMPLES

#: Column names taken as the time axis (case-insensitive, units in brackets
#: ignored); names starting with "time" count too.
TIME_COLUMNS = ("t", "timestamp", "stamp", "seconds", "sec", "datetime", "date")

#: Seconds per unit of a numeric time column.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}

#: Largest relative deviation of a time step from the mean step: sensor logs
#: print their times with limited decimals, which alone jitters the steps.
TIME_STEP_TOLERANCE = 1e-3


def is_time_column(name: str) -> bool:
    """``time``, ``Time [s]``, ``timestamp (ns)``, ``t`` ... but not ``gyro_t``.

    >>> [is_time_column(n) for n in ("Time [s]", "timestamp", "t", "gx", "gyro_time")]
    [True, True, True, False, False]
    """
    bare = re.sub(r"[\[(].*?[\])]", "", name).strip().lower()
    return bare.startswith("time") or bare in TIME_COLUMNS


class InputFileError(ValueError):
    """A file cannot be read as numeric series (missing, malformed, bad values)."""


@dataclass(frozen=True)
class SeriesTable:
    """Numeric columns of a file and the sampling rate its time column gives."""

    columns: pd.DataFrame
    freq: float | None
    path: Path
    time_column: str | None = None


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _read_text(path: Path) -> tuple[pd.DataFrame, bool]:
    """CSV (comma, semicolon or tab) or whitespace-separated text; header optional.

    Returns the table (all cells as text) and whether it had a header row.
    """
    try:
        with path.open("r", encoding="utf-8", errors="replace") as handle:
            first = handle.readline()
            while first and (not first.strip() or first.lstrip().startswith("#")):
                first = handle.readline()
            second = handle.readline()
    except OSError as error:
        raise InputFileError(f"{path}: cannot read the file ({error.strerror or error})") from error
    if not first.strip():
        raise InputFileError(f"{path}: the file is empty")
    separator = next((sep for sep in (";", "\t", ",") if sep in first), r"\s+")
    decimal_comma = separator == ";" and re.search(r"\d,\d", second + first) is not None
    tokens = [token.strip().strip('"') for token in re.split(separator, first.strip())]
    has_header = not all(_is_number(token.replace(",", ".") if decimal_comma else token) for token in tokens if token)
    if has_header and len(set(tokens)) != len(tokens):
        raise InputFileError(f"{path}: duplicate column names {tokens}")
    try:
        frame = pd.read_csv(
            path,
            sep=separator,
            header=0 if has_header else None,
            engine="python" if separator == r"\s+" else "c",
            skip_blank_lines=False,  # a blank line is a missing value, not nothing
            comment="#",
            dtype=str,
            keep_default_na=False,
        )
    except (pd.errors.ParserError, UnicodeDecodeError, ValueError) as error:
        raise InputFileError(f"{path}: not a readable CSV/text table ({str(error).splitlines()[0]})") from error
    blank = frame.isna() | (frame == "")
    filled = np.flatnonzero(~blank.all(axis=1).to_numpy())
    frame = frame.iloc[: filled[-1] + 1 if filled.size else 0]  # trailing blank lines end the file
    if decimal_comma:
        frame = frame.apply(lambda column: column.str.replace(",", ".", regex=False))
    if not has_header:
        frame.columns = [f"x{i + 1}" for i in range(frame.shape[1])] if frame.shape[1] > 1 else ["x"]
    frame.columns = [str(name).strip() for name in frame.columns]
    return frame, has_header


def _read_npy(path: Path) -> pd.DataFrame:
    try:
        array = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as error:
        raise InputFileError(f"{path}: not a readable .npy array ({error})") from error
    if array.ndim == 1:
        return pd.DataFrame({"x": array})
    if array.ndim == 2:
        return pd.DataFrame(array, columns=[f"x{i + 1}" for i in range(array.shape[1])])
    raise InputFileError(f"{path}: a .npy file must hold a 1-D or 2-D array, got shape {array.shape}")


def _numeric(frame: pd.DataFrame, name: str, path: Path, first_line: int) -> np.ndarray:
    """One column as float64, naming the first row that is not a number."""
    raw = frame[name]
    if raw.dtype.kind in "biuf":
        values = raw.to_numpy(dtype=np.float64)
    else:
        text = raw.astype(str).str.strip()
        values = pd.to_numeric(text.str.replace(r"(?i)^(nan|na|)$", "nan", regex=True), errors="coerce").to_numpy(
            dtype=np.float64
        )
        bad = np.isnan(values) & ~text.str.fullmatch(r"(?i)nan|na|").to_numpy()
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            raise InputFileError(
                f"{path}: column {name!r} is not numeric: row {row + 1} (line {row + first_line}) holds {text.iloc[row]!r}"
            )
    missing = ~np.isfinite(values)
    if missing.any():
        row = int(np.flatnonzero(missing)[0])
        raise InputFileError(
            f"{path}: column {name!r} has {int(missing.sum())} NaN/missing or infinite value(s); "
            f"the first is in row {row + 1} (line {row + first_line})"
        )
    return values


def _rate_from_time(frame: pd.DataFrame, name: str, path: Path, first_line: int, unit: str) -> float:
    """Sampling rate (Hz) of a regular time column: numbers in ``unit`` or ISO 8601 date-times."""
    raw = frame[name]
    text = raw.astype(str).str.strip()
    ticks = None
    if text.str.fullmatch(r"-?\d{1,19}").all():
        try:  # integer stamps (e.g. epoch nanoseconds) are exact in int64, not in float64
            ticks = np.array([int(token) for token in text], dtype=np.int64)
        except OverflowError:
            ticks = None
    if ticks is not None:
        seconds = (ticks - ticks[0]).astype(np.float64) * TIME_UNITS[unit]
    elif all(_is_number(token) for token in text.iloc[:5]):
        numbers = _numeric(frame, name, path, first_line)
        seconds = (numbers - numbers[0]) * TIME_UNITS[unit]
    else:
        try:
            stamps = pd.to_datetime(text, format="ISO8601")
        except (ValueError, TypeError) as error:
            raise InputFileError(
                f"{path}: time column {name!r} holds neither numbers nor ISO 8601 date-times "
                f"(e.g. 2024-01-31T12:00:00.010); first value {text.iloc[0]!r}"
            ) from error
        seconds = (stamps - stamps.iloc[0]).dt.total_seconds().to_numpy()
    steps = np.diff(seconds)
    if steps.size == 0 or np.any(steps <= 0):
        raise InputFileError(f"{path}: time column {name!r} must increase strictly")
    step = float(seconds[-1] - seconds[0]) / steps.size  # more accurate than any single step
    if np.max(np.abs(steps - step)) > TIME_STEP_TOLERANCE * step:
        raise InputFileError(
            f"{path}: time column {name!r} is irregular (steps from {steps.min():g} to {steps.max():g} s); "
            "resample it, or pass --freq to treat the samples as regular"
        )
    return 1.0 / step


def read_series(
    path: str | Path, columns: list[str] | None = None, rate_from_time: bool = True, time_unit: str = "s"
) -> SeriesTable:
    """Read numeric columns (and the rate of a time column) from a file.

    Parameters
    ----------
    path : str or Path
        ``.npy`` (1-D or 2-D array), or a text table: CSV (comma, semicolon or
        tab separated) or whitespace-separated, with or without a header row.
        Columns without a header are named ``x`` (one column) or ``x1, x2, ...``.
    columns : list of str, optional
        Columns to keep (default: every column but the time column).
    rate_from_time : bool
        Whether the time column (named like ``time``, ``Time [s]``,
        ``timestamp``; see :func:`is_time_column`) gives the rate. It is never
        data either way.
    time_unit : {"s", "ms", "us", "ns"}
        Unit of a numeric time column.

    Returns
    -------
    SeriesTable
        ``columns`` as float64 DataFrame, ``freq`` from the time column or
        None, and ``time_column`` (its name, or None).

    Examples
    --------
    >>> import tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "gyro.csv")
    >>> _ = open(path, "w").write("time,gx\\n0.00,1\\n0.01,2\\n0.02,4\\n0.03,3\\n")
    >>> table = read_series(path)
    >>> list(table.columns), round(table.freq, 6)
    (['gx'], 100.0)
    """
    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"{path}: no such file")
    if path.suffix.lower() == ".npy":
        frame, first_line = _read_npy(path), 1
    else:
        frame, has_header = _read_text(path)
        first_line = 2 if has_header else 1  # file line of the first data row
    time_name = next((name for name in frame.columns if is_time_column(name)), None)
    if columns:
        unknown = [name for name in columns if name not in frame.columns]
        if unknown:
            raise InputFileError(f"{path}: unknown column(s) {unknown}; the file has {list(frame.columns)}")
        wanted = list(columns)
    else:
        wanted = [name for name in frame.columns if name != time_name]
    if not wanted:
        raise InputFileError(f"{path}: no data column besides the time column {time_name!r}")
    if len(frame) < MIN_SAMPLES:
        raise InputFileError(f"{path}: {len(frame)} sample(s); the Allan variance needs at least {MIN_SAMPLES}")
    data = pd.DataFrame({name: _numeric(frame, name, path, first_line) for name in wanted})
    freq = None
    if time_name is not None and rate_from_time:
        freq = _rate_from_time(frame, time_name, path, first_line, time_unit)
    return SeriesTable(columns=data, freq=freq, path=path, time_column=time_name)
