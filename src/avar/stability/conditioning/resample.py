"""Gaps filled and records averaged (Stable32's Fill and Average), each saying what it changed.

* :func:`fill_gaps`: NaN values (gaps) filled by linear interpolation between the nearest
  finite neighbours (``"linear"``), or left as gaps for the statistics' ``nan_policy="omit"``
  (``"none"``); gaps at either end cannot be interpolated and are cut off.
* :func:`average`: the record at m times the sampling interval: frequency data by the mean of
  m consecutive values, phase data by keeping every m-th point (the phase at the end of each
  interval, which is what averaging the frequency over it means). A last incomplete group is
  dropped and counted.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from avar._validation import as_array, as_float64, check_numeric_dtype, short_repr

__all__ = ["Resampled", "average", "fill_gaps"]


@dataclass(frozen=True, eq=False)
class Resampled:
    """A record after :func:`fill_gaps` or :func:`average`, and what was changed.

    Attributes
    ----------
    data : ndarray
        The new record.
    changed : ndarray of int64
        Indices (in the data as given) of the values filled, or for :func:`average` the
        first index of every group averaged.
    dropped : int
        Values left out (gaps at the ends that could not be filled; an incomplete last group).
    note : str
        One line saying what was done.
    """

    data: np.ndarray
    changed: np.ndarray
    dropped: int
    note: str

    def __str__(self) -> str:
        return self.note


def _vector(data: Any) -> np.ndarray:
    array = as_array(data.to_numpy() if hasattr(data, "to_numpy") else data, "data")
    check_numeric_dtype(array, "data")
    if array.ndim != 1:
        raise ValueError(f"data must be 1-D, got an array of shape {array.shape}")
    values = np.array(as_float64(array), dtype=np.float64)
    if np.isinf(values).any():
        raise ValueError("data has infinite values; only NaN marks a gap")
    return values


def fill_gaps(data: Any, method: str = "linear") -> Resampled:
    """Fill the NaN gaps of a record (see the module).

    >>> import numpy as np
    >>> res = fill_gaps(np.array([np.nan, 1.0, np.nan, 3.0, np.nan, np.nan, 6.0, np.nan]))
    >>> res.data.tolist(), res.changed.tolist(), res.dropped
    ([1.0, 2.0, 3.0, 4.0, 5.0, 6.0], [2, 4, 5], 2)
    """
    if method not in ("linear", "none"):
        raise ValueError(f"method must be 'linear' or 'none', got {short_repr(method)}")
    values = _vector(data)
    finite = np.flatnonzero(~np.isnan(values))
    if finite.size == 0:
        raise ValueError("data holds no samples (every value is NaN)")
    if method == "none":
        gaps = np.flatnonzero(np.isnan(values))
        return Resampled(values, gaps, 0, f"fill: none; {gaps.size} gap value(s) left for nan_policy='omit'")
    first, last = int(finite[0]), int(finite[-1])
    inner = values[first:last + 1].copy()
    gaps = np.flatnonzero(np.isnan(inner))
    inner[gaps] = np.interp(gaps, np.flatnonzero(~np.isnan(inner)), inner[~np.isnan(inner)])
    dropped = first + (values.size - 1 - last)
    note = f"fill: {gaps.size} gap value(s) filled linearly" + (f"; {dropped} at the ends cut off" if dropped else "")
    return Resampled(inner, gaps + first, dropped, note)


def average(data: Any, factor: int, data_type: str = "freq") -> Resampled:
    """The record at ``factor`` times the sampling interval (Stable32's Average; see the module).

    >>> import numpy as np
    >>> res = average(np.arange(7.0), 3)                 # frequency: means of 3
    >>> res.data.tolist(), res.dropped
    ([1.0, 4.0], 1)
    >>> average(np.arange(7.0), 3, data_type="phase").data.tolist()   # phase: every 3rd point
    [0.0, 3.0, 6.0]
    """
    if isinstance(factor, bool) or not isinstance(factor, (int, np.integer)) or factor < 1:
        raise ValueError(f"factor must be a whole number >= 1, got {short_repr(factor)}")
    if data_type not in ("freq", "phase"):
        raise ValueError(f"data_type must be 'freq' or 'phase', got {short_repr(data_type)}")
    values = _vector(data)
    m = int(factor)
    if data_type == "phase":
        kept = values[::m]
        dropped = (values.size - 1) % m
        return Resampled(kept, np.arange(0, values.size, m), dropped,
                         f"average: every {m}th phase point kept ({kept.size} of {values.size})")
    groups = values.size // m
    if groups == 0:
        raise ValueError(f"data has {values.size} values, fewer than factor = {m}")
    means = values[: groups * m].reshape(groups, m).mean(axis=1)
    dropped = values.size - groups * m
    return Resampled(means, np.arange(groups) * m, dropped,
                     f"average: {groups} means of {m} frequency values" + (f"; last {dropped} dropped" if dropped else ""))
