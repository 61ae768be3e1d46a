"""Apache Parquet tables (``.parquet``), read by pandas with pyarrow.

Every column becomes a column of the log, by name: numbers are data (or a time column,
by its name, as in text tables); datetime columns are time columns. pyarrow is an
optional dependency (``pip install "allanvar[parquet]"``); without it the error says so.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pandas as pd

#: The first and last bytes of every Parquet file.
MAGIC = b"PAR1"


def is_parquet(path: Path) -> bool:
    """Whether ``path`` starts with Parquet's magic bytes (whatever its name)."""
    with path.open("rb") as handle:
        return handle.read(4) == MAGIC


def read_parquet(path: Path) -> dict[str, np.ndarray]:
    """The columns of a Parquet file, by name, as 1-D arrays (numbers, or datetime64 for times)."""
    if importlib.util.find_spec("pyarrow") is None:
        raise ValueError(f"{path}: reading Parquet needs pyarrow; pip install \"allanvar[parquet]\" (or pyarrow)")
    try:
        frame = pd.read_parquet(path, engine="pyarrow")
    except (OSError, ValueError) as error:
        raise ValueError(f"{path}: not a readable Parquet file ({str(error).splitlines()[0][:200]})") from None
    columns = {}
    for name in frame.columns:
        values = frame[name]
        if isinstance(values.dtype, pd.DatetimeTZDtype):
            values = values.dt.tz_convert("UTC").dt.tz_localize(None)
        array = values.to_numpy()
        if array.dtype.kind not in "iufM":
            raise ValueError(f"{path}: column {str(name)!r} has dtype {values.dtype}, not numbers or times")
        if array.dtype.kind == "M" and values.isna().any():
            raise ValueError(f"{path}: time column {str(name)!r} has {int(values.isna().sum())} missing time(s)")
        columns[str(name)] = array
    if not columns:
        raise ValueError(f"{path}: the Parquet file holds no column")
    return columns
