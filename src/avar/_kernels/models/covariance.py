"""Theoretical Allan variance of a covariance matrix (moav, noav), in numba.

One pass over a T x T covariance matrix C (used by avar.models.nonstationary) that
checks it (finite, symmetric) and, in the same visit of each row, gathers
what the theoretical MOAV / NOAV need. Two tasks share the work: the top
one walks rows 0, 1, ... and the bottom one rows T - 1, T - 2, ...; the
split of the symmetry check between them is fixed by the tile size only,
so results do not depend on the number of threads.

MOAV (see avar.models.nonstationary for the derivation). With the diagonals
c_d(i) = C[i, i + d], each centred on its middle element beta_d, the sum
over windows of w' C_s w (w = -1 x n, +1 x n) is

  sum_{d < 2n} mult_d rho_d(n) (beta_d W + D_d) - (Q1[2n-1] - 2 R[n-1] + 2 Q2[n-1])

(W = T - 2n + 1, mult_0 = 1 else 2, rho_d = 2n - 3d for d < n else d - 2n)
where D_d is the sum of the centred diagonal d, and, with the second-order
prefix sums H[x, d] = sum_{i < x} (x - i) F[i, d] of the centred corner
entries F[i, d] = c_d(i) + c_d(T - d - 1 - i) (top-left corner plus the
bottom-right one turned onto it),

  Q1[q] = sum_{x + d = q} mult_d sign(x - d) H[x, d]
  Q2[q] = sum_{x + d = q} mult_d H[x, d]
  R[x]  = sum_{d <= x} mult_d H[x, d]

(the three ramps of the weight of a corner entry, see avar.models.nonstationary).
The pass yields beta, D, Q1, Q2, R for d, q < 2 max(n); each scale then
costs O(n). NOAV sums the upper triangle of the disjoint diagonal blocks
row by row (each row of a block is two or three segment sums).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from avar._kernels.runtime.tasks import run_tasks

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


@njit(cache=True, nogil=True)
def _cov_task(task, c, beta, width, noav_ns, noav_scan, tile, split, far, asym, top, sums, acc, f, pre):
    """Task ``task`` (0: the top, walking down; 1: the bottom, walking up) of :func:`covariance_pass`."""
    t = c.shape[0]
    half = width // 2
    bits = c.view(np.int64)
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


class CovariancePass(NamedTuple):
    """What :func:`covariance_pass` finds: the checks of ``c`` and the MOAV / NOAV sums."""

    #: max |c - c.T| (meaningless if c is not finite).
    asym: float
    #: Bits of max |c| (as float64): >= 0x7FF0000000000000 iff c holds an infinite or NaN entry.
    top: int
    #: Diagonal centres, centred diagonal sums and corner sums, shape (width,) each (see above).
    beta: np.ndarray
    dp: np.ndarray
    q1: np.ndarray
    q2: np.ndarray
    rr: np.ndarray
    #: Sum over the disjoint blocks of ``w' C_s w``, one per NOAV scale.
    noav: np.ndarray


def covariance_pass(c, width, noav_ns, noav_scan, noav_width, tile=COV_TILE) -> CovariancePass:
    """Check ``c`` and gather the MOAV / NOAV sums, in one pass of two tasks on the threads.

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
    CovariancePass
        ``asym`` (float): max |c - c.T| (meaningless if c is not finite); ``top`` (int): bits
        of max |c| (as float64), >= 0x7FF0000000000000 iff c holds an infinite or NaN entry;
        ``beta, dp, q1, q2, rr`` (float64 arrays, shape (width,)): diagonal centres, centred
        diagonal sums and corner sums (see above); ``noav`` (float64 array, shape
        (len(noav_ns),)): sum over the disjoint blocks of ``w' C_s w``.

    Notes
    -----
    The top task checks the pairs (i < j) with i < split, j < far and takes
    rows [0, split); the bottom task the other pairs and rows. ``split`` is
    half the strips of ``tile`` rows and ``far`` three quarters, so that both
    check about T^2 / 4 pairs.
    """
    t = c.shape[0]
    d = np.arange(width)
    mid = (t - 1 - d) // 2
    beta = c[mid, mid + d].astype(np.float64)
    n_strips = -(-t // tile)
    split = min(t, (n_strips // 2) * tile)
    far = min(t, max(split, ((3 * n_strips + 2) // 4) * tile))
    asym = np.zeros(2)
    top = np.zeros(2, dtype=np.int64)
    sums = np.zeros((2, 6, max(width, 1)))
    # per-task rows at least a cache line apart (no false sharing)
    acc = np.zeros((2, noav_ns.shape[0] + 8))
    f = np.empty((2, width + 8))
    pre = np.empty((2, noav_width + 9))
    run_tasks(2, lambda task: _cov_task(task, c, beta, width, noav_ns, noav_scan, tile, split, far, asym, top, sums,
                                        acc, f, pre))
    n = noav_ns.shape[0]
    noav = acc[0, :n] + acc[1, :n]
    with np.errstate(over="ignore", invalid="ignore"):  # as in compiled code: an overflow is inf, caught later
        out = sums[0][[0, 3, 4, 5], :width] + sums[1][[0, 3, 4, 5], :width]
    return CovariancePass(float(max(asym[0], asym[1])), int(max(top[0], top[1])), beta, out[0], out[1], out[2], out[3],
                          noav)


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
