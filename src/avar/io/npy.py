"""NumPy ``.npy`` files: plain 1-D or 2-D arrays, or structured arrays with named fields.

The file is memory-mapped (no copy is made until a column is used). A 1-D array is one
column ``x``; a 2-D array of shape (N, C) has columns ``x1 .. xC``; a structured array's
field names are its column names (so a field ``time`` is a time column).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def read_npy(path: Path) -> dict[str, np.ndarray]:
    """The columns of a ``.npy`` file, by name, as read-only (memory-mapped) 1-D arrays."""
    try:
        array = np.load(path, mmap_mode="r", allow_pickle=False)
    except (OSError, ValueError) as error:
        raise ValueError(f"{path}: not a readable .npy array ({error})") from None
    expected = getattr(array, "offset", 0) + array.nbytes
    size = path.stat().st_size
    if size > expected:
        raise ValueError(f"{path}: {size - expected} byte(s) follow the {array.shape} array of the .npy file "
                         "(a damaged or concatenated file); save one array per file (numpy.save)")
    if array.dtype.names:
        if array.ndim != 1:
            raise ValueError(f"{path}: a structured .npy array must be 1-D, got shape {array.shape}")
        columns = {}
        for name in array.dtype.names:
            field = array[name]
            if field.ndim != 1:
                raise ValueError(f"{path}: field {name!r} has shape {field.shape[1:]} per row; give one number per field")
            columns[name] = field
    elif array.ndim == 1:
        columns = {"x": array}
    elif array.ndim == 2:
        columns = {f"x{i + 1}": array[:, i] for i in range(array.shape[1])}
    else:
        raise ValueError(f"{path}: a .npy file must hold a 1-D or 2-D array, got shape {array.shape}")
    for name, values in columns.items():
        if values.dtype.kind == "c":
            raise ValueError(f"{path}: column {name!r} is complex; the Allan variance needs real numbers")
        if values.dtype.kind not in "iufM":
            raise ValueError(f"{path}: column {name!r} has dtype {values.dtype}, not numbers")
    return columns
