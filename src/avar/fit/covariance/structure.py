"""The covariance of the maximal-overlap AV estimates from the model's structure function: any N, flicker included.

The formula of :mod:`avar.fit.covariance.formula` needs gamma_jk, the
cross-covariance of the Allan-filtered series W_s(m) = (ybar_{s+m} - ybar_s) / sqrt(2).
Every term but the sinusoid has stationary increments, so gamma_jk follows from
the structure function D(k) = Var(y_{t+k} - y_t) of the whole model (the sum of
its terms')::

    Cov(y_a - y_b, y_c - y_d) = [D(a - d) + D(b - c) - D(a - c) - D(b - d)] / 2,
    sum_{i<L1} sum_{l<L2} D(c + i - l) = S2(c + L1 + 1) - S2(c + L1 - L2 + 1) - S2(c + 1) + S2(c - L2 + 1),

S2 the second cumulative sum of D, so gamma_jk(h) costs 16 reads of S2 at any m.
gamma is linear in D: the model's is the sum of its terms' scales times the
unit terms' gamma, which depend only on the log's length and grid and are
computed once for every channel. S2 of QN, WN, FN and RW is in closed form
(no table of the log's length); a Gauss-Markov term's is summed outward from 0 over its first correlation
times, in closed form beyond (:mod:`~avar.fit.covariance.markov`). The sum over h runs exactly near
the kinks of gamma_jk and c_jk and by the trapezoid rule on integer nodes in
between (the summand is smooth there), a few thousand evaluations per pair of
levels whatever N, to :data:`ACCURACY` of the levels' spread (the plain twin,
:mod:`avar.fit.covariance.exact`, sums every lag). The nodes within the
filters' reach depend only on the log's length and grid: laid once for every
model and channel of a log. A Gauss-Markov term's longer memory adds, per model,
:data:`NODES` trapezoid nodes on each side beyond that reach, where no kink
remains (one set of nodes stretched over both once left few nodes on a short
term's lags: 1.8 % off the plain sum with T = 14 and 3000 samples).

Tables of pure power laws (one noise type per level) misstate this covariance
where terms mix, which is where a sensor's random walk and bias instability are
read: the noise report's sandwich intervals (:mod:`avar.fit.report.uncertainty`)
take it for the fitted sum of processes itself.

Per-sample structure functions: QN 6 q2 at lag 1, 4 q2 beyond; WN 2 sigma2;
FN (4 b2 / pi) sum_{j<=k} 1 / (2 j - 1); RW gamma2 |k|; AR1 2 (c(0) - c(k)),
c(k) = phi^k / (1 - phi^2). DR contributes the mean mu_m = sqrt(omega2 / 2) m
of the ramp (its AV is omega2 m^2 / 2).

A sinusoid (SIN) of fixed amplitude and random phase is not Gaussian: its
share of a level's estimate hardly varies between records (a Gaussian line
would have a random amplitude and about one degree of freedom), so it is
left out of the covariance. Its cross terms with the noise,
(4 / M) sum_h gamma_noise(h) gamma_sin(h), are left out with it: they matter
only at the few levels the sinusoid dominates, where its own interval
(from the same sandwich) is then too narrow.

References
----------
D. B. Percival, A. T. Walden, Wavelet Methods for Time Series Analysis, 2000, ch. 8.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from avar.fit.covariance.formula import level_counts, pair_counts, summand
from avar.fit.covariance.markov import MarkovSums, markov_sums
from avar.fit.terms import Component, components_of

__all__ = ["structure_covariance", "structure_function", "MAX_EXACT_LEVELS", "ACCURACY"]

#: Error of the covariance relative to the levels' spread sigma_j sigma_k (the trapezoid rule between
#: the summand's kinks), within :data:`MAX_EXACT_LEVELS` levels.
ACCURACY = 1e-3

#: Integers summed exactly on each side of a kink of the summand.
DENSE = 24
#: Trapezoid nodes between two kinks.
NODES = 96
#: Levels computed pair by pair; a denser grid is interpolated from this many log-spaced ones.
MAX_EXACT_LEVELS = 40
#: Lags beyond the filters' reach kept for terms of infinite memory (flicker, Gauss-Markov), in filter lengths.
TAIL = 4


def structure_function(model: Any, size: int) -> np.ndarray:
    """D(k), k = 0..size, of the Gaussian terms of ``model`` (per-sample parameters; DR and SIN add nothing).

    >>> structure_function([Component("WN", 1.0), Component("RW", 0.5)], 3).tolist()
    [0.0, 2.5, 3.0, 3.5]
    """
    out = np.zeros(size + 1)
    for c in components_of(model):
        if c.kind in UNIT_KINDS:
            out += c.scale * _unit_structure(c.kind, size)
        elif c.kind == "AR1":
            k = np.arange(size + 1, dtype=np.float64)
            phi = float(c.shape)
            out += 2.0 * c.scale * (-np.expm1(k * math.log(phi))) / ((1.0 - phi) * (1.0 + phi))
        elif c.kind not in ("DR", "SIN"):
            raise ValueError(f"no structure function for a {c.kind!r} term")
    return out


#: Terms whose structure function is their scale times a fixed function of the lag.
UNIT_KINDS = ("QN", "WN", "FN", "RW")


def _unit_structure(kind: str, size: int) -> np.ndarray:
    out = np.zeros(size + 1)
    if kind == "QN":
        out[1:2], out[2:] = 6.0, 4.0
    elif kind == "WN":
        out[1:] = 2.0
    elif kind == "FN":  # (4 / pi) sum_{j<=k} 1 / (2 j - 1)
        out[1:] = np.cumsum(4.0 / (math.pi * (2.0 * np.arange(1, size + 1) - 1.0)))
    else:
        out[:] = np.arange(size + 1, dtype=np.float64)
    return out


def _second_sums(structure: np.ndarray) -> np.ndarray:
    """S2(x) for x = 0..R with S1(x + 1) - S1(x) = D(x), S2(x + 1) - S2(x) = S1(x), S1(0) = S2(0) = 0.

    Summed outward from 0, so values near 0 carry no rounding of large ones; D is
    even, so S2(-x) = S2(x + 2) for x > 0 and one side suffices.
    """
    s1 = np.concatenate([[0.0], np.cumsum(structure)])
    return np.concatenate([[0.0], np.cumsum(s1)])


def _s2(source: np.ndarray | str | MarkovSums, x: np.ndarray) -> np.ndarray:
    """S2 at integers x (D is even: S2(-x) = S2(x + 2)), from a table, a Gauss-Markov term's or a unit term's
    closed form."""
    folded = np.where(x < 0, 2 - x, x)
    if isinstance(source, str):
        return _unit_second_sums(source, folded)
    return source(folded) if isinstance(source, MarkovSums) else source[folded]


def _nodes(low: int, high: int, kinks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Integer nodes in [low, high] and weights w with sum_h F(h) ~ sum w F(node), F linear between nodes."""
    dense = (kinks[:, None] + np.arange(-DENSE, DENSE + 1)[None, :]).ravel()
    marks = np.unique(np.clip(np.concatenate([dense, [low, high]]), low, high))
    pieces = [marks]
    gaps = np.diff(marks)
    for a, g in zip(marks[:-1][gaps > 1], gaps[gaps > 1]):
        pieces.append(a + np.unique(np.linspace(0, g, min(NODES, g) + 1).round().astype(np.int64)))
    nodes = np.unique(np.concatenate(pieces))
    gap = np.diff(nodes).astype(np.float64)
    weights = np.ones(nodes.size)
    weights[:-1] += (gap - 1.0) / 2.0
    weights[1:] += (gap - 1.0) / 2.0
    return nodes, weights


def structure_covariance(model: Any, n: int, factors: np.ndarray) -> np.ndarray:
    """Gaussian covariance of the maximal-overlap AV estimates of a sum of terms at averaging ``factors``.

    Parameters
    ----------
    model : NoiseModel or sequence of processes or components
        The model's terms, per-sample parameters (:func:`avar.fit.terms.components_of`).
    n : int
        Series length N (samples).
    factors : ndarray of int
        Averaging factors m_j, 1 <= m_j <= (N - 1) / 2.

    Returns
    -------
    ndarray, shape (len(factors), len(factors))
        In the squared units of the Allan variance. Beyond :data:`MAX_EXACT_LEVELS`
        levels, the covariance relative to the model's AV, nu_j nu_k, is computed
        at that many log-spaced factors and interpolated in log m (it is smooth there).

    Examples
    --------
    White noise of unit variance: the lag-1 Allan variance of N samples has variance about 3 / N.

    >>> cov = structure_covariance([Component("WN", 1.0)], 10_000, np.array([1, 2]))
    >>> round(float(cov[0, 0]) * 10_000, 2)
    3.0
    """
    components = components_of(model)
    factors = np.asarray(factors, dtype=np.int64)
    if factors.size > MAX_EXACT_LEVELS:
        return _interpolated(components, n, factors)
    memory = any(c.kind in ("FN", "AR1") for c in components)
    # a Gauss-Markov term's covariance (phi^h) squared falls below 1e-6 of its start after this many lags
    memory_lags = max([math.ceil(7.0 / -math.log(c.shape)) for c in components if c.kind == "AR1"], default=0)
    key = (int(n), tuple(int(m) for m in factors), memory)
    plan = _lag_plan(*key)
    gamma = np.zeros(plan.h.size)
    for c in components:
        if c.kind in UNIT_KINDS:
            gamma += c.scale * _unit_gamma(key, c.kind)
    shaped = [c for c in components if c.kind == "AR1"]
    tail = _tail_plan(key, memory_lags) if memory_lags else None
    size = max(plan.size, tail.size if tail is not None else 0)
    markov = [markov_sums(c, size) for c in shaped]
    for term in markov:
        gamma += _gamma(term, plan)
    ramp = sum(c.scale for c in components if c.kind == "DR")
    mean2 = (ramp / 2.0) * plan.mj * plan.mk  # mu_j mu_k at every node, mu_m = sqrt(omega2 / 2) m
    totals = np.add.reduceat(plan.weights * summand(gamma, mean2), plan.starts)
    if tail is not None and tail.h.size:
        # beyond the filters' reach only the terms of infinite memory remain (WN, QN, RW: gamma is 0 there)
        far = np.zeros(tail.h.size)
        for term in markov:
            far += _gamma(term, tail)
        flicker = sum(c.scale for c in components if c.kind == "FN")
        if flicker:
            far += flicker * _gamma("FN", tail)
        pieces = tail.weights * summand(far, (ramp / 2.0) * tail.mj * tail.mk)
        totals = totals + np.bincount(tail.pair, weights=pieces, minlength=totals.size)
    out = np.empty((factors.size, factors.size))
    out[plan.j, plan.k] = out[plan.k, plan.j] = totals / plan.norms
    return out


@dataclass(frozen=True)
class _Plan:
    """The lags of every pair of levels: nodes h, their weights times pair counts, and the pairs' layout."""

    h: np.ndarray
    mj: np.ndarray
    mk: np.ndarray
    weights: np.ndarray
    starts: np.ndarray
    j: np.ndarray
    k: np.ndarray
    norms: np.ndarray
    size: int


def _pair_spans(n: int, m: np.ndarray, memory: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray,
                                                                    np.ndarray]:
    """Every pair of levels (j <= k): j, k, the lags' range [low, high] within the filters' reach and the counts."""
    counts = level_counts(n, m)
    j, k = np.triu_indices(m.size)
    span = 2 * (m[j] + m[k]) * (1 + TAIL) if memory else 2 * (m[j] + m[k]) + 2
    return j, k, np.maximum(1 - counts[j], -span), np.minimum(counts[k] - 1, span), counts


@functools.lru_cache(maxsize=4)
def _lag_plan(n: int, factors: tuple[int, ...], memory: bool) -> _Plan:
    """The nodes of :func:`structure_covariance` within the filters' reach, for one length and grid (shared by
    every channel of a log and every model on it; a Gauss-Markov term's longer memory is :func:`_tail_plan`'s)."""
    m = np.asarray(factors, dtype=np.int64)
    top = int(m.max())
    pair_j, pair_k, lows, highs, counts = _pair_spans(n, m, memory)
    reach = min(int(counts.max()), (2 + 2 * TAIL) * 2 * top if memory else 2 * top + 2)
    pieces = []
    for j, k, low, high in zip(pair_j.tolist(), pair_k.tolist(), lows.tolist(), highs.tolist()):
        mj, mk, count_j, count_k = int(m[j]), int(m[k]), int(counts[j]), int(counts[k])
        # s in 1..M_j and s + h in 1..M_k;
        # gamma's kinks: where an argument of S2 crosses 0; the pair count's: h = 0 and h = M_k - M_j
        shifts = np.array([mj, -mk, mj - mk, 0])
        ends = np.array([mj + 1, mj - mk + 1, 1, 1 - mk])
        kinks = np.concatenate([(shifts[:, None] + ends[None, :]).ravel(), [0, count_k - count_j]])
        h, weights = _nodes(low, high, kinks)
        pairs = pair_counts(count_j, count_k, h)
        pieces.append((j, k, h, weights * pairs, float(count_j) * float(count_k)))
    lengths = np.array([p[2].size for p in pieces])
    return _Plan(h=np.concatenate([p[2] for p in pieces]),
                 mj=np.repeat([int(m[p[0]]) for p in pieces], lengths),
                 mk=np.repeat([int(m[p[1]]) for p in pieces], lengths),
                 weights=np.concatenate([p[3] for p in pieces]),
                 starts=np.concatenate([[0], np.cumsum(lengths)[:-1]]),
                 j=np.array([p[0] for p in pieces]), k=np.array([p[1] for p in pieces]),
                 norms=np.array([p[4] for p in pieces]), size=reach + 4 * top + 4)


@dataclass(frozen=True)
class _Tail:
    """The lags beyond :func:`_lag_plan`'s reach that a Gauss-Markov memory adds: nodes h, weights times pair
    counts, the factors and the index of the pair each node belongs to."""

    h: np.ndarray
    mj: np.ndarray
    mk: np.ndarray
    weights: np.ndarray
    pair: np.ndarray
    size: int


@functools.lru_cache(maxsize=4)
def _tail_plan(key: tuple, memory_lags: int) -> _Tail:
    """Nodes of the lags from :func:`_lag_plan`'s reach out to ``memory_lags`` more on each side: no kink
    there, so the trapezoid rule on at most :data:`NODES` + 1 integer nodes per side, every pair at once."""
    n, factors, memory = key
    m = np.asarray(factors, dtype=np.int64)
    pair_j, pair_k, lows, highs, counts = _pair_spans(n, m, memory)
    pairs = np.arange(pair_j.size)
    # the left side [max(1 - M_j, low - lags), low - 1], then the right one [high + 1, min(M_k - 1, high + lags)]
    first = np.concatenate([np.maximum(1 - counts[pair_j], lows - memory_lags), highs + 1])
    last = np.concatenate([lows - 1, np.minimum(counts[pair_k] - 1, highs + memory_lags)])
    owner = np.concatenate([pairs, pairs])
    keep = last >= first
    first, last, owner = first[keep], last[keep], owner[keep]
    length = last - first
    per = np.minimum(NODES, length) + 1  # nodes per side
    side = np.repeat(np.arange(first.size), per)
    at = np.arange(side.size) - np.repeat(np.cumsum(per) - per, per)  # 0 .. per - 1 within each side
    steps = np.maximum(per - 1, 1)
    h = first[side] + np.rint(at * length[side] / steps[side]).astype(np.int64)
    ends = np.concatenate([[True], side[1:] != side[:-1]])  # a side's first node
    gap = np.diff(h).astype(np.float64)
    gap[ends[1:]] = 1.0  # no gap across two sides
    weights = np.ones(h.size)
    weights[:-1] += (gap - 1.0) / 2.0
    weights[1:] += (gap - 1.0) / 2.0
    j, k = pair_j[owner[side]], pair_k[owner[side]]
    top = int(m.max())
    reach = int(np.max(np.abs(h))) if h.size else 0
    return _Tail(h=h, mj=m[j], mk=m[k], weights=weights * pair_counts(counts[j], counts[k], h),
                 pair=owner[side], size=reach + 4 * top + 4)


@functools.lru_cache(maxsize=2 * len(UNIT_KINDS))  # one log's length and grid: shared by its channels
def _unit_gamma(key: tuple, kind: str) -> np.ndarray:
    """gamma_jk(h) at every node of the plan ``key`` for a unit term of ``kind``."""
    out = _gamma(kind, _lag_plan(*key))
    out.flags.writeable = False
    return out


def _gamma(s2: np.ndarray | str | MarkovSums, plan: _Plan | _Tail) -> np.ndarray:
    """gamma_jk(h) at the plan's nodes from S2 (a table, or the name of a unit term)."""
    mj, mk, h = plan.mj, plan.mk, plan.h
    total = (_phi(s2, mj - h, mj, mk) + _phi(s2, -h - mk, mj, mk) - _phi(s2, mj - mk - h, mj, mk)
             - _phi(s2, -h, mj, mk))
    return total / (4.0 * mj * mk)


def _unit_second_sums(kind: str, x: np.ndarray) -> np.ndarray:
    """S2(x), x >= 0 integers, of a unit term, in closed form (S2(x) = sum_{u<x-1} (x - 1 - u) D(u)).

    QN: 2 x (x - 2) (x >= 2); WN: (x - 1)(x - 2) (x >= 1); RW: x (x - 1)(x - 2) / 6;
    FN: [A (A - 2) O(x - 2) - 2 (A - 1)(x - 2) + (x - 2)^2] / (2 pi) (x >= 2), A = 2x - 1,
    O(k) = sum_{j<=k} 1 / (2j - 1) = (psi(k + 1/2) - psi(1/2)) / 2.

    >>> (_unit_second_sums("FN", np.array([3, 4])) * math.pi / 4).round(6).tolist()  # D(1) = 1, D(2) = 4 / 3
    [1.0, 3.333333]
    """
    x = np.asarray(x, dtype=np.float64)
    if kind == "QN":
        return np.where(x >= 2.0, 2.0 * x * (x - 2.0), 0.0)
    if kind == "WN":
        return np.where(x >= 1.0, (x - 1.0) * (x - 2.0), 0.0)
    if kind == "RW":
        return x * (x - 1.0) * (x - 2.0) / 6.0
    from scipy.special import digamma

    k = np.maximum(x - 2.0, 0.0)
    a = 2.0 * x - 1.0
    odd = 0.5 * (digamma(k + 0.5) - digamma(0.5))
    return np.where(x >= 2.0, (a * (a - 2.0) * odd - 2.0 * (a - 1.0) * k + k * k) / (2.0 * math.pi), 0.0)


def _interpolated(components: Sequence[Component], n: int, factors: np.ndarray) -> np.ndarray:
    """The covariance on a dense grid from :data:`MAX_EXACT_LEVELS` log-spaced levels.

    Relative to nu_j nu_k, it is interpolated linearly in (mean, distance) of the
    levels' log factors, where it is smooth (across the diagonal it has a kink).
    """
    from scipy.interpolate import LinearNDInterpolator

    anchors = np.unique(np.geomspace(factors.min(), factors.max(), MAX_EXACT_LEVELS).round().astype(np.int64))
    gaussian = [c for c in components if c.kind != "SIN"]

    def model_av(m: np.ndarray) -> np.ndarray:
        return np.sum([c.av(m) for c in gaussian], axis=0) if gaussian else np.ones(m.size)

    def coordinates(m: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        j, k = np.triu_indices(m.size)
        logs = np.log(m.astype(np.float64))
        return j, k, np.column_stack([(logs[j] + logs[k]) / 2.0, logs[k] - logs[j]])

    nu_anchor, nu = model_av(anchors), model_av(factors)
    relative = structure_covariance(components, n, anchors) / np.outer(nu_anchor, nu_anchor)
    aj, ak, known = coordinates(anchors)
    j, k, wanted = coordinates(factors)
    values = LinearNDInterpolator(known, relative[aj, ak])(wanted)
    out = np.empty((factors.size, factors.size))
    out[j, k] = out[k, j] = values
    return out * np.outer(nu, nu)


def _phi(s2: np.ndarray | str | MarkovSums, c: np.ndarray, l1: np.ndarray | int, l2: np.ndarray | int) -> np.ndarray:
    """sum_{i<l1} sum_{l<l2} D(c + i - l) for integer arrays c (l1, l2 arrays of the same shape, or ints)."""
    return _s2(s2, c + l1 + 1) - _s2(s2, c + l1 - l2 + 1) - _s2(s2, c + 1) + _s2(s2, c - l2 + 1)
