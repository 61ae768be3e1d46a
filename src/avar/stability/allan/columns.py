"""The Allan variance of every column of a table: the kernel call and its overflow check.

A single series is a table of one column; an IMU is a table of its channels.
Both reach :func:`allan_variance_columns`, the one estimation path.
"""

from __future__ import annotations

import numpy as np

from avar import _kernels
from avar._kernels.allan.columns import SMALL_MAX, column_kernels
from avar._kernels.runtime.paths import numpy_path
from avar._validation import check_finite
from avar.stability.classic.small import level_sums

#: Series of at most NUMPY_SAMPLES samples whose levels hold at most NUMPY_DIFFERENCES differences
#: in all (per column) take the NumPy path while the kernels are cold (:func:`numpy_columns`):
#: 0.03 s for the octave levels of 2**18 samples, against seconds of compilation.
NUMPY_SAMPLES = 1 << 18
NUMPY_DIFFERENCES = 1 << 25
#: Magnitudes outside [2**-LIMIT_EXP, 2**LIMIT_EXP] are scaled by a power of two (as the kernels do).
LIMIT_EXP = 400


def _exact_float64(x: np.ndarray) -> np.ndarray | None:
    """``x`` (N, C) as float64 when every value converts exactly (floats, booleans, integers up
    to 2**53 in magnitude); None otherwise (the kernels split 64-bit integers exactly)."""
    if x.dtype.kind == "b" or (x.dtype.kind in "iu" and x.dtype.itemsize < 8) or \
            (x.dtype.kind == "f" and x.dtype.itemsize <= 8):
        return x.astype(np.float64, copy=False)
    if x.dtype.kind in "iu" and x.size and max(abs(int(x.min())), abs(int(x.max()))) <= 2**53:
        return x.astype(np.float64)
    return None


def _octave(factors: np.ndarray) -> bool:
    f = np.asarray(factors, dtype=np.int64)
    return bool(np.all((f & (f - 1)) == 0))


def _differences(n: int, factors: np.ndarray, is_mo: bool) -> int:
    """The differences of every valid level, and one per sample (the NumPy path's work)."""
    f = np.asarray(factors, dtype=np.int64).reshape(-1)
    counts = n - 2 * f + 1 if is_mo else n // np.maximum(f, 1) - 1
    return int(counts[(f >= 1) & (counts > 0)].sum()) + n


def numpy_columns(data: np.ndarray, factors: np.ndarray, type: str) -> np.ndarray | None:
    """:func:`allan_variance_columns` by NumPy (:mod:`avar.stability.classic.small`: the Allan
    variance of a series is OADEV**2 ("mo") or ADEV**2 ("to") of it as frequency data): for
    series of at most :data:`NUMPY_SAMPLES` samples whose levels hold at most
    :data:`NUMPY_DIFFERENCES` differences while the kernels
    they would take are not compiled yet (:func:`avar._kernels.runtime.paths.numpy_path`),
    finite, every column certified; None otherwise (the kernels then run).

    >>> from avar._kernels.runtime.paths import forced
    >>> with forced("numpy"):  # whether the kernels are compiled or not
    ...     numpy_columns(np.array([[1.0], [3.0], [2.0], [4.0], [3.0]]), np.array([1, 2]), "mo").tolist()
    [[1.25, 0.5]]
    """
    x = np.asarray(data)
    if x.ndim == 1:
        x = x[:, None]
    elif x.ndim != 2:
        return None
    n, channels = x.shape
    is_mo = type == "mo"
    flags = x.flags  # what the kernels' route and argument types depend on
    route = ("allan", x.dtype.str, flags.c_contiguous, flags.f_contiguous, flags.aligned, type, n <= SMALL_MAX,
             is_mo or n <= SMALL_MAX or _octave(factors))
    if not numpy_path(lambda: _differences(n, factors, is_mo), NUMPY_DIFFERENCES,
                      lambda: column_kernels(x, factors, type), fits=n <= NUMPY_SAMPLES, route=route):
        return None
    f = np.asarray(factors, dtype=np.int64).reshape(-1)
    counts = n - 2 * f + 1 if is_mo else n // np.maximum(f, 1) - 1
    valid = (f >= 1) & (counts > 0)
    values = _exact_float64(x)
    if values is None:
        return None
    out = np.full((channels, f.shape[0]), np.nan)
    strides = np.ones_like(f[valid]) if is_mo else f[valid]
    m = f[valid].astype(np.float64)
    for j in range(channels):
        column = np.ascontiguousarray(values[:, j])
        big = float(np.max(np.abs(column))) if n else 0.0
        if not np.isfinite(big):
            return None
        scale = 1.0
        if big > 2.0**LIMIT_EXP or 0.0 < big < 2.0**-LIMIT_EXP:
            scale = float(np.ldexp(1.0, -int(np.clip(np.frexp(big)[1], -1000, 1000))))
            column = column * scale
        centre = float(np.sum(column)) / n
        if x.dtype.kind in "iub":
            centre = float(np.floor(centre + 0.5))
        levels = level_sums(column, 0, centre, 0.0, 1.0, 0, f[valid], strides, counts[valid])
        if levels is None:
            return None
        with np.errstate(over="ignore"):  # an overflow is reported by the caller
            out[j, valid] = levels.sums / (2.0 * m * m * counts[valid]) / scale / scale
    return out


def allan_variance_columns(data: np.ndarray, factors: np.ndarray, type: str) -> np.ndarray:
    """Allan variance of every column of ``data`` at cluster sizes ``factors``.

    ``data`` is a real array of shape (N, C) (float64, float32, any integer
    dtype, possibly memory-mapped; a non-finite value is reported by
    :func:`avar._validation.check_finite`); returns float64 of shape (C, L).
    Short series take the NumPy path (:func:`numpy_columns`, nothing to compile); the
    kernels (:func:`avar._kernels.streaming_allan_variance`) read the others in
    place, in blocks: short series take a one-call path, octave "to" grids
    the Haar pyramid, octave "mo" grids a cache-blocked sweep, other grids a
    level-by-level pass. They agree with exact arithmetic to ~1e-13 relative
    (exact centring, power-of-two scaling of extreme magnitudes, compensated
    double-double sums); a column's result does not depend on the other
    columns nor on the number of threads.
    """
    allan = numpy_columns(data, factors, type)
    if allan is None:
        allan = _kernels.streaming_allan_variance(data, factors, type)
    if not np.isfinite(allan).all():
        # a non-finite value makes the kernels' sums non-finite: long series are checked here, by that pass
        for j in range(data.shape[1]):
            check_finite(data[:, j], "x" if data.shape[1] == 1 else f"column {j}")
        raise ValueError("the Allan variance overflows float64; rescale the data, e.g. to other units")
    if (allan < np.finfo(np.float64).tiny).any():  # 0 or subnormal: a constant column, or squares that underflow
        for j in range(data.shape[1]):
            column = data[:, j]
            low, high = float(column.min()), float(column.max())
            if high > low and (allan[j] < np.finfo(np.float64).tiny).any() and max(abs(low), abs(high)) < 2.0 ** -400:
                raise ValueError(f"the Allan variance of data of magnitude {max(abs(low), abs(high)):.3g} is below "
                                 "the float64 range (its squares underflow); rescale the data, e.g. to other units")
    return allan
