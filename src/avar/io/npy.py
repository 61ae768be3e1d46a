"""NumPy files: ``.npy`` arrays and ``.npz`` archives.

``.npy``: memory-mapped (no copy is made until a column is used). A 1-D array is one
column ``x``; a 2-D array of shape (N, C) has columns ``x1 .. xC``; a structured array's
field names are its column names (so a field ``time`` is a time column).

``.npz`` (``numpy.savez``): equal-length 1-D arrays, one column each named by its key
(``savez(f, time=t, gx=gx, ...)``), and at most one other array read as a ``.npy`` array
is, whose C columns at most one array of strings names (``savez(f, time=t, data=a,
columns=names)``). Anything else is an error that lists what the archive holds.
"""

from __future__ import annotations

import math
import zipfile
from pathlib import Path

import numpy as np

from avar.io.streams import check_memory
from avar.io.timecols import time_columns


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
    return columns_of_array(array, path)


def columns_of_array(array: np.ndarray, path: Path, names: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """The columns of one array as :func:`read_npy` names them, or by ``names`` (one per column)."""
    if array.dtype.names:
        if names is not None:  # the fields name the columns: other names would be dropped unseen
            raise ValueError(f"{path}: the structured array names its own columns {list(array.dtype.names)[:8]}; "
                             f"drop the array of names {[str(name) for name in np.atleast_1d(names)][:8]}")
        if array.ndim != 1:
            raise ValueError(f"{path}: a structured .npy array must be 1-D, got shape {array.shape}")
        columns = {}
        for name in array.dtype.names:
            field = array[name]
            if field.ndim != 1:
                raise ValueError(f"{path}: field {name!r} has shape {field.shape[1:]} per row; give one number per field")
            columns[name] = field
    elif array.ndim in (1, 2) and names is not None:
        width = 1 if array.ndim == 1 else array.shape[1]
        labels = [str(name) for name in np.atleast_1d(names)]
        if len(labels) != width or len(set(labels)) != width:
            raise ValueError(f"{path}: {len(labels)} column name(s) {labels[:8]} for {width} column(s) of the "
                             f"{array.shape} array (one distinct name per column)")
        columns = {label: (array if array.ndim == 1 else array[:, i]) for i, label in enumerate(labels)}
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


def _declared_arrays(path: Path) -> dict[str, tuple[tuple[int, ...], np.dtype]]:
    """The shape and dtype every member of a ``.npz`` archive declares, read from the .npy headers
    alone (nothing is allocated); a member that is not a ``.npy`` array is an error naming it."""
    declared = {}
    with zipfile.ZipFile(path) as archive:
        for info in archive.infolist():
            if info.is_dir():
                continue
            if not info.filename.endswith(".npy"):
                raise ValueError(f"{path}: member {info.filename!r} of the .npz archive is not a .npy array; a .npz "
                                 "archive holds .npy arrays only (numpy.savez)")
            try:
                with archive.open(info) as member:
                    version = np.lib.format.read_magic(member)
                    read_header = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                                   else np.lib.format.read_array_header_2_0)
                    shape, _, dtype = read_header(member)
            except (OSError, ValueError, EOFError, zipfile.BadZipFile) as error:
                raise ValueError(f"{path}: member {info.filename!r} is not a readable .npy array "
                                 f"({str(error).splitlines()[0][:200]})") from None
            if dtype.hasobject:
                raise ValueError(f"{path}: member {info.filename!r} holds Python objects ({dtype}), not numbers")
            declared[info.filename[: -len(".npy")]] = (shape, dtype)
    return declared


def read_npz(path: Path) -> dict[str, np.ndarray]:
    """The columns of a ``.npz`` archive (see the module's notes), by name.

    The shapes the members declare are checked against the memory a reader may allocate
    (:func:`avar.io.streams.check_memory`) before any member is decompressed."""
    try:
        declared = _declared_arrays(path)
    except (OSError, EOFError, zipfile.BadZipFile) as error:
        raise ValueError(f"{path}: not a readable .npz archive ({error})") from None
    sizes = {key: math.prod(shape) * dtype.itemsize for key, (shape, dtype) in declared.items()}
    if sizes:
        largest = max(sizes, key=sizes.get)
        shape, dtype = declared[largest]
        check_memory(path, sum(sizes.values()), f"its arrays (the largest, {largest!r}, a {shape} {dtype} array)")
    try:
        with np.load(path, allow_pickle=False) as archive:
            arrays = {}
            for key in archive.files:
                try:
                    arrays[key] = archive[key]
                except (OSError, ValueError, EOFError, zipfile.BadZipFile) as error:
                    raise ValueError(f"{path}: member {key + '.npy'!r} is not a readable .npy array "
                                     f"({str(error).splitlines()[0][:200]})") from None
    except (OSError, EOFError, zipfile.BadZipFile) as error:
        raise ValueError(f"{path}: not a readable .npz archive ({error})") from None
    return columns_of_arrays(arrays, path, "a .npz archive")


def columns_of_arrays(arrays: dict[str, np.ndarray], path: Path, what: str) -> dict[str, np.ndarray]:
    """The columns of named arrays (an archive's, a MATLAB file's), by the rules of ``.npz``."""
    held = ", ".join(f"{key} {value.dtype}{list(value.shape)}" for key, value in arrays.items())
    if not arrays:
        raise ValueError(f"{path}: {what} that holds no array")
    text = {key: value for key, value in arrays.items() if value.dtype.kind in "US"}
    numbers = {key: value for key, value in arrays.items() if key not in text}
    tables = [key for key, value in numbers.items() if value.ndim != 1 or value.dtype.names]
    if len(numbers) == 1:  # one array, named by the one array of strings if there is one
        main = next(iter(numbers))
    elif len(tables) == 1:  # one table, and 1-D arrays beside it (a time, say)
        main = tables[0]
    else:  # 1-D arrays only: a column each
        main = None
    if text and main is not None and time_columns([main]) and numbers[main].ndim == 1:
        raise ValueError(f"{path}: {what} holds the time vector {main!r} and the text {next(iter(text))!r}, but no "
                         "data: text names the columns of a data matrix (time, data and names); give the data too")
    singles = {key: value for key, value in numbers.items() if key != main}
    rows = {value.shape[0] for value in singles.values() if value.ndim == 1}
    if main is not None and numbers[main].ndim >= 1:
        rows.add(numbers[main].shape[0])
    if len(text) > 1 or (text and main is None) or any(value.ndim != 1 for value in singles.values()) \
            or len(rows) > 1:
        raise ValueError(f"{path}: {what} must hold equal-length 1-D arrays (a column each, named by its "
                         f"key) and at most one other array (its columns named by at most one array of strings) "
                         f"of as many rows; it holds {held}")
    columns = {}
    if main is not None:
        columns.update(columns_of_array(numbers[main], path, names=next(iter(text.values()), None)))
    for key, value in singles.items():
        if key in columns:
            raise ValueError(f"{path}: the column name {key!r} is both a key and a name of {main!r}'s columns")
        columns.update(columns_of_array(value, path, names=np.array([key])))
    return columns
