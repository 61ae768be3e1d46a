"""The plain-array entry point of the streaming kernels: :func:`allan_variance_columns`."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from avar._kernels.allan.blocks import (
    BLOCK,
    CERTIFY_TOL,
    CHUNK_BLOCKS,
    LIMIT_EXP,
    NEAR,
    block_table,
    read_only,
    table_task,
)
from avar._kernels.allan.far import FAR_SPAN, SWEEP_FINE, far_sums, far_task
from avar._kernels.allan.haar import CHUNK_BLOCKS as HAAR_CHUNK
from avar._kernels.allan.haar import HAAR_KERNEL, PYRAMID_EXP, haar_sums
from avar._kernels.allan.levels import level_sums, to_task
from avar._kernels.allan.pyramid import PYRAMID_BLOCK, PYRAMID_CHUNK, PYRAMID_NEAR, pyramid_sums, pyramid_task
from avar._kernels.allan.small import PARALLEL_KERNEL, small_allan_variance, small_allan_variance_parallel
from avar._kernels.allan.sweep import SWEEP_BLOCK, SWEEP_CHUNK, SWEEP_NEAR, sweep_sums

#: Series of at most this many samples take the one-call small path
#: (:mod:`avar._kernels.allan.small`): one thread, a full cumulative sum of 16 bytes
#: a sample; starting the thread pool would cost more than the work. (Decided
#: on N alone: a column's bits do not depend on the other columns.)
SMALL_MAX = 1 << 15

#: Octave-or-not "mo" series of at most this many samples (a 5.8 h log at 200 Hz) take the
#: small path with the levels shared among the threads (16 bytes a sample of cumulative sum,
#: and up to 8 bytes a sample per thread for a level that fails certification). Warm, the
#: octave path (:func:`run_sweep`) was about twice as fast above 2**18 samples (17 ms against 33 ms for
#: 1.44 M samples), but compiling its pyramid, far and block-table kernels costs about 4 s more
#: on a cold cache than the small path: a typical log's first report would wait for them.
SMALL_MO_MAX = 1 << 22


#: A last group of far levels of at most this many levels is merged into the group before (see
#: :func:`run_sweep`): every group computes its local prefixes once, which costs about as much as
#: two levels (at N = 1e7, the octave levels 2**21 and 2**22 as a group of their own took 10 %
#: more CPU time in all than one group of eight with a 2 MB ring).
FAR_TAIL = 2

#: ... provided the merged group's largest factor is at most this many times ``span`` its smallest.
FAR_TAIL_RATIO = 4


def _scales(maxabs):
    """Power-of-two scale per column bringing extreme magnitudes near 1 (1.0 otherwise), and
    whether any column has one. (NumPy: a handful of values, nothing to compile.)"""
    with np.errstate(invalid="ignore"):
        extreme = np.isfinite(maxabs) & (maxabs > 0.0) & ((maxabs > 2.0**LIMIT_EXP) | (maxabs < 2.0**-LIMIT_EXP))
    _, e = np.frexp(np.where(extreme, maxabs, 1.0))
    scale = np.where(extreme, np.ldexp(1.0, -np.clip(e, -1000, 1000)), 1.0)  # 2**-e stays a normal float64
    return scale, bool(extreme.any())


def _finish(sums, scale, factors, n_diff):
    """The Allan variances from the sums of squares of every (column, level)."""
    m = factors.astype(np.float64)
    unscale = (1.0 / scale)[:, None]
    return sums / (2.0 * m * m * n_diff) * unscale * unscale


def _table(data, block):
    """Block table with the scale of extreme columns: (th, tl, centre, scale, spread)."""
    integral = data.dtype.kind in "iu"
    th, tl, centre, maxabs, spread = block_table(data, np.ones(data.shape[1]), integral, block)
    scale, redo = _scales(maxabs)
    if redo:
        th, tl, centre, maxabs, spread = block_table(data, scale, integral, block)
    return th, tl, centre, scale, spread


def run_levels(data, factors, n_diff, is_mo, block=BLOCK, near=NEAR, chunk=CHUNK_BLOCKS):
    """Any grid (``factors`` increasing, all valid): level by level (:mod:`avar._kernels.allan.levels`)."""
    data = read_only(data)
    th, tl, centre, scale, _ = _table(data, block)
    counts = n_diff if is_mo else data.shape[0] // factors
    small_count = int(np.searchsorted(factors, near, side="right")) if is_mo else factors.shape[0]
    sums = level_sums(data, centre, scale, th, tl, factors, counts, is_mo, small_count, block, near, chunk)
    return _finish(sums, scale, factors, n_diff.astype(np.float64))


def _chunk(n, block, most):
    """Blocks per task: ``most``, or fewer so that a short series still makes about 4 tasks.

    A function of N alone: the summation order does not depend on the number of threads.
    """
    n_blocks = -(-int(n) // block)
    return max(1, min(most, -(-n_blocks // 4)))


def run_haar(data, factors, n_diff, exp=PYRAMID_EXP, chunk=None):
    """"to" at power-of-two cluster sizes ``factors`` (increasing): the Haar pyramid."""
    data = read_only(data)
    exps = np.log2(factors).astype(np.int64)
    n_levels = int(exps[-1]) + 1
    chunk = _chunk(data.shape[0], 1 << exp, HAAR_CHUNK) if chunk is None else chunk
    sums, big = haar_sums(data, np.ones(data.shape[1]), n_levels, exp, chunk)
    scale, redo = _scales(big)
    if redo:
        sums, _ = haar_sums(data, scale, n_levels, exp, chunk)
    out = _finish(np.ascontiguousarray(sums[:, exps]), scale, factors, n_diff.astype(np.float64))
    out[~np.isfinite(big)] = np.nan  # a non-finite sample, maybe in no requested level's clusters
    return out


def run_sweep(data, factors, n_diff, block=None, near=None, chunk=None, fine=SWEEP_FINE, tol=CERTIFY_TOL,
              span=FAR_SPAN, window=False):
    """"mo" at power-of-two cluster sizes ``factors`` (increasing): the levels below ``near``
    by moving sums by pairs in blocks of ``block`` samples (:mod:`avar._kernels.allan.pyramid`;
    ``window=True``: by the compensated sliding window of :mod:`avar._kernels.allan.sweep`, the
    former path, with its own defaults), the others by residue class
    (:mod:`avar._kernels.allan.far`, table granularity ``fine``, certification tolerance ``tol``),
    in groups whose largest factor is at most ``span`` times their smallest (a task's ring
    of local prefixes holds ``2 span + 2`` pieces: 528 kB by default, whatever N); a last
    group of at most :data:`FAR_TAIL` levels joins the one before when the whole stays within
    ``FAR_TAIL_RATIO span`` (a ring of at most 2 MB)."""
    data = read_only(data)
    if near is None:
        near = SWEEP_NEAR if window else PYRAMID_NEAR
    if block is None:
        block = SWEEP_BLOCK if window else PYRAMID_BLOCK
    n_small = int(np.searchsorted(factors, near))
    fine = min(fine, int(factors[n_small])) if n_small < factors.shape[0] else fine
    th, tl, centre, scale, spread = _table(data, fine)
    sums = np.empty((data.shape[1], factors.shape[0]))
    if n_small > 0:
        small, nd = factors[:n_small], n_diff[:n_small]
        if window:
            chunk = _chunk(n_diff[0], block, SWEEP_CHUNK) if chunk is None else chunk
            sums[:, :n_small] = sweep_sums(data, centre, scale, small, nd, block, chunk)
        else:
            chunk = _chunk(n_diff[0], block, PYRAMID_CHUNK) if chunk is None else chunk
            sums[:, :n_small] = pyramid_sums(data, centre, scale, small, nd, block, chunk, tol)
    start = n_small
    while start < factors.shape[0]:
        stop = int(np.searchsorted(factors, factors[start] * span, side="right"))
        if factors.shape[0] - stop <= FAR_TAIL and factors[-1] <= factors[start] * span * FAR_TAIL_RATIO:
            stop = factors.shape[0]  # a short last group joins this one: its prefixes would cost more than its ring
        sums[:, start:stop] = far_sums(data.T, scale, centre, th, tl, spread, factors[start:stop], n_diff[start:stop],
                                       fine, tol)
        start = stop
    return _finish(sums, scale, factors, n_diff.astype(np.float64))


def _as_kernel_input(data) -> np.ndarray:
    """``data`` as an (N, C) array of a dtype the kernels read, always read-only (a view,
    never a copy, when it is one already): writable and read-only arrays are distinct
    types to numba, and each would compile the kernels again."""
    x = np.asarray(data)  # an np.memmap becomes a plain view, never a copy
    if x.ndim == 1:
        x = x[:, None]
    kind = x.dtype.kind
    if kind == "b":
        x = x.view(np.uint8)
    elif kind not in "iuf" or not x.dtype.isnative or x.dtype.itemsize > 8:
        x = x.astype(np.float64)
    elif x.dtype == np.float16:
        x = x.astype(np.float32)  # exact; numba has no float16 arithmetic
    return read_only(x)


class KernelCall(NamedTuple):
    """A compiled loop and the first argument it would be called with: an entry of
    :func:`avar._kernels.runtime.paths.compiled` (a tuple ``(kernel, argument)``)."""

    kernel: object
    argument: object


def column_kernels(data, factors, type: str) -> list[KernelCall]:
    """The compiled loops :func:`allan_variance_columns` runs on series of up to
    :data:`SMALL_MO_MAX` samples, as :class:`KernelCall` entries of
    :func:`avar._kernels.runtime.paths.compiled` (whether they are compiled yet, for this dtype)."""
    x = _as_kernel_input(data)
    f = np.asarray(factors, dtype=np.int64).reshape(-1)
    n = x.shape[0]
    if n <= SMALL_MAX:
        return [KernelCall(small_allan_variance, x)]
    if type == "mo":
        return [KernelCall(small_allan_variance, x), KernelCall(PARALLEL_KERNEL, np.empty(0))]
    if f.size and np.all((f & (f - 1)) == 0):
        return [KernelCall(HAAR_KERNEL, x.T)]
    return [KernelCall(table_task, x), KernelCall(to_task, x)]


def sweep_kernels(data) -> list[KernelCall]:
    """The compiled loops :func:`run_sweep` runs on ``data`` (N, C), as :class:`KernelCall`
    entries of :func:`avar._kernels.runtime.paths.compiled` (the far levels' exact redo,
    compiled only when a piece needs it, aside)."""
    x = _as_kernel_input(data)
    return [KernelCall(table_task, x), KernelCall(pyramid_task, x.T), KernelCall(far_task, x.T)]


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
    small = n <= SMALL_MAX
    if small and f.shape[0] and channels and f.min() >= 1 and n_diff.min() > 0:
        return small_allan_variance(x, f, n_diff, is_mo, x.dtype.kind in "iu")  # the common short call
    out = np.full((channels, f.shape[0]), np.nan)
    valid = (f >= 1) & (n_diff > 0)
    if not valid.any() or channels == 0:
        return out
    fs, inverse = np.unique(f[valid], return_inverse=True)  # increasing, distinct
    nd = n - 2 * fs + 1 if is_mo else n // fs - 1
    if small:
        values = small_allan_variance(x, fs, nd, is_mo, x.dtype.kind in "iu")
    elif is_mo and n <= SMALL_MO_MAX:
        values = small_allan_variance_parallel(x, fs, nd, is_mo, x.dtype.kind in "iu")
    else:
        if np.all((fs & (fs - 1)) == 0):  # powers of two (octave grids)
            values = run_sweep(x, fs, nd) if is_mo else run_haar(x, fs, nd)
        else:
            values = run_levels(x, fs, nd, is_mo)
    out[:, valid] = values[:, inverse.reshape(-1)]
    return out
