"""The Allan variance of every column of a table: workspace and kernel calls.

A single series is a table of one column; an IMU is a table of its channels.
Both reach :func:`allan_variance_columns`, the one estimation path.
"""

from __future__ import annotations

import threading

import numpy as np

from avar import _kernels
from avar.stability.grids import n_differences

#: Bytes of cumulative sums (12 per sample and channel) held at once: wide
#: inputs are processed in batches of channels that reuse one workspace, so
#: memory stays bounded and fresh pages are faulted in only once.
CUMSUM_BUDGET = 1 << 28


class _Workspace:
    """The cumulative-sum buffers, kept between calls while they fit the budget.

    Faulting in fresh pages costs about as much as the cumulative sum itself,
    so repeated calls (bootstrap replicates, channel batches, notebooks) reuse
    one pair of buffers of at most ``CUMSUM_BUDGET`` bytes. A call that finds
    them in use by another thread, or needs more, allocates its own.
    """

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.hi = np.empty(0, dtype=np.float64)
        self.lo = np.empty(0, dtype=np.float32)

    def arrays(self, rows: int, columns: int, reuse: bool) -> tuple[np.ndarray, np.ndarray]:
        size = rows * columns
        if reuse and 12 * size <= CUMSUM_BUDGET:
            if self.hi.size < size:
                self.hi = np.empty(size, dtype=np.float64)
                self.lo = np.empty(size, dtype=np.float32)
            return self.hi[:size].reshape(rows, columns), self.lo[:size].reshape(rows, columns)
        return np.empty((rows, columns), dtype=np.float64), np.empty((rows, columns), dtype=np.float32)


_WORKSPACE = _Workspace()


#: Tables with more values than this stream through the block kernels
#: (:func:`avar._kernels.streaming_allan_variance`) instead of holding the
#: 12-byte-per-value compensated cumulative sums of the whole table.
STREAMING_MIN_VALUES = CUMSUM_BUDGET // 12


def uses_streaming(data: np.ndarray) -> bool:
    """Whether a table goes through the streaming kernels.

    They read the input in place, in blocks, with a workspace of about a
    megabyte: memory-mapped files, tables too large for the cumulative-sum
    budget, and every non-float64 dtype (float32 is never copied whole to
    float64, and integers, even spanning the whole int64 range, are centred
    on an integer and summed exactly). In-memory float64 tables that fit the
    budget take the fused cumulative-sum kernels, the faster of the two there.
    """
    return isinstance(data, np.memmap) or data.dtype != np.float64 or data.size > STREAMING_MIN_VALUES


def allan_variance_columns(data: np.ndarray, factors: np.ndarray, type: str) -> np.ndarray:
    """Allan variance of every column of ``data`` at cluster sizes ``factors``.

    ``data`` is a finite real array of shape (N, C) (float64, float32, any
    integer dtype, possibly memory-mapped); returns float64 of shape (C, L).
    See :func:`uses_streaming` for which kernels run; both agree with exact
    arithmetic to ~1e-13 relative.
    The series are centred on their means and scaled by a power of two before
    the compensated cumulative sums (see :mod:`avar._kernels`), so the result
    is as exact as the float64 input allows. Columns are processed in batches
    that fit ``CUMSUM_BUDGET``; each column's result does not depend on the
    batching.
    """
    factors = np.asarray(factors, dtype=np.int64)
    if uses_streaming(data):
        with np.errstate(over="ignore", invalid="ignore"):
            allan = _kernels.streaming_allan_variance(data, factors, type)
        if not np.all(np.isfinite(allan)):
            raise ValueError("the Allan variance overflows float64; rescale the data, e.g. to other units")
        return allan
    n, channels = data.shape
    centre, low, high = _kernels.column_moments(data)
    with np.errstate(over="ignore"):
        span = np.maximum(high - centre, centre - low)  # inf only for |x| near the float64 limit
    _, exponent = np.frexp(np.where((span > 0) & np.isfinite(span), span, 1.0))
    exponent = np.clip(exponent, -1000, 1000)  # 2**-exponent stays a normal float64
    scale = np.ldexp(1.0, -exponent)
    strides = factors if type == "to" else np.ones_like(factors)
    counts = n_differences(n, factors, type)
    batch = max(1, min(channels, CUMSUM_BUDGET // (12 * (n + 1))))
    sums = np.empty((channels, factors.shape[0]))
    owned = _WORKSPACE.lock.acquire(blocking=False)
    try:
        hi, lo = _WORKSPACE.arrays(batch, n + 1, reuse=owned)
        for first in range(0, channels, batch):
            last = min(channels, first + batch)
            k = last - first
            _kernels.centred_cumsum(data[:, first:last], centre[first:last], scale[first:last], hi[:k], lo[:k])
            sums[first:last] = _kernels.squared_difference_sums(hi[:k], lo[:k], factors, strides, counts)
    finally:
        if owned:
            _WORKSPACE.lock.release()
    unscale = np.ldexp(1.0, exponent)[:, None]
    with np.errstate(over="ignore"):
        allan = sums / (2.0 * factors.astype(np.float64) ** 2 * counts) * unscale * unscale
    if not np.all(np.isfinite(allan)):
        raise ValueError(
            "the Allan variance overflows float64 (the data reach "
            f"{np.max(np.maximum(np.abs(low), np.abs(high))):.3g}); rescale the data, e.g. to other units"
        )
    return allan
