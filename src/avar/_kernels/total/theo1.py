"""Theo1 at a few even factors in O(N log N + m log m) per level (FFT and numba).

With h = m / 2, n = N - m, w_a = 1 / a and b = m - a, Theo1's double sum is
S = sum_{a=1}^{h} w_a V(a, b), V(a, b) = sum_{i<n} (x_i - x_{i+a} - x_{i+b} + x_{i+m})^2.
Expanded with the record's autocorrelation F and the partial lag sums
Pre(L, P) = sum_{j<P} x_j x_{j+L} at the head (and Suf, the same at the tail:
Pre of the reversed record x~)::

    V(a, b) = squares + 2 [F(m) + F(b - a) - 2 F(a) - 2 F(b)
                           + Pre(a, b) + Pre(b, a) - Pre(b - a, a) + (the same with Suf)]

The head sums over a are, with AC_k the autocorrelation of x[:k]:

* sum_a w_a [Pre(a, b) + Pre(b, a)] = sum_{l<m} AC_m(l) / min(l, m - l) (l = h twice);
* E3 = sum_a w_a Pre(m - 2a, a), the pairs p <= q, p + q < m, q - p even with weight
  2 / (m - q + p): split at q = h into sum_{c=1}^{h} x_{m-c} Φ(c) (Φ of
  :func:`avar._kernels.total.fft.phi_sums`, once for every level) and
  sum_{l even < h} 2 AC_h(l) / (m - l).

So a level costs two FFT autocorrelations of each end and O(m) sums. The
expansion loses digits where the terms are much larger than S (strongly
correlated phase at small m): :func:`theo1_expanded` returns that ratio, and
:func:`theo1_sums` gives such levels to :func:`split_sums`, the same expansion
of the record less a broken line (:mod:`avar._kernels.total.split`: the terms
then scale with the wander between knots about m apart, not over the record),
and sums directly only a level that is ill-conditioned even so. No validation;
gap-free, detrended x.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit
from scipy import fft

from avar._kernels.runtime.paths import numpy_path
from avar._kernels.total import theo1_numpy
from avar._kernels.total.fft import autocorrelation, phi_sums, short_autocorrelation
from avar._kernels.total.split import combine, groups, split_parts
from avar._kernels.total.theobr import lag_diagonals, oavar_expanded, theo1_every

#: Levels with fewer inner terms than this are summed directly (cheaper than the FFTs).
DIRECT_TERMS = 1 << 22
#: From this many long levels on, they come from :func:`avar._kernels.total.theobr.theo1_every` (every
#: even m up to the largest at once) rather than level by level.
EVERY_LEVELS = 64
#: Above this ratio of the expansion's largest terms to the result it may have lost
#: more than about 1e-11 (relative): the level is summed directly instead.
MAX_RATIO = 1e4
#: A split group of :func:`theo1_sums` takes the factors down to 1 / SPLIT_REACH of its knot spacing
#: (random-walk FM: ratio about 5 at the spacing, 1e3 at 1 / 8 of it).
SPLIT_REACH = 8


class Expanded(NamedTuple):
    """One level's double sum by the expansion and its ratio of the largest terms to it (:func:`theo1_expanded`)."""

    total: float
    ratio: float


class SplitSums(NamedTuple):
    """Theo1's and the overlapping Allan double sums through the split (:func:`split_sums`), with
    each one's ratio of the expansion's largest terms to it."""

    theo1: np.ndarray
    theo1_ratios: np.ndarray
    allan: np.ndarray
    allan_ratios: np.ndarray


class Theo1Sums(NamedTuple):
    """Theo1's double sums at every level (:func:`theo1_sums`)."""

    sums: np.ndarray
    #: How many levels took an expansion (whole or split) rather than the direct sum.
    n_expanded: int


@njit(cache=True)
def _plain_parts(x: np.ndarray, reverse: np.ndarray, squares: np.ndarray, autocorr: np.ndarray,
                 phi: np.ndarray, phi_reverse: np.ndarray, m: int) -> tuple[float, float, float]:
    """Level m's square terms, its F terms (2 [...] above) and sum_{c<=h} x_{m-c} Φ(c) of both ends."""
    n_points = x.shape[0]
    n = n_points - m
    h = m // 2
    weight = 0.0
    square = 0.0
    lags = 0.0
    ends = 0.0
    for a in range(1, h + 1):
        w = 1.0 / a
        b = m - a
        weight += w
        square += w * (squares[n + a] - squares[a] + squares[n + b] - squares[b])
        lags += w * (autocorr[m - 2 * a] - 2.0 * autocorr[a] - 2.0 * autocorr[b])
        ends += x[b] * phi[a] + reverse[b] * phi_reverse[a]
    square += weight * (squares[n] + squares[n_points] - squares[m])
    lags += weight * autocorr[m]
    return square, lags, ends


@njit(cache=True)
def _weighted_lags(long: np.ndarray, short: np.ndarray, m: int) -> tuple[float, float]:
    """sum_{0<l<m} long[l] / min(l, m - l) (l = h twice) and sum_{l even < h} 2 short[l] / (m - l)."""
    h = m // 2
    first = 2.0 * long[h] / h
    for lag in range(1, h):
        first += (long[lag] + long[m - lag]) / lag
    second = 0.0
    for lag in range(0, h, 2):
        second += 2.0 * short[lag] / (m - lag)
    return first, second


#: The compiled kernels of the expansion (while they are cold, short records take a NumPy twin of
#: the whole sum, :func:`avar.stability.total.small.theo1_level_sums`, and long ones these
#: kernels' twins, :mod:`avar._kernels.total.theo1_numpy`).
THEO1_KERNELS = (_plain_parts, _weighted_lags)
#: The route of :func:`avar._kernels.runtime.paths.numpy_path` (found compiled once, never asked again).
_ROUTE = "total.theo1_expanded"


def _end_autocorrelation(x: np.ndarray, reverse: np.ndarray, k: int) -> np.ndarray:
    """AC_k of the head plus AC_k of the tail (one inverse FFT for both)."""
    size = fft.next_fast_len(2 * k, real=True)
    head = fft.rfft(x[:k], size)
    tail = fft.rfft(reverse[:k], size)
    return fft.irfft(head.real**2 + head.imag**2 + tail.real**2 + tail.imag**2, size)[:k]


def prepare(x: np.ndarray, h_max: int, autocorr: np.ndarray | None = None) -> tuple:
    """What every level shares: x reversed, running sum of x^2, F (``autocorr`` if given), Φ of
    both ends up to ``h_max``."""
    reverse = np.ascontiguousarray(x[::-1])
    squares = np.concatenate(([0.0], np.cumsum(x * x)))
    autocorr = autocorrelation(x) if autocorr is None else autocorr
    return (x, reverse, squares, autocorr, phi_sums(x, h_max + 1), phi_sums(reverse, h_max + 1))


def theo1_expanded(prepared: tuple, m: int) -> Expanded:
    """Theo1's double sum at even m (see the module) and the ratio of the expansion's largest
    terms (the square terms, or sum(x^2) sum w_a) to it: the result has about ``eps * ratio``
    relative error. ``prepared``: :func:`prepare` with h_max >= m / 2."""
    x, reverse, squares, autocorr, phi, phi_reverse = prepared
    cold = numpy_path(m, theo1_numpy.PARTS_LIMIT, THEO1_KERNELS, route=_ROUTE)  # NumPy's twins, bit for bit, while cold
    parts, lags_of = (theo1_numpy.plain_parts, theo1_numpy.weighted_lags) if cold else (_plain_parts, _weighted_lags)
    square, lags, ends = parts(x, reverse, squares, autocorr, phi, phi_reverse, m)
    pairs, corners = lags_of(_end_autocorrelation(x, reverse, m), _end_autocorrelation(x, reverse, m // 2), m)
    total = square + 2.0 * lags + 2.0 * pairs - 2.0 * (ends + corners)
    weight = float(np.sum(1.0 / np.arange(1, m // 2 + 1)))
    ratio = max(square, weight * squares[-1]) / total if total > 0 else np.inf
    return Expanded(total, ratio)


def split_sums(x: np.ndarray, factors: np.ndarray, reach: float,
               allan: np.ndarray | None = None, every=theo1_every) -> SplitSums:
    """Theo1's double sums at the even ``factors`` by the broken-line split of
    :mod:`avar._kernels.total.split` and each one's ratio (as :func:`theo1_expanded`), then the
    overlapping Allan sums at the factors ``allan`` (span 2m; none by default) and their ratios
    (as :func:`avar._kernels.total.theobr.oavar_expanded`).

    The spans go in groups (:func:`avar._kernels.total.split.groups`): one split per group, its
    knot spacing the group's largest span, S(r) by :func:`theo1_expanded` per level or, for
    :data:`EVERY_LEVELS` Theo1 levels or more, by :func:`avar._kernels.total.theobr.theo1_every`; F of r
    only up to the spacing (:func:`avar._kernels.total.fft.short_autocorrelation`). ``every``: the
    function of :func:`~avar._kernels.total.theobr.theo1_every`'s signature that sums a group's levels
    at once (a NumPy twin's, while the kernels are cold)."""
    factors = np.asarray(factors, dtype=np.int64)
    allan = np.zeros(0, dtype=np.int64) if allan is None else np.asarray(allan, dtype=np.int64)
    spans = np.concatenate((factors, 2 * allan))
    sums = np.empty(spans.size)
    ratios = np.empty(spans.size)
    for spacing, members in groups(spans, reach):
        parts = split_parts(x, spacing)
        r = parts.rest
        autocorr = short_autocorrelation(r, spacing + 1)  # lags up to the spacing only
        theo, pairs = members[members < factors.size], members[members >= factors.size]
        diagonals = None
        if theo.size >= EVERY_LEVELS or pairs.size:
            diagonals = lag_diagonals(r, np.ascontiguousarray(r[::-1]), spacing // 2 + 1)
        if theo.size >= EVERY_LEVELS:
            every_level = every(r, spacing, autocorr, diagonals)
            rest, rest_ratio = every_level.sums[spans[theo]], every_level.ratios[spans[theo]]
        elif theo.size:
            prepared = prepare(r, spacing // 2, autocorr)
            rest, rest_ratio = np.array([theo1_expanded(prepared, int(m)) for m in spans[theo]]).reshape(-1, 2).T
        if theo.size:
            sums[theo], ratios[theo] = combine(rest, rest_ratio, parts, spacing, spans[theo])
        if pairs.size:
            rest, rest_ratio = oavar_expanded(r, spans[pairs] // 2, autocorr, diagonals)
            sums[pairs], ratios[pairs] = combine(rest, rest_ratio, parts, spacing, spans[pairs], allan=True)
    return SplitSums(sums[: factors.size], ratios[: factors.size], sums[factors.size :], ratios[factors.size :])


def theo1_sums(x: np.ndarray, factors: np.ndarray, direct,
               autocorr: np.ndarray | None = None) -> Theo1Sums:
    """Theo1's double sums of gap-free ``x`` at the even ``factors``: directly (``direct(x, m)``)
    where that is cheap, else by :func:`theo1_expanded` (or :func:`avar._kernels.total.theobr.theo1_every`
    for :data:`EVERY_LEVELS` levels or more); a level whose ratio exceeds :data:`MAX_RATIO` by
    :func:`split_sums` instead, and directly if it still does. ``autocorr``: x's
    :func:`~avar._kernels.total.fft.autocorrelation` if the caller has it. Returns the sums and
    how many levels took an expansion (whole or split)."""
    n_points = x.shape[0]
    sums = np.empty(factors.shape[0])
    long = np.array([(n_points - m) * (m // 2) > DIRECT_TERMS for m in factors.tolist()], dtype=bool)
    every = None
    if long.sum() >= EVERY_LEVELS:
        largest = int(factors[long].max())
        diagonals = lag_diagonals(x, np.ascontiguousarray(x[::-1]), largest // 2 + 1)
        every = theo1_every(x, largest, autocorrelation(x) if autocorr is None else autocorr, diagonals)
    elif long.any():
        prepared = prepare(x, int(factors[long].max()) // 2, autocorr)
    expanded = 0
    retry = []
    for level, m in enumerate(factors.tolist()):
        if long[level]:
            total, ratio = (every.sums[m], every.ratios[m]) if every is not None else theo1_expanded(prepared, m)
            if ratio <= MAX_RATIO:
                sums[level] = total
                expanded += 1
            else:
                retry.append(level)
            continue
        sums[level] = direct(x, m)
    if retry:
        split = split_sums(x, factors[retry], SPLIT_REACH)
        for level, total, ratio in zip(retry, split.theo1.tolist(), split.theo1_ratios.tolist()):
            if ratio <= MAX_RATIO:
                sums[level] = total
                expanded += 1
            else:
                sums[level] = direct(x, int(factors[level]))
    return Theo1Sums(sums, expanded)
