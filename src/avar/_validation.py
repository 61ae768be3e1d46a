"""Input checks shared by the public functions.

Every public function validates its input once, here, and raises
``TypeError`` (wrong kind of object) or ``ValueError`` (right kind, bad
value) with a message that says what was wrong and what is accepted.
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np
import pandas as pd

MIN_SAMPLES = 4

#: Integers beyond this magnitude are not all exact in float64.
EXACT_INTEGER_LIMIT = 2**53


def integer_range(array: np.ndarray) -> tuple[int, int] | None:
    """(min, max) of an integer array as Python ints, or None for other dtypes."""
    if array.dtype.kind not in "iu" or array.size == 0:
        return None
    return int(array.min()), int(array.max())


def as_float64(array: np.ndarray) -> np.ndarray:
    """Contiguous float64 values of a real 1-D array.

    Integers beyond 2**53 are first shifted by an exact integer offset (the
    midrange): the Allan variance does not depend on a shift, and the shifted
    values convert exactly as long as the data span less than 2**53.
    """
    bounds = integer_range(array)
    if bounds is None or max(abs(bounds[0]), abs(bounds[1])) <= EXACT_INTEGER_LIMIT:
        return np.ascontiguousarray(array, dtype=np.float64)
    offset = (bounds[0] + bounds[1]) // 2
    if array.dtype.kind == "i":
        return (array - np.int64(offset)).astype(np.float64)
    above = array >= np.uint64(offset)
    return np.where(above, (array - np.uint64(offset)).astype(np.float64), -(np.uint64(offset) - array).astype(np.float64))


def check_freq(freq: Any, name: str = "freq") -> float:
    """A finite, positive sampling frequency as float."""
    if isinstance(freq, (bool, np.bool_)) or not isinstance(freq, numbers.Real):
        raise TypeError(f"{name} must be a positive real number (Hz), got {type(freq).__name__}")
    value = float(freq)
    if not np.isfinite(value) or value <= 0:
        raise ValueError(f"{name} must be a finite number > 0 (Hz), got {freq!r}")
    return value


def check_numeric_dtype(array: np.ndarray, what: str) -> None:
    """Reject non-numeric and complex data."""
    kind = array.dtype.kind
    if kind == "c":
        raise TypeError(f"{what} is complex; the Allan variance needs real-valued data")
    if kind not in "biuf":
        raise TypeError(
            f"{what} must be numeric (int or float), got dtype {array.dtype}; "
            "convert it with numpy.asarray(x, dtype=float) if it holds numbers"
        )


def check_finite(values: np.ndarray, what: str) -> None:
    """Reject NaN and infinite values, saying how many and where the first is."""
    bad = ~np.isfinite(values)
    if bad.any():
        where = np.flatnonzero(bad)
        n_nan = int(np.isnan(values[where]).sum())
        raise ValueError(
            f"{what} has {where.size} non-finite value(s) ({n_nan} NaN, {where.size - n_nan} inf); "
            f"the first is at index {where[0]}. Remove or fill them before computing the Allan variance."
        )


def check_length(n: int, what: str) -> None:
    if n < MIN_SAMPLES:
        raise ValueError(f"{what} has {n} sample(s); the Allan variance needs at least {MIN_SAMPLES}")


def rate_from_index(index: pd.Index, what: str) -> float | None:
    """Sampling rate (Hz) of a regular DatetimeIndex or TimedeltaIndex.

    Returns None for other indexes; raises ValueError for an irregular one.
    """
    if not isinstance(index, (pd.DatetimeIndex, pd.TimedeltaIndex)) or len(index) < 2:
        return None
    steps = np.diff(index.to_numpy()).astype("timedelta64[ns]").astype(np.int64)
    step_ns = steps[0]
    if np.any(steps <= 0):
        raise ValueError(f"{what} has a time index that does not increase strictly; sort it or drop duplicate times")
    if np.any(steps != step_ns):
        raise ValueError(
            f"{what} has an irregular time index (steps from {steps.min()} to {steps.max()} ns); "
            "resample it to a regular grid or pass freq explicitly with positional data"
        )
    return 1e9 / float(step_ns)


def as_series(x: Any, freq: Any) -> tuple[np.ndarray, float]:
    """Validate a 1-D series and its rate; return float64 values and freq.

    ``freq=None`` means the rate of a pandas time index when there is one,
    otherwise 1 Hz.
    """
    what = "x"
    index_rate = None
    if isinstance(x, pd.DataFrame):
        raise TypeError("x is a DataFrame; give a 1-D series or an avar.IMU (see avar.IMU.from_dataframe)")
    if isinstance(x, pd.Series):
        index_rate = rate_from_index(x.index, what) if freq is None else None
        x = x.to_numpy()
    if isinstance(x, (str, bytes)):
        raise TypeError("x must be a numeric 1-D series, got a string")
    array = np.asarray(x)
    check_numeric_dtype(array, what)
    if array.ndim != 1:
        raise ValueError(
            f"x must be 1-D, got an array of shape {array.shape}; give a 1-D series or an avar.IMU"
        )
    check_length(array.shape[0], what)
    values = as_float64(array)
    check_finite(values, what)
    if freq is None:
        rate = index_rate if index_rate is not None else 1.0
    else:
        rate = check_freq(freq)
    return values, rate


def check_whole_numbers(values: Any, name: str) -> np.ndarray:
    """An int64 array of whole numbers (1.0 accepted, 1.5 rejected)."""
    array = np.atleast_1d(np.asarray(values))
    if array.dtype.kind == "b" or array.dtype.kind not in "iuf":
        raise TypeError(f"{name} must hold whole numbers, got {array.dtype}")
    if array.dtype.kind == "f":
        if not np.all(np.isfinite(array)) or np.any(array != np.round(array)):
            raise ValueError(f"{name} must hold whole numbers, got {values!r}")
        if np.any(np.abs(array) >= 2.0**62):
            raise ValueError(f"{name} holds numbers too large to be scales or sizes: {values!r}")
    return array.astype(np.int64)
