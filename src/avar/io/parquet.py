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

from avar.io.streams import check_memory, format_bytes

#: The first and last bytes of every Parquet file.
MAGIC = b"PAR1"


def is_parquet(path: Path) -> bool:
    """Whether ``path`` starts with Parquet's magic bytes (whatever its name)."""
    with path.open("rb") as handle:
        return handle.read(4) == MAGIC


def _check_declared(path: Path) -> None:
    """The sizes the file's metadata declare (uncompressed row groups; 8 bytes per value once read)
    against the memory a reader may allocate, before anything is decompressed."""
    import pyarrow
    import pyarrow.parquet as pq

    try:
        meta = pq.read_metadata(path)
    except (OSError, ValueError, pyarrow.ArrowException) as error:
        raise ValueError(f"{path}: not a readable Parquet file ({str(error).splitlines()[0][:200]})") from None
    declared = sum(meta.row_group(i).total_byte_size for i in range(meta.num_row_groups))
    values = 8 * meta.num_rows * meta.num_columns
    check_memory(path, declared + values, f"{meta.num_rows:,} rows x {meta.num_columns:,} column(s) "
                                          f"({format_bytes(declared)} uncompressed)")


def read_parquet(path: Path) -> dict[str, np.ndarray]:
    """The columns of a Parquet file, by name, as 1-D arrays (numbers, or datetime64 for times)."""
    if importlib.util.find_spec("pyarrow") is None:
        raise ValueError(f"{path}: reading Parquet needs pyarrow; pip install \"allanvar[parquet]\" (or pyarrow)")
    _check_declared(path)
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
