"""Theo1's double sums kept well conditioned on wandering phase: a broken line taken out first.

Theo1's sum at even m (h = m / 2, b = m - a, w_a = 1 / a, n = N - m)::

    S(x) = sum_{a=1}^{h} w_a sum_{i<n} d_a(i)^2,   d_a(i) = x_i - x_{i+a} - x_{i+b} + x_{i+m},

expanded by FFT over the whole record (:mod:`avar._kernels.total.theo1`,
:mod:`avar._kernels.total.theobr`), loses digits when x wanders far more than d: its
terms grow with x^2, about (N / m)^3 times S on random-walk FM phase. d
annihilates lines (so does the overlapping Allan sum, sum_i (x_i - 2 x_{i+m} + x_{i+2m})^2:
the single term a = b = m of Theo1's at 2m, weight 1), so x is split as x = g + r, g the broken line through x at
the knots t_0 = 0, t_k = k K (k = 1 .. J, the last at least K before the end)
and t_{J+1} = N - 1, with slope changes beta_k at the inner knots::

    g(t) = x_0 + s_0 t + sum_{k=1}^{J} beta_k (t - t_k)_+.

r = x - g is the record less its chords: of the scale of the wander over K
points, not N. With K >= m a span (i, i + m) holds at most one knot, and the
kink (t - t_k)_+ gives d_a(i) = e_a(t_k - i), the trapezoid
e_a(u) = min(u, a, m - u) for 0 < u < m (0 elsewhere). Hence, exactly::

    S(x) = S(r) + 2 X + G,
    X = sum_{|v|<m} P(v) c_m(v),     P(v) = sum_k beta_k r_{t_k + v},
    c_m(v) = sum_a w_a sum_{s in (0, a, b, m)} sigma_s e_a(s - v),   sigma = (1, -1, -1, 1),
    G = sum_k beta_k^2 sum_a w_a E_a,   E_a = sum_u e_a(u)^2 = a (a + 1) (2 a + 1) / 3 + (m - 2 a - 1) a^2.

S(r) is the FFT expansion again, on r: its terms are now about (K / m)^3 times
S on random-walk FM (measured: ratio about 5 at K = m, 200 to 400 at K = 4 m,
1e4 at K = 16 m). c_m's second difference is 16 spikes per a (at v = s - t,
weight w_a sigma_s sigma_t), so a level's X and G cost O(m) and the profile P
O(N) for every level of one K. No validation; gap-free x of N >= 2 points.

Rounding: r_t = (x_t - x_{t_k}) - s_k (t - t_k) errs by about eps times the
local wander, not eps |x|; X and G sum terms of the size of S.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from avar._kernels.runtime.paths import numpy_path
from avar._kernels.total import split_numpy


class ExpandedSums(NamedTuple):
    """Double sums computed by an expansion, and each one's ratio of the expansion's largest terms
    to it: the sum has about ``eps * ratio`` relative error (inf where the sum is not > 0)."""

    sums: np.ndarray
    ratios: np.ndarray


class SplitParts(NamedTuple):
    """What the levels m <= K of one knot spacing K share (:func:`split_parts`)."""

    #: r = x less its broken line (:func:`split_record`).
    rest: np.ndarray
    #: P(v) = sum_k beta_k r_{t_k + v}, v = -(K - 1) .. K - 1 (:func:`knot_profile`).
    profile: np.ndarray
    #: sum_k beta_k^2.
    kink_square: float


@njit(cache=True)
def split_record(x: np.ndarray, spacing: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """r = x less the broken line through x at the knots 0, K, 2K, ..., N - 1 (K = ``spacing``,
    the last inner knot at least K before N - 1): r, the inner knots t_k and the slope changes
    beta_k there (slope after the knot less slope before)."""
    n = x.shape[0]
    inner = max(0, (n - 1) // spacing - 1)
    knots = np.empty(inner + 2, dtype=np.int64)
    for k in range(inner + 1):
        knots[k] = k * spacing
    knots[inner + 1] = n - 1
    r = np.empty(n)
    slopes = np.empty(inner + 1)
    for k in range(inner + 1):
        first = knots[k]
        last = knots[k + 1]
        base = x[first]
        slope = (x[last] - base) / (last - first)
        slopes[k] = slope
        for t in range(first, last + 1):  # the knot ``last`` is 0 again from the next segment on
            r[t] = (x[t] - base) - slope * (t - first)
    kinks = np.empty(inner)
    for k in range(inner):
        kinks[k] = slopes[k + 1] - slopes[k]
    return r, knots[1 : inner + 1].copy(), kinks


@njit(cache=True)
def knot_profile(r: np.ndarray, knots: np.ndarray, kinks: np.ndarray, reach: int) -> np.ndarray:
    """P(v) = sum_k beta_k r_{t_k + v} for v = -(reach - 1) .. reach - 1 (at index v + reach - 1);
    every knot must lie at least ``reach`` - 1 points inside r."""
    profile = np.zeros(2 * reach - 1)
    for k in range(knots.shape[0]):
        beta = kinks[k]
        start = knots[k] - reach + 1
        for v in range(2 * reach - 1):
            profile[v] += beta * r[start + v]
    return profile


@njit(cache=True)
def _moment(first: np.ndarray, lagged: np.ndarray, reach: int, j: int, top: int) -> tuple[float, float]:
    """T(j) = sum_{v=j+1}^{top} (v - j) P(v) from the running sums of P and v P (``first``,
    ``lagged``: sums up to v at index v + reach), and the size of its four terms."""
    upper = first[top + reach]
    lower = first[j + reach]
    upper1 = lagged[top + reach]
    lower1 = lagged[j + reach]
    return (upper1 - lower1) - j * (upper - lower), abs(upper1) + abs(lower1) + abs(j) * (abs(upper) + abs(lower))


@njit(cache=True)
def crossing_terms(profile: np.ndarray, reach: int, kink_square: float, factors: np.ndarray,
                   allan: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """X, G (module docstring) and the size of X's terms at each even factor m <= ``reach``;
    ``profile``: :func:`knot_profile` with this ``reach``; ``kink_square`` = sum_k beta_k^2.

    Theo1: c_m from its spikes by two running sums, X = sum_v P(v) c_m(v), O(m) per level.
    ``allan``: the overlapping Allan sums at m / 2 (the single a = h = m / 2, weight 1), whose
    spikes are 6 at 0, -4 at +-h and 1 at +-m: X = sum_j spike_j T(j), T(j) = sum_{j<v<m} (v - j) P(v)
    from the running sums of P and v P, O(1) per level."""
    count = factors.shape[0]
    cross = np.zeros(count)
    square = np.zeros(count)
    magnitude = np.zeros(count)
    first = np.zeros(2 * reach)
    lagged = np.zeros(2 * reach)
    if allan:
        for index in range(2 * reach - 1):
            v = index - reach + 1
            first[index + 1] = first[index] + profile[index]
            lagged[index + 1] = lagged[index] + v * profile[index]
    for level in range(count):
        m = factors[level]
        h = m // 2
        if allan:
            acc = 0.0
            size = 0.0
            for j, spike in ((0, 6.0), (h, -4.0), (-h, -4.0), (-m, 1.0)):  # T(m) = 0
                moment, terms = _moment(first, lagged, reach, j, m - 1)
                acc += spike * moment
                size += abs(spike) * terms
            cross[level] = acc
            magnitude[level] = size
            square[level] = kink_square * (h * (h + 1.0) * (2.0 * h + 1.0) / 3.0 - h * h)
            continue
        spikes = np.zeros(2 * m + 1)  # at v + m, v = -m .. m
        weight = 0.0
        for a in range(1, h + 1):
            w = 1.0 / a
            b = m - a
            weight += w * (a * (a + 1.0) * (2.0 * a + 1.0) / 3.0 + (m - 2.0 * a - 1.0) * a * a)
            points = (0, a, b, m)
            for s in range(4):
                for t in range(4):
                    sign = 1.0 if (s == 0 or s == 3) == (t == 0 or t == 3) else -1.0
                    spikes[points[s] - points[t] + m] += sign * w
        slope = 0.0
        value = 0.0  # c_m(v), 0 at v = -m
        acc = 0.0
        size = 0.0
        offset = reach - 1 - m  # P(v) at index v + m + offset
        for v in range(2 * m - 1):  # value becomes c_m(v - m + 1)
            slope += spikes[v]
            value += slope
            term = profile[v + 1 + offset] * value
            acc += term
            size += abs(term)
        cross[level] = acc
        magnitude[level] = size
        square[level] = kink_square * weight
    return cross, square, magnitude


#: The compiled loops of :func:`split_parts` and of :func:`combine` (while they are cold, their
#: NumPy twins answer: :mod:`avar._kernels.total.split_numpy`), and their routes for
#: :func:`avar._kernels.runtime.paths.numpy_path` (found compiled once, never asked again).
SPLIT_KERNELS = (split_record, knot_profile)
CROSSING_KERNELS = (crossing_terms,)
_SPLIT_ROUTE = "total.split_parts"
_CROSSING_ROUTE = "total.crossing_terms"


def split_parts(x: np.ndarray, spacing: int) -> SplitParts:
    """r of :func:`split_record` at knot spacing K = ``spacing``, the profile P (reach K) and
    sum_k beta_k^2: all that the levels m <= K share."""
    cold = numpy_path(x.shape[0], split_numpy.SPLIT_LIMIT, SPLIT_KERNELS, route=_SPLIT_ROUTE)
    record, profile = (split_numpy.split_record, split_numpy.knot_profile) if cold else (split_record, knot_profile)
    r, knots, kinks = record(x, int(spacing))
    return SplitParts(r, profile(r, knots, kinks, int(spacing)), float(kinks @ kinks))


def combine(rest: np.ndarray, rest_ratio: np.ndarray, parts: SplitParts, spacing: int, factors: np.ndarray,
            allan: bool = False) -> ExpandedSums:
    """S(x) = S(r) + 2 X + G at ``factors`` (each <= ``spacing``) from S(r) (``rest``) and its ratio,
    and the ratio of the largest terms to S(x): ratio(r) S(r) + 2 |X's terms| + G, over S(x).
    ``allan``: the overlapping Allan sums at ``factors`` / 2 instead (:func:`crossing_terms`)."""
    factors = np.ascontiguousarray(factors, dtype=np.int64)
    spikes = (lambda: 4 * len(factors)) if allan else (lambda: 8 * int(np.sum(factors)))  # 16 per a <= m / 2
    cold = numpy_path(spikes, split_numpy.CROSSING_LIMIT, CROSSING_KERNELS, route=_CROSSING_ROUTE)
    cross, square, magnitude = (split_numpy.crossing_terms if cold else crossing_terms)(
        parts.profile, int(spacing), parts.kink_square, factors, bool(allan))
    total = rest + 2.0 * cross + square
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        terms = rest_ratio * np.abs(rest) + 2.0 * magnitude + square
        ratio = np.where((total > 0) & np.isfinite(terms), terms / total, np.inf)
    return ExpandedSums(total, ratio)


class SplitGroup(NamedTuple):
    """Factors that share one split (:func:`groups`)."""

    #: The knot spacing K: the group's largest factor.
    spacing: int
    #: Indices of the group's factors m, K / reach < m <= K.
    members: np.ndarray


def groups(factors: np.ndarray, reach: float) -> list[SplitGroup]:
    """The factors' :class:`SplitGroup` s, largest first: the spacing K and the indices of the
    factors m with K / ``reach`` < m <= K, K the group's largest factor."""
    order = np.argsort(-np.asarray(factors), kind="stable")
    out = []
    start = 0
    while start < order.size:
        spacing = int(factors[order[start]])
        stop = start
        while stop < order.size and factors[order[stop]] * reach > spacing:
            stop += 1
        out.append(SplitGroup(spacing, order[start:stop]))
        start = stop
    return out
