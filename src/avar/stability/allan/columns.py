"""The Allan variance of every column of a table: the kernel call and its overflow check.

A single series is a table of one column; an IMU is a table of its channels.
Both reach :func:`allan_variance_columns`, the one estimation path.
"""

from __future__ import annotations

import numpy as np

from avar import _kernels
from avar._validation import check_finite


def allan_variance_columns(data: np.ndarray, factors: np.ndarray, type: str) -> np.ndarray:
    """Allan variance of every column of ``data`` at cluster sizes ``factors``.

    ``data`` is a real array of shape (N, C) (float64, float32, any integer
    dtype, possibly memory-mapped; a non-finite value is reported by
    :func:`avar._validation.check_finite`); returns float64 of shape (C, L).
    The kernels (:func:`avar._kernels.streaming_allan_variance`) read it in
    place, in blocks: short series take a one-call path, octave "to" grids
    the Haar pyramid, octave "mo" grids a cache-blocked sweep, other grids a
    level-by-level pass. They agree with exact arithmetic to ~1e-13 relative
    (exact centring, power-of-two scaling of extreme magnitudes, compensated
    double-double sums); a column's result does not depend on the other
    columns nor on the number of threads.
    """
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
