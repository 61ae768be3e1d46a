"""NumPy twins of the broken-line split's kernels, bit for bit: nothing to compile on a cold first call.

Theo1 of wandering phase (random-walk FM, say) takes its long levels through the split of
:mod:`avar._kernels.total.split`, whose three compiled loops (:func:`~avar._kernels.total.split.split_record`,
:func:`~avar._kernels.total.split.knot_profile`, :func:`~avar._kernels.total.split.crossing_terms`)
cost about 1.5 s of compilation in a process without numba's cache, for O(N) and O(m) work. While
they are cold (:func:`avar._kernels.runtime.paths.numpy_path`) the functions here answer instead:
every term is formed with the kernel's operations, each running sum by :func:`numpy.cumsum` from an
explicit zero (it adds in sequence, as the kernel's loop does, signs of zero included), and the
spikes of :func:`crossing_terms` by :func:`numpy.add.at` in the kernel's order, so the results are
the kernel's to the last bit (the tests compare them with ``==``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: Largest record (samples) :func:`knot_profile` takes while the kernel is cold: its products
#: (about 2 N of them) are formed at once, 32 MB at this size.
SPLIT_LIMIT = 1 << 21

#: Largest spike count (16 per ``a`` of every Theo1 level) :func:`crossing_terms` takes while cold.
CROSSING_LIMIT = 1 << 24


class SplitRecord(NamedTuple):
    """r, the inner knots and the slope changes there (as the kernel's tuple)."""

    rest: np.ndarray
    knots: np.ndarray
    kinks: np.ndarray


class CrossingTerms(NamedTuple):
    """X, G and the size of X's terms per level (as the kernel's tuple)."""

    cross: np.ndarray
    square: np.ndarray
    magnitude: np.ndarray


def _running(values: np.ndarray) -> np.ndarray:
    """``out[i] = 0 + values[0] + ... + values[i]``, added one by one from a zero (as a loop's ``s += v``)."""
    return np.cumsum(np.concatenate(([0.0], values)))[1:]


def split_record(x: np.ndarray, spacing: int) -> SplitRecord:
    """:func:`avar._kernels.total.split.split_record`: r, the inner knots and the slope changes."""
    n = x.shape[0]
    inner = max(0, (n - 1) // spacing - 1)
    knots = np.arange(inner + 2, dtype=np.int64) * spacing
    knots[inner + 1] = n - 1
    first, last = knots[:-1], knots[1:]
    base = x[first]
    slopes = (x[last] - base) / (last - first)
    t = np.arange(n)
    segment = np.minimum(t // spacing, inner)  # [k K, (k + 1) K) is segment k; the last one runs to N - 1
    r = (x - base[segment]) - slopes[segment] * (t - first[segment])
    return SplitRecord(r, knots[1 : inner + 1].copy(), slopes[1:] - slopes[:-1])


def knot_profile(r: np.ndarray, knots: np.ndarray, kinks: np.ndarray, reach: int) -> np.ndarray:
    """:func:`avar._kernels.total.split.knot_profile`: P(v) = sum_k beta_k r_{t_k + v}, the knots in order."""
    products = kinks[:, None] * r[(knots - reach + 1)[:, None] + np.arange(2 * reach - 1)]
    return np.cumsum(np.concatenate((np.zeros((1, 2 * reach - 1)), products)), axis=0)[-1]


def _moment(first: np.ndarray, lagged: np.ndarray, reach: int, j: int, top: int) -> tuple[float, float]:
    """:func:`avar._kernels.total.split._moment`, on Python floats (IEEE arithmetic, the same bits)."""
    upper = float(first[top + reach])
    lower = float(first[j + reach])
    upper1 = float(lagged[top + reach])
    lower1 = float(lagged[j + reach])
    return (upper1 - lower1) - j * (upper - lower), abs(upper1) + abs(lower1) + abs(j) * (abs(upper) + abs(lower))


#: (s, t) of the spikes of one ``a``, in the kernel's order, and their signs.
_S, _T = np.divmod(np.arange(16), 4)
_SIGNS = np.where((_S == 0) | (_S == 3), 1.0, -1.0) * np.where((_T == 0) | (_T == 3), 1.0, -1.0)


def crossing_terms(profile: np.ndarray, reach: int, kink_square: float, factors: np.ndarray,
                   allan: bool) -> CrossingTerms:
    """:func:`avar._kernels.total.split.crossing_terms`: X, G and the size of X's terms per level."""
    count = factors.shape[0]
    cross = np.zeros(count)
    square = np.zeros(count)
    magnitude = np.zeros(count)
    if allan:
        v = np.arange(2 * reach - 1) - reach + 1
        first = np.concatenate(([0.0], _running(profile)))
        lagged = np.concatenate(([0.0], _running(v * profile)))
    for level, m in enumerate(factors.tolist()):
        h = m // 2
        if allan:
            acc = 0.0
            size = 0.0
            for j, spike in ((0, 6.0), (h, -4.0), (-h, -4.0), (-m, 1.0)):
                moment, terms = _moment(first, lagged, reach, j, m - 1)
                acc += spike * moment
                size += abs(spike) * terms
            cross[level] = acc
            magnitude[level] = size
            square[level] = kink_square * (h * (h + 1.0) * (2.0 * h + 1.0) / 3.0 - h * h)
            continue
        a = np.arange(1, h + 1)
        w = 1.0 / a
        weight = _running(w * (a * (a + 1.0) * (2.0 * a + 1.0) / 3.0 + (m - 2.0 * a - 1.0) * a * a))[-1]
        points = np.stack((np.zeros_like(a), a, m - a, np.full_like(a, m)), axis=1)  # (0, a, b, m)
        spikes = np.zeros(2 * m + 1)
        np.add.at(spikes, (points[:, _S] - points[:, _T] + m).ravel(), (_SIGNS * w[:, None]).ravel())
        value = _running(_running(spikes[: 2 * m - 1]))  # c_m(v - m + 1) at index v
        terms = profile[reach - m : reach + m - 1] * value
        cross[level] = _running(terms)[-1]
        magnitude[level] = _running(np.abs(terms))[-1]
        square[level] = kink_square * weight
    return CrossingTerms(cross, square, magnitude)
