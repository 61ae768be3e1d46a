"""The plain-array entry point of the streaming kernels: :func:`allan_variance_columns`."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from avar._kernels.levels import level_sums, level_sums_serial
from avar._kernels.streaming import BLOCK, CHUNK_BLOCKS, LIMIT_EXP, NEAR, block_table, block_table_serial

#: Inputs with at most this many values (N * C) run on one thread: starting
#: the thread pool costs more than the work.
SERIAL_MAX = 1 << 17


@njit(cache=True)
def _scales(maxabs):
    """Power-of-two scale per column bringing extreme magnitudes near 1 (1.0 otherwise)."""
    scale = np.ones(maxabs.shape[0])
    redo = False
    for c in range(maxabs.shape[0]):
        v = maxabs[c]
        if np.isfinite(v) and v > 0.0 and (v > 2.0**LIMIT_EXP or v < 2.0**-LIMIT_EXP):
            _, e = math.frexp(v)
            e = min(max(e, -1000), 1000)  # 2**-e stays a normal float64
            scale[c] = math.ldexp(1.0, -e)
            redo = True
    return scale, redo


@njit(cache=True)
def _finish(sums, scale, factors, n_diff):
    out = np.empty_like(sums)
    for c in range(sums.shape[0]):
        unscale = 1.0 / scale[c]
        for k in range(sums.shape[1]):
            m = np.float64(factors[k])
            out[c, k] = sums[c, k] / (2.0 * m * m * n_diff[k]) * unscale * unscale
    return out


def _run_serial(data, factors, counts, n_diff, is_mo, small_count):
    integral = data.dtype.kind in "iu"
    ones = np.ones(data.shape[1])
    # (Python glue on purpose: compiled as one numba function, the level loops
    # ran ~20x slower; the three dispatches cost a few microseconds.)
    th, tl, centre, maxabs = block_table_serial(data, ones, integral, BLOCK)
    scale, redo = _scales(maxabs)
    if redo:
        th, tl, centre, maxabs = block_table_serial(data, scale, integral, BLOCK)
    sums = level_sums_serial(data, centre, scale, th, tl, factors, counts, is_mo, small_count, BLOCK, NEAR,
                             CHUNK_BLOCKS)
    return _finish(sums, scale, factors, n_diff)


def _run_parallel(data, factors, counts, n_diff, is_mo, small_count):
    integral = data.dtype.kind in "iu"
    ones = np.ones(data.shape[1])
    th, tl, centre, maxabs = block_table(data, ones, integral, BLOCK)
    scale, redo = _scales(maxabs)
    if redo:
        th, tl, centre, maxabs = block_table(data, scale, integral, BLOCK)
    sums = level_sums(data, centre, scale, th, tl, factors, counts, is_mo, small_count, BLOCK, NEAR, CHUNK_BLOCKS)
    return _finish(sums, scale, factors, n_diff)


def _as_kernel_input(data) -> np.ndarray:
    x = np.asarray(data)  # an np.memmap becomes a plain view, never a copy
    if x.ndim == 1:
        x = x[:, None]
    kind = x.dtype.kind
    if kind == "b":
        return x.view(np.uint8)
    if kind not in "iuf" or not x.dtype.isnative or x.dtype.itemsize > 8:
        return x.astype(np.float64)
    if x.dtype == np.float16:
        return x.astype(np.float32)  # exact; numba has no float16 arithmetic
    return x


def allan_variance_columns(data, factors, type: str) -> np.ndarray:
    """Allan variance of every column of ``data`` (N, C) at the cluster sizes ``factors``.

    ``data``: any real array (float64, float32, any integer dtype, any memory
    layout, a slice or an ``np.memmap``); it is read in blocks, never copied
    to float64. ``factors``: int64 cluster sizes in any order. ``type``: "mo"
    or "to". Returns float64 of shape (C, L); nan where a factor has no
    difference (m < 1 or m > N / 2), +inf or nan on overflow or non-finite
    data (no exception: the caller decides).
    """
    x = _as_kernel_input(data)
    f = np.asarray(factors, dtype=np.int64).reshape(-1)
    n, channels = x.shape
    is_mo = type == "mo"
    n_diff = n - 2 * f + 1 if is_mo else n // np.maximum(f, 1) - 1
    out = np.full((channels, f.shape[0]), np.nan)
    valid = (f >= 1) & (n_diff > 0)
    if not valid.any() or channels == 0:
        return out
    order = np.argsort(np.where(valid, f, -1), kind="stable")[np.count_nonzero(~valid):]
    fs = f[order]
    counts = n_diff[order] if is_mo else n // fs
    small_count = int(np.searchsorted(fs, NEAR, side="right")) if is_mo else fs.shape[0]
    run = _run_serial if n * channels <= SERIAL_MAX else _run_parallel
    out[:, order] = run(x, fs, counts, n_diff[order].astype(np.float64), is_mo, small_count)
    return out
