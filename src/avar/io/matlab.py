"""MATLAB ``.mat`` files (formats v4 to v7), read by SciPy.

The variables follow the rules of ``.npz`` archives (:mod:`avar.io.npy`): equal-length
vectors, a column each named by its variable (``save log.mat time gx gy``), and at most
one matrix of as many rows, its columns named by at most one cell array of strings
(``save log.mat time data names``). MATLAB's vectors are N x 1 or 1 x N matrices: both
are vectors here. v7.3 files are HDF5, which SciPy does not read: the error says to save
with ``-v7``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from avar.io.npy import columns_of_arrays
from avar.io.streams import check_memory


def _variable(value: np.ndarray) -> np.ndarray:
    """A MATLAB vector as 1-D, a cell array of strings as strings; other arrays as they are."""
    if value.dtype == object:  # a cell array: of strings, the names of a matrix's columns
        cells = [np.asarray(cell).ravel() for cell in value.ravel()]
        if all(cell.dtype.kind in "US" and cell.size == 1 for cell in cells):
            return np.array([str(cell[0]) for cell in cells])
        return value
    if value.ndim == 2 and 1 in value.shape and value.dtype.kind not in "US":
        return value.ravel()
    return value


#: Bytes per element of MATLAB's classes (whosmat's names); cells and structs hold at least a pointer each.
ITEM_BYTES = {"double": 8, "single": 4, "int8": 1, "uint8": 1, "int16": 2, "uint16": 2, "int32": 4, "uint32": 4,
              "int64": 8, "uint64": 8, "logical": 1, "char": 4}


def _check_declared(path: Path, whosmat) -> None:
    """Refuse before loading: sparse matrices, and variables whose declared sizes exceed the memory a
    reader may allocate (a small compressed file can declare gigabytes)."""
    declared = whosmat(path)
    sparse = [name for name, _, kind in declared if kind == "sparse"]
    if sparse:
        raise ValueError(f"{path}: variable {sparse[0]!r} is a sparse matrix; save it full (full({sparse[0]})) to "
                         "read it here")
    sizes = {name: math.prod(shape) * ITEM_BYTES.get(kind, 8) for name, shape, kind in declared}
    if sizes:
        largest = max(sizes, key=sizes.get)
        shape, kind = next((shape, kind) for name, shape, kind in declared if name == largest)
        check_memory(path, sum(sizes.values()), f"its variables (the largest, {largest!r}, a {shape} {kind} matrix)")


def read_mat(path: Path) -> dict[str, np.ndarray]:
    """The columns of a MATLAB ``.mat`` file (see the module's notes), by name."""
    from scipy.io import loadmat, whosmat
    from scipy.io.matlab import MatReadError

    try:
        _check_declared(path, whosmat)
        variables = loadmat(path, squeeze_me=False, struct_as_record=True)
    except NotImplementedError:  # SciPy's answer to v7.3 (HDF5)
        raise ValueError(f"{path}: a MATLAB v7.3 (HDF5) file; save it with save(..., '-v7') to read it here") from None
    except (MatReadError, OSError, ValueError, TypeError) as error:
        if str(error).startswith(str(path)):
            raise
        raise ValueError(f"{path}: not a readable MATLAB file ({str(error)[:200]})") from None
    arrays = {key: _variable(value) for key, value in variables.items() if not key.startswith("__")}
    odd = [key for key, value in arrays.items() if value.dtype == object or value.dtype.names]
    if odd:
        raise ValueError(f"{path}: variable(s) {odd} are cell arrays or structs; give numeric vectors or "
                         "one matrix, and at most one cell array of strings naming its columns")
    return columns_of_arrays(arrays, path, "a MATLAB file")
