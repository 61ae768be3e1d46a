"""Hot loops of the Allan variance, compiled with numba.

Nothing here validates input or builds objects: :mod:`avar.estimate` does that
once at the public boundary and calls these kernels on clean float64 arrays.
The tests check every kernel against a plain NumPy transcription of the
estimator formulas.

How the Allan variance is computed
----------------------------------
Both estimators need, for a cluster size ``m``, sums of squared second
differences of the cumulative sum ``S`` of the series::

    D_k = S[b + 2m] - 2 S[b + m] + S[b]        (b = k * stride)

``D_k / m`` is the difference of two adjacent cluster means; ``stride`` is 1
for the maximal-overlap estimator and ``m`` for the tau-overlap one. Each
``D_k`` costs O(1), so a level costs O(number of differences), never O(N m).

Cancellation is the numerical risk: ``S`` can be many orders of magnitude
larger than ``D`` (a drift or random walk, a large offset). Three steps keep
the result within a few ulps of exact arithmetic on the float64 input:

1. the series is centred on its mean, and the centred value is kept exactly
   as an unevaluated sum ``hi + lo`` (Knuth's TwoSum);
2. it is scaled by a power of two (exact) so that values are O(1);
3. the cumulative sum is compensated: ``S = hi + lo`` with ``hi`` the float64
   running sum and ``lo`` its accumulated rounding error, stored as float32
   (its own relative precision is irrelevant because it is ~1e-16 of ``hi``;
   float32 keeps the memory at 12 bytes per sample).

The differences ``S[a] - S[b]`` are then formed as ``(hi[a] - hi[b]) +
(lo[a] - lo[b])``, which is accurate relative to the window sums rather than
to ``S``.
"""

from __future__ import annotations

import os

# numba's OpenMP threads spin-wait between parallel regions by default; when
# another process holds a core, a short parallel call can then take 10-100x
# longer. A short spin before sleeping keeps full speed on an idle machine and
# degrades gracefully on a busy one. The user's own settings win. (Read by
# libgomp when numba first starts its thread pool, i.e. after this import.)
if "OMP_WAIT_POLICY" not in os.environ and "GOMP_SPINCOUNT" not in os.environ:
    os.environ["GOMP_SPINCOUNT"] = "1000"

import numpy as np  # noqa: E402
from numba import njit, prange  # noqa: E402

#: Number of differences one parallel task sums (tasks are (channel, level,
#: chunk) triples; the chunk size fixes the summation order, so results do
#: not depend on the number of threads).
CHUNK = 1 << 15

#: Samples per block of the parallel cumulative sum.
CUMSUM_BLOCK = 1 << 16

#: Differences per time block when all "mo" levels are fused: the window
#: ends of the smaller levels stay in the caches across the block.
FUSED_BLOCK = 1 << 16

#: Grids with more levels than this (such as taus="all") go level by level:
#: their per-level work is large and the fused per-block table would be too.
FUSED_MAX_LEVELS = 128


@njit(cache=True, parallel=True)
def column_moments(data, block=CUMSUM_BLOCK):
    """Mean, minimum and maximum of every column of ``data`` (N, C) in one pass.

    The mean is a sum of block sums (the centre needs no more precision: the
    Allan variance does not depend on it, and the centring itself is exact).
    """
    n, channels = data.shape
    n_blocks = (n + block - 1) // block
    sums = np.zeros((channels, n_blocks))
    lows = np.empty((channels, n_blocks))
    highs = np.empty((channels, n_blocks))
    for task in prange(channels * n_blocks):
        c = task // n_blocks
        b = task % n_blocks
        total = 0.0
        low = data[b * block, c]
        high = low
        for i in range(b * block, min(n, (b + 1) * block)):
            v = data[i, c]
            total += v
            low = min(low, v)
            high = max(high, v)
        sums[c, b] = total
        lows[c, b] = low
        highs[c, b] = high
    mean = np.empty(channels)
    low = np.empty(channels)
    high = np.empty(channels)
    for c in range(channels):
        mean[c] = sums[c].sum() / n
        low[c] = lows[c].min()
        high[c] = highs[c].max()
    return mean, low, high


@njit(cache=True, inline="always")
def _two_sum(a, b):
    """Knuth's TwoSum: ``a + b == s + e`` exactly."""
    s = a + b
    bv = s - a
    e = (a - (s - bv)) + (b - bv)
    return s, e


@njit(cache=True, inline="always")
def _centred(xi, ctr, sc):
    """``(xi - ctr) * sc`` as an exact pair (``sc`` is a power of two)."""
    yh, yl = _two_sum(xi, -ctr)
    return yh * sc, yl * sc


@njit(cache=True, parallel=True)
def centred_cumsum(data, centre, scale, hi, lo, block=CUMSUM_BLOCK):
    """Fill ``hi``, ``lo`` with compensated cumulative sums of ``(data[:, c] - centre[c]) * scale[c]``.

    Two passes over blocks of ``block`` samples, both parallel: the first
    sums every block, an exact (double-double) scan turns the block sums into
    offsets, the second writes the running sums of every block from its
    offset. The block size, not the thread count, fixes the arithmetic.

    Parameters
    ----------
    data : float64 array, shape (N, C)
    centre, scale : float64 arrays, shape (C,); ``scale`` must be powers of two.
    hi : float64 array, shape (C, N + 1), output
        Running float64 sums, ``hi[c, 0] = 0``.
    lo : float32 array, shape (C, N + 1), output
        Accumulated rounding errors: ``hi + lo`` is the exact cumulative sum
        up to O(eps**2).

    The outputs are allocated by the caller with NumPy, whose allocator asks
    the kernel for huge pages: first-touch page faults of fresh memory
    otherwise cost more than the arithmetic.
    """
    n, channels = data.shape
    n_blocks = (n + block - 1) // block
    block_hi = np.empty((channels, n_blocks))
    block_lo = np.empty((channels, n_blocks))
    for task in prange(channels * n_blocks):
        c = task // n_blocks
        b = task % n_blocks
        total = 0.0
        comp = 0.0
        for i in range(b * block, min(n, (b + 1) * block)):
            yh, yl = _centred(data[i, c], centre[c], scale[c])
            total, err = _two_sum(total, yh)
            comp += err + yl
        block_hi[c, b] = total
        block_lo[c, b] = comp
    for c in range(channels):
        total = 0.0
        comp = 0.0
        for b in range(n_blocks):
            offset_hi = block_hi[c, b]
            block_hi[c, b] = total
            offset_lo = block_lo[c, b]
            block_lo[c, b] = comp
            total, err = _two_sum(total, offset_hi)
            comp += err + offset_lo
        hi[c, 0] = 0.0
        lo[c, 0] = 0.0
    for task in prange(channels * n_blocks):
        c = task // n_blocks
        b = task % n_blocks
        total = block_hi[c, b]
        comp = block_lo[c, b]
        for i in range(b * block, min(n, (b + 1) * block)):
            yh, yl = _centred(data[i, c], centre[c], scale[c])
            total, err = _two_sum(total, yh)
            comp += err + yl
            hi[c, i + 1] = total
            lo[c, i + 1] = comp


#: Length of the per-task scratch buffer: the squared differences of a block
#: are written there by a vectorizable loop, then summed by a reduction that
#: may reassociate. The compensated differences themselves are never
#: reassociated (that would undo the compensation).
BLOCK = 512


@njit(cache=True, fastmath=True)
def _sum(buffer, count):
    total = 0.0
    for j in range(count):
        total += buffer[j]
    return total


@njit(cache=True)
def _contiguous_squares(hi, lo, m, start, count, buffer):
    """Sum of ``D_k**2`` for ``k = start .. start + count - 1`` with stride 1.

    ``count`` must not exceed ``buffer.shape[0]``. The loop over contiguous
    windows is one that LLVM vectorizes.
    """
    h0 = hi[start : start + count]
    h1 = hi[start + m : start + m + count]
    h2 = hi[start + 2 * m : start + 2 * m + count]
    l0 = lo[start : start + count]
    l1 = lo[start + m : start + m + count]
    l2 = lo[start + 2 * m : start + 2 * m + count]
    for j in range(count):
        # lo's second difference in float32 (8 lanes, one conversion): its
        # rounding is ~6e-8 of a quantity already ~1e-16 of the cumulative sum.
        d = ((h2[j] - h1[j]) - (h1[j] - h0[j])) + np.float64((l2[j] - l1[j]) - (l1[j] - l0[j]))
        buffer[j] = d * d
    return _sum(buffer, count)


@njit(cache=True)
def _strided_squares(hi, lo, m, stride, start, count, buffer):
    """Sum of ``D_k**2`` for ``k = start .. start + count - 1``, windows ``stride`` apart."""
    for j in range(count):
        b = (start + j) * stride
        d = ((hi[b + 2 * m] - hi[b + m]) - (hi[b + m] - hi[b])) + np.float64(
            (lo[b + 2 * m] - lo[b + m]) - (lo[b + m] - lo[b])
        )
        buffer[j] = d * d
    return _sum(buffer, count)


@njit(cache=True, parallel=True)
def fused_overlapping_sums(hi, lo, factors, n_differences, block=FUSED_BLOCK):
    """Maximal-overlap sums of all levels, one time block per task.

    Task ``(c, b)`` covers differences ``k`` in ``[b * block, (b + 1) * block)``
    of channel ``c`` at every level, so the cumulative sums around that block
    are read from memory once for all levels (for octave grids the window
    ends of level j are the window middles of level j + 1).

    ``factors`` must be increasing (so ``n_differences`` decreases).
    Returns the per-block sums, shape (C, n_blocks, L).
    """
    channels = hi.shape[0]
    n_levels = factors.shape[0]
    n_blocks = (n_differences[0] + block - 1) // block
    out = np.zeros((channels, n_blocks, n_levels))
    for task in prange(channels * n_blocks):
        c = task // n_blocks
        start = (task % n_blocks) * block
        buffer = np.empty(BLOCK)
        h = hi[c]
        l = lo[c]
        for k in range(n_levels):
            stop = min(start + block, n_differences[k])
            if stop <= start:
                break
            total = 0.0
            for first in range(start, stop, BLOCK):
                total += _contiguous_squares(h, l, factors[k], first, min(BLOCK, stop - first), buffer)
            out[c, task % n_blocks, k] = total
    return out


@njit(cache=True, parallel=True)
def task_sums(hi, lo, task_channel, task_factor, task_stride, task_first, task_last):
    """Evaluate every task's sum of squared second differences in parallel.

    Task ``i`` sums ``D_k**2`` of channel ``task_channel[i]`` at cluster size
    ``task_factor[i]`` and stride ``task_stride[i]`` for
    ``k in [task_first[i], task_last[i])``.
    """
    n_tasks = task_channel.shape[0]
    out = np.empty(n_tasks, dtype=np.float64)
    for i in prange(n_tasks):
        buffer = np.empty(BLOCK)
        h = hi[task_channel[i]]
        l = lo[task_channel[i]]
        m = task_factor[i]
        stride = task_stride[i]
        total = 0.0
        for first in range(task_first[i], task_last[i], BLOCK):
            count = min(BLOCK, task_last[i] - first)
            if stride == 1:
                total += _contiguous_squares(h, l, m, first, count, buffer)
            else:
                total += _strided_squares(h, l, m, stride, first, count, buffer)
        out[i] = total
    return out


def _level_wise_sums(hi, lo, channels, factors, strides, n_differences, chunk):
    """Sums of (channel, level) pairs, each split into tasks of ``chunk`` differences."""
    per_pair = -(-n_differences // chunk)
    pair_of_task = np.repeat(np.arange(channels.shape[0]), per_pair)
    pair_start = np.concatenate(([0], np.cumsum(per_pair)[:-1]))
    first = (np.arange(pair_of_task.shape[0]) - pair_start[pair_of_task]) * chunk
    last = np.minimum(first + chunk, n_differences[pair_of_task])
    sums = task_sums(
        hi, lo, channels[pair_of_task], factors[pair_of_task], strides[pair_of_task], first, last
    )
    return np.bincount(pair_of_task, weights=sums, minlength=channels.shape[0])


def squared_difference_sums(hi, lo, factors, strides, n_differences, chunk=CHUNK):
    """Sum of squared second differences ``D_k**2`` for every channel and level.

    Parameters
    ----------
    hi, lo : arrays of shape (C, N + 1) from :func:`centred_cumsum`.
    factors, strides, n_differences : int64 arrays of shape (L,)
        Cluster size ``m`` (increasing), stride between differences (1 for
        "mo", ``m`` for "to") and number of differences of every level.
    chunk : int
        Differences per parallel task on the level-by-level path.

    Returns
    -------
    float64 array of shape (C, L)

    Notes
    -----
    Maximal-overlap grids of at most ``FUSED_MAX_LEVELS`` levels go through
    :func:`fused_overlapping_sums`; others (tau overlap, taus="all") through
    :func:`task_sums`. Either way the summation order depends only on the
    block sizes, never on the number of threads.
    """
    factors = np.asarray(factors, dtype=np.int64)
    strides = np.asarray(strides, dtype=np.int64)
    n_differences = np.asarray(n_differences, dtype=np.int64)
    n_channels = hi.shape[0]
    n_levels = factors.shape[0]
    if np.all(strides == 1) and n_levels <= FUSED_MAX_LEVELS:
        return fused_overlapping_sums(hi, lo, factors, n_differences).sum(axis=1)
    channel = np.repeat(np.arange(n_channels, dtype=np.int64), n_levels)
    level = np.tile(np.arange(n_levels), n_channels)
    sums = _level_wise_sums(hi, lo, channel, factors[level], strides[level], n_differences[level], chunk)
    return sums.reshape(n_channels, n_levels)


# --- Theoretical Allan variance of a covariance matrix (moav, noav) ---
#
# One pass over a T x T covariance matrix C (used by avar.nonstationary) that
# checks it (finite, symmetric) and, in the same visit of each row, gathers
# what the theoretical MOAV / NOAV need. Two tasks share the work: the top
# one walks rows 0, 1, ... and the bottom one rows T - 1, T - 2, ...; the
# split of the symmetry check between them is fixed by the tile size only,
# so results do not depend on the number of threads.
#
# MOAV (see avar.nonstationary for the derivation). With the diagonals
# c_d(i) = C[i, i + d], each centred on its middle element beta_d, the sum
# over windows of w' C_s w (w = -1 x n, +1 x n) is
#
#   sum_{d < 2n} mult_d rho_d(n) (beta_d W + D_d) - (Q1[2n-1] - 2 R[n-1] + 2 Q2[n-1])
#
# (W = T - 2n + 1, mult_0 = 1 else 2, rho_d = 2n - 3d for d < n else d - 2n)
# where D_d is the sum of the centred diagonal d, and, with the second-order
# prefix sums H[x, d] = sum_{i < x} (x - i) F[i, d] of the centred corner
# entries F[i, d] = c_d(i) + c_d(T - d - 1 - i) (top-left corner plus the
# bottom-right one turned onto it),
#
#   Q1[q] = sum_{x + d = q} mult_d sign(x - d) H[x, d]
#   Q2[q] = sum_{x + d = q} mult_d H[x, d]
#   R[x]  = sum_{d <= x} mult_d H[x, d]
#
# (the three ramps of the weight of a corner entry, see avar.nonstationary).
# The pass yields beta, D, Q1, Q2, R for d, q < 2 max(n); each scale then
# costs O(n). NOAV sums the upper triangle of the disjoint diagonal blocks
# row by row (each row of a block is two or three segment sums).

#: Rows per strip and side of the tiles of the symmetry check.
COV_TILE = 64

#: NOAV switches from per-scale segment sums to a per-row prefix scan when
#: the scales' total block width exceeds this multiple of the widest block.
NOAV_SCAN_RATIO = 16


@njit(cache=True, fastmath=True)
def _cov_sum(v, lo, hi):
    """``v[lo:hi].sum()`` (vectorized; the order depends on ``hi - lo`` only)."""
    w = v[lo:hi]
    total = 0.0
    for j in range(w.shape[0]):
        total += w[j]
    return total


#: Mask of the magnitude bits of a float64: (bits & mask), compared as int64,
#: orders |x| like floats and puts inf and NaN above every finite value.
_MAGNITUDE = np.int64(0x7FFFFFFFFFFFFFFF)


@njit(cache=True)
def _cov_magnitude(bits, r0, r1, c0, c1, top):
    """max of ``bits[r0:r1, c0:c1] & _MAGNITUDE`` and ``top`` (contiguous rows)."""
    for a in range(r0, r1):
        row = bits[a, c0:c1]
        for b in range(row.shape[0]):
            v = row[b] & _MAGNITUDE
            top = v if v > top else top
    return top


@njit(cache=True)
def _cov_tile(c, bits, r0, r1, c0, c1, asym, top):
    """Check the tile ``c[r0:r1, c0:c1]`` (c0 >= r0; c0 == r0: a diagonal tile,
    upper triangle) against its mirror ``c[c0:c1, r0:r1]``.

    Returns the running max |c[a, b] - c[b, a]| and the running max magnitude
    bits of all entries of both tiles (see ``_MAGNITUDE``). The mirror's rows
    are read contiguously first (which also brings them into cache for the
    column walk of the comparison); columns are compared two at a time, as two
    independent chains of max.
    """
    if c0 != r0:
        top = _cov_magnitude(bits, c0, c1, r0, r1, top)
    top = _cov_magnitude(bits, r0, r1, c0, c1, top)
    a = r0
    while a + 1 < r1:
        lo = max(c0, a + 2)
        u0 = c[a, lo:c1]
        u1 = c[a + 1, lo:c1]
        l0 = c[lo:c1, a]
        l1 = c[lo:c1, a + 1]
        m0 = 0.0
        m1 = 0.0
        for b in range(u0.shape[0]):
            m0 = max(m0, abs(u0[b] - l0[b]))
            m1 = max(m1, abs(u1[b] - l1[b]))
        asym = max(asym, m0, m1)
        if c0 == r0:  # the pair (a, a + 1) of a diagonal tile
            asym = max(asym, abs(c[a, a + 1] - c[a + 1, a]))
        a += 2
    if a < r1:
        for b in range(max(c0, a + 1), c1):
            asym = max(asym, abs(c[a, b] - c[b, a]))
    return asym, top


@njit(cache=True)
def _cov_noav_row(row, r, t, ns, acc, scan, pre):
    """Add row r's share of every NOAV block sum: for r in the first half A of
    its block [s, s + 2n), ``C[r, r] + 2 C[r, r+1:s+n].sum() - 2 C[r, s+n:s+2n].sum()``,
    in the second half ``C[r, r] + 2 C[r, r+1:s+2n].sum()``."""
    if scan:  # pre[x] = row[r:r+x].sum(), once for all scales
        seg = row[r:r + min(pre.shape[0] - 1, t - r)]
        run = 0.0
        pre[0] = 0.0
        for x in range(seg.shape[0]):
            run += seg[x]
            pre[x + 1] = run
    for k in range(ns.shape[0]):
        n = ns[k]
        two = 2 * n
        if r >= two * (t // two):
            continue
        s = (r // two) * two
        e = s + n
        if scan:
            if r < e:
                v = 2.0 * ((pre[e - r] - pre[1]) - (pre[e + n - r] - pre[e - r]))
            else:
                v = 2.0 * (pre[s + two - r] - pre[1])
        elif r < e:
            v = 2.0 * (_cov_sum(row, r + 1, e) - _cov_sum(row, e, e + n))
        else:
            v = 2.0 * _cov_sum(row, r + 1, s + two)
        acc[k] += row[r] + v


@njit(cache=True)
def _cov_centred(row, r, beta, nd, f):
    """``f[:nd] = row[r:r+nd] - beta[:nd]`` (the centred diagonals in row r).

    The hot loops index slices from 0: with ``row[r + d]`` numba's handling of
    negative indices keeps LLVM from vectorizing (3-4x slower)."""
    src = row[r:r + nd]
    b = beta[:nd]
    out = f[:nd]
    for d in range(nd):
        out[d] = src[d] - b[d]


@njit(cache=True)
def _cov_add(dst, src, n, scale=1.0):
    """``dst[:n] += scale * src[:n]``."""
    a = dst[:n]
    b = src[:n]
    for d in range(n):
        a[d] += scale * b[d]


@njit(cache=True)
def _cov_prefix(f, g, h, n):
    """One step of the second-order prefix sums: ``g += f; h += g`` (first n)."""
    a = f[:n]
    b = g[:n]
    e = h[:n]
    for d in range(n):
        b[d] += a[d]
        e[d] += b[d]


@njit(cache=True)
def _cov_moav_row(row, r, t, beta, width, half, band, down, f, sums):
    """MOAV work of row r: the centred diagonal sums (if ``band``) and one step of
    the corner recursion, for the top-left corner when walking down (x = r + 1:
    every diagonal is at its x-th element) or else the bottom-right one (q = T - r:
    diagonal d is at its (q - d)-th element from the end).

    ``sums`` holds the rows dp, g, h, q1, q2, rr. The loops are split so that each
    touches few arrays (LLVM vectorizes a loop only if it can check all pairs of
    them for overlap).
    """
    dp, g, h, q1, q2, rr = sums[0], sums[1], sums[2], sums[3], sums[4], sums[5]
    nd = min(width, t - r)
    if down:
        nc = width - r - 1 if r <= width - 2 else 0  # corner diagonals d < width - x
    else:
        nc = t - r if t - r < width else 0  # d < q
    _cov_centred(row, r, beta, nd if band else nc, f)
    if band:
        _cov_add(dp, f, nd)
    if nc == 0:
        return
    _cov_prefix(f, g, h, nc)  # h[d] = H[x, d] (down) or H[q - d, d] (up)
    if down:
        x = r + 1
        q1[x] += h[0]  # q1[x + d] += mult_d sign(x - d) h[d]
        _cov_add(q1[x + 1:], h[1:], min(x, nc) - 1, 2.0)
        if nc > x + 1:
            _cov_add(q1[2 * x + 1:], h[x + 1:], nc - x - 1, -2.0)
        if x < half:
            q2[x] += h[0]
            _cov_add(q2[x + 1:], h[1:], half - x - 1, 2.0)
            rr[x] += h[0] + 2.0 * _cov_sum(h, 1, x + 1)
    else:
        q = nc
        q1[q] += h[0] + 2.0 * (_cov_sum(h, 1, (q + 1) // 2) - _cov_sum(h, q // 2 + 1, q))
        if q < half:
            q2[q] += h[0] + 2.0 * _cov_sum(h, 1, q)
        for d in range(max(0, q - half + 1), q // 2 + 1):  # rr[x] += mult_d H[x, d], d <= x
            rr[q - d] += h[d] if d == 0 else 2.0 * h[d]


@njit(cache=True)
def _cov_check_strip(c, bits, r0, r1, stop, mirror, tile, asym, top):
    """Check the tiles of rows [r0, r1) and columns [r0, stop), then the tiles of
    rows [0, mirror) and columns [r0, r1), against their mirrors (one call site of
    ``_cov_tile``: each call site is inlined, and compiling is the slow part)."""
    n_own = (stop - r0 + tile - 1) // tile
    for k in range(n_own + (mirror + tile - 1) // tile):
        if k < n_own:
            a0, a1, b0, b1 = r0, r1, r0 + k * tile, min(stop, r0 + (k + 1) * tile)
        else:
            a0 = (k - n_own) * tile
            a1, b0, b1 = min(mirror, a0 + tile), r0, r1
        asym, top = _cov_tile(c, bits, a0, a1, b0, b1, asym, top)
    return asym, top


@njit(cache=True, parallel=True)
def _cov_tasks(c, beta, width, noav_ns, noav_scan, tile, split, far, asym, top, sums, acc,
               f, pre):
    """The two tasks of :func:`covariance_pass` (the only parallel loop: with
    ``parallel=True`` numba turns every array expression into a parallel loop of
    its own, each costing compile time, so nothing else is here)."""
    t = c.shape[0]
    half = width // 2
    bits = c.view(np.int64)
    for task in prange(2):
        down = task == 0  # the top task walks down, the bottom one up
        run_asym = 0.0
        run_top = np.int64(0)
        scan_buffer = pre[task, :pre.shape[1] - 8]  # the rest is padding
        # own rows (check, diagonal sums, NOAV), then the rest of the task's corner
        n_own = split if down else t - split
        if down:
            n_rest = max(0, width - 1 - split)  # rows split .. width - 2
        else:
            n_rest = max(0, split - max(t - width + 1, 0))  # rows split - 1 .. T - width + 1
        for k in range(n_own + n_rest):
            r = k if down else t - 1 - k
            band = k < n_own
            if band and (r % tile == 0 if down else (r + 1) % tile == 0 or r == t - 1):
                r0 = r - r % tile  # a new strip of rows [r0, r1)
                r1 = min(split if down else t, r0 + tile)
                mirror = split if not down and r0 >= far else 0
                run_asym, run_top = _cov_check_strip(c, bits, r0, r1, far if down else t,
                                                     mirror, tile, run_asym, run_top)
            if width > 0:
                _cov_moav_row(c[r], r, t, beta, width, half, band, down, f[task], sums[task])
            if band and noav_ns.shape[0] > 0:
                _cov_noav_row(c[r], r, t, noav_ns, acc[task], noav_scan, scan_buffer)
        asym[task] = run_asym
        top[task] = run_top


@njit(cache=True)
def covariance_pass(c, width, noav_ns, noav_scan, noav_width, tile=COV_TILE):
    """Check ``c`` and gather the MOAV / NOAV sums, in one parallel pass.

    Parameters
    ----------
    c : float64 array, shape (T, T), C-contiguous
    width : int
        ``2 max(n)`` of the MOAV scales (0: no MOAV sums).
    noav_ns : int64 array
        NOAV scales (may be empty).
    noav_scan : bool
        Use one prefix scan per row for NOAV (many scales) instead of
        segment sums per scale.
    noav_width : int
        ``2 max(noav_ns)`` (prefix length of the scan).

    Returns
    -------
    asym : float
        max |c - c.T| (meaningless if c is not finite).
    top : int64
        Bits of max |c| (as float64): >= 0x7FF0000000000000 iff c holds an
        infinite or NaN entry.
    beta, dp, q1, q2, rr : float64 arrays, shape (width,)
        Diagonal centres, centred diagonal sums and corner sums (see above).
    noav : float64 array, shape (len(noav_ns),)
        Sum over the disjoint blocks of ``w' C_s w``.

    Notes
    -----
    The top task checks the pairs (i < j) with i < split, j < far and takes
    rows [0, split); the bottom task the other pairs and rows. ``split`` is
    half the strips of ``tile`` rows and ``far`` three quarters, so that both
    check about T^2 / 4 pairs.
    """
    t = c.shape[0]
    beta = np.empty(width)
    for d in range(width):
        mid = (t - 1 - d) // 2
        beta[d] = c[mid, mid + d]
    n_strips = (t + tile - 1) // tile
    split = min(t, (n_strips // 2) * tile)
    far = min(t, max(split, ((3 * n_strips + 2) // 4) * tile))
    asym = np.zeros(2)
    top = np.zeros(2, dtype=np.int64)
    sums = np.zeros((2, 6, max(width, 1)))
    # per-task rows at least a cache line apart (no false sharing)
    acc = np.zeros((2, noav_ns.shape[0] + 8))
    f = np.empty((2, width + 8))
    pre = np.empty((2, noav_width + 9))
    _cov_tasks(c, beta, width, noav_ns, noav_scan, tile, split, far, asym, top, sums, acc,
               f, pre)
    n = noav_ns.shape[0]
    noav = np.empty(n)
    for k in range(n):
        noav[k] = acc[0, k] + acc[1, k]
    out = np.empty((4, width))
    for k, row in enumerate((0, 3, 4, 5)):
        for d in range(width):
            out[k, d] = sums[0, row, d] + sums[1, row, d]
    return max(asym[0], asym[1]), max(top[0], top[1]), beta, out[0], out[1], out[2], out[3], noav


@njit(cache=True)
def moav_from_sums(ns, t, beta, dp, q1, q2, rr):
    """MOAV at every scale from the sums of :func:`covariance_pass` (O(n) each)."""
    out = np.empty(ns.shape[0])
    for k in range(ns.shape[0]):
        n = ns[k]
        w = t - 2 * n + 1
        total = 0.0
        for d in range(2 * n):
            rho = 2 * n - 3 * d if d < n else d - 2 * n  # sum_m w_m w_(m+d)
            mult = 1.0 if d == 0 else 2.0
            total += mult * rho * (beta[d] * w + dp[d])
        corner = q1[2 * n - 1] - 2.0 * rr[n - 1] + 2.0 * q2[n - 1]
        out[k] = (total - corner) / (2.0 * n * n * w)
    return out
