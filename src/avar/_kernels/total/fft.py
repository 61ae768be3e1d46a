"""FFT primitives of the fast Theo1 sums: the autocorrelation, two triangle-restricted products, Φ.

Theo1's expansion (see :mod:`avar._kernels.total.theo1`) needs, besides the
record's autocorrelation, sums over index pairs restricted to a triangle:

* :func:`hankel_lower`: ``out[g] = sum_{i<g} y[i] kappa[g + i]`` (a Hankel product
  over the lower triangle i < g);
* :func:`half_convolution`: ``out[m] = sum_{a<=b, a+b=m} f[a] g[b]`` (the half of a
  convolution with a <= b).

Both split the index range in halves: the pairs with one index in each half
form a full rectangle, summed by one FFT; the two halves recurse. Every node of
one depth has the same size, so each depth is one batched FFT, and blocks of
at most 128 indices are summed directly (numba). O(n log^2 n); each output errs
by about eps times the norms of the inputs, as an FFT convolution.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit
from scipy import fft

from avar._kernels.runtime.paths import numpy_path
from avar._kernels.total import theo1_numpy

#: The route of :func:`avar._kernels.runtime.paths.numpy_path` for the Hankel leaves.
_HANKEL_ROUTE = "total.hankel_leaves"
#: Leaf sizes of the recursion (5-smooth, so that every FFT size is fast).
LEAVES = (64, 72, 75, 80, 81, 90, 96, 100, 108, 120, 125, 128)


def autocorrelation(x: np.ndarray) -> np.ndarray:
    """F[L] = sum_{p=0}^{N-1-L} x_p x_{p+L}, L = 0 .. N - 1, by FFT."""
    n = x.shape[0]
    size = fft.next_fast_len(2 * n, real=True)
    spectrum = fft.rfft(x, size)
    return fft.irfft(spectrum.real**2 + spectrum.imag**2, size)[:n]


#: Fewest points of an FFT of :func:`short_autocorrelation` (shorter ones cost more per point).
_SHORT_FFT = 1 << 13


def short_autocorrelation(x: np.ndarray, count: int) -> np.ndarray:
    """F[L] = sum_{p=0}^{N-1-L} x_p x_{p+L} for L = 0 .. ``count`` - 1 only, in blocks.

    The points p go in blocks of B; a block's products are the correlation of its B points
    with the B + count - 1 from its start (0 past the end), one FFT of size >= B + count - 1
    each (all blocks in one batch), summed over the blocks in order. O(N log count) for
    count << N, against O(N log N) for :func:`autocorrelation`."""
    n = x.shape[0]
    count = min(int(count), n)
    size = fft.next_fast_len(max(4 * count, _SHORT_FFT), real=True)
    block = size - count + 1
    if 2 * block >= n:
        return autocorrelation(x)[:count]
    n_blocks = -(-n // block)
    extended = np.zeros(n_blocks * block + size)
    extended[:n] = x
    windows = np.lib.stride_tricks.as_strided(extended, (n_blocks, size), (block * extended.itemsize, extended.itemsize),
                                              writeable=False)
    heads = np.zeros((n_blocks, size))
    heads[:, :block] = extended[: n_blocks * block].reshape(n_blocks, block)
    spectrum = fft.rfft(windows, axis=1) * np.conj(fft.rfft(heads, axis=1))
    return fft.irfft(spectrum, size, axis=1)[:, :count].sum(axis=0)


class LeafBlocks(NamedTuple):
    """The recursion's layout: ``length = leaf * 2**k`` samples in leaves of ``leaf``."""

    leaf: int
    length: int


def leaf_blocks(count: int, leaves: tuple = LEAVES) -> LeafBlocks:
    """The smallest ``length = leaf * 2**k >= count`` over the leaf sizes ``leaves`` (:data:`LEAVES`).

    >>> leaf_blocks(1000), leaf_blocks(1000, (8, 9, 10))
    (LeafBlocks(leaf=125, length=1000), LeafBlocks(leaf=8, length=1024))
    """
    best = None
    for leaf in leaves:
        length = leaf
        while length < count:
            length *= 2
        if best is None or length < best.length:
            best = LeafBlocks(leaf, length)
    return best


def padded(values: np.ndarray, length: int) -> np.ndarray:
    """``values`` cut or padded with zeros to ``length``."""
    out = np.zeros(length)
    n = min(length, values.shape[0])
    out[:n] = values[:n]
    return out


@njit(cache=True, nogil=True)
def _hankel_leaves(y: np.ndarray, kappa: np.ndarray, out: np.ndarray, leaf: int) -> None:
    for start in range(0, out.shape[0], leaf):
        for g in range(start + 1, start + leaf):
            acc = 0.0
            for i in range(start, g):
                acc += y[i] * kappa[g + i]
            out[g] += acc


def hankel_lower(y: np.ndarray, kappa: np.ndarray, count: int) -> np.ndarray:
    """out[g] = sum_{i<g} y[i] kappa[g + i] for g = 0 .. count - 1 (missing values are 0).

    A node [s, s + S) adds, for g in its upper half, the products with every i of
    its lower half: a correlation of the reversed lower half of y with
    kappa[2s + S/2 .. 2s + 3S/2), of length S without wrapping into the outputs used."""
    leaf, length = leaf_blocks(count)
    yy = padded(y, length)
    kk = padded(kappa, 3 * length)
    out = np.zeros(length)
    if numpy_path(length * leaf, theo1_numpy.HANKEL_LIMIT, (_hankel_leaves,), route=_HANKEL_ROUTE):
        theo1_numpy.hankel_leaves(yy, kk, out, leaf)  # cold kernel: its NumPy twin, bit for bit
    else:
        _hankel_leaves(yy, kk, out, leaf)
    size = 2 * leaf
    while size <= length:
        half = size // 2
        nodes = length // size
        lower = yy.reshape(nodes, size)[:, :half][:, ::-1]
        window = kk[half : half + 2 * size * nodes].reshape(nodes, 2 * size)[:, :size]
        product = fft.irfft(fft.rfft(lower, size, axis=1) * fft.rfft(window, size, axis=1), size, axis=1)
        out.reshape(nodes, size)[:, half:] += product[:, half - 1 : size - 1]
        size *= 2
    return out[:count]


@njit(cache=True, nogil=True)
def _half_leaves(f: np.ndarray, g: np.ndarray, out: np.ndarray, leaf: int) -> None:
    for start in range(0, f.shape[0], leaf):
        for a in range(start, start + leaf):
            fa = f[a]
            for b in range(a, start + leaf):
                out[a + b] += fa * g[b]


def half_convolution(f: np.ndarray, g: np.ndarray, count: int) -> np.ndarray:
    """out[m] = sum_{a<=b, a+b=m} f[a] g[b] for m = 0 .. count - 1 (missing values are 0).

    A node [s, s + S) adds the full convolution of f over its lower half with g
    over its upper half (every a < b there) at m = 2s + S/2 .. 2s + 3S/2 - 2."""
    leaf, length = leaf_blocks(count)
    ff = padded(f, length)
    gg = padded(g, length)
    out = np.zeros(3 * length)
    _half_leaves(ff, gg, out, leaf)
    size = 2 * leaf
    while size <= length:
        half = size // 2
        nodes = length // size
        lower = ff.reshape(nodes, size)[:, :half]
        upper = gg.reshape(nodes, size)[:, half:]
        product = fft.irfft(fft.rfft(lower, size, axis=1) * fft.rfft(upper, size, axis=1), size, axis=1)
        out[half : half + 2 * size * nodes].reshape(nodes, 2 * size)[:, :size] += product
        size *= 2
    return out[:count]


#: The compiled kernel of the ends' autocorrelations (Theo1's expansion; TheoBR adds :func:`half_convolution`'s).
HANKEL_KERNELS = (_hankel_leaves,)
#: The compiled kernel of :func:`half_convolution`'s leaves (no NumPy twin here: TheoBR's has its own).
HALF_KERNELS = (_half_leaves,)


def phi_sums(z: np.ndarray, count: int) -> np.ndarray:
    """Φ(c) = sum_{j<c, j = c mod 2} 2 z_j / (c + j), c = 0 .. count - 1.

    Over each parity e (c = 2g + e, j = 2i + e) it is sum_{i<g} z_{2i+e} / (g + i + e):
    :func:`hankel_lower` with kappa[t] = 1 / (t + e)."""
    out = np.zeros(count)
    for parity in (0, 1):
        n = (count - parity + 1) // 2
        if n <= 0:
            continue
        t = np.arange(2 * n + 1, dtype=np.float64) + parity
        kappa = np.divide(1.0, t, out=np.zeros_like(t), where=t > 0)
        out[parity::2] = hankel_lower(z[parity::2], kappa, n)
    return out
