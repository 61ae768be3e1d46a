"""Independent reference implementations of the Allan variance for the tests.

Written straight from the formulas of DESIGN.md, with no cumulative-sum
tricks: plain O(N m) NumPy loops, and exact integer arithmetic.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np


def cluster_means(x: np.ndarray, m: int, starts) -> np.ndarray:
    """Mean of x[t:t+m] for each start t (one NumPy sum per window)."""
    return np.array([np.sum(x[t : t + m]) / m for t in starts], dtype=np.float64)


def allan_mo_loop(x, m: int) -> float:
    """Maximal overlap AV by the definition: every window of 2m samples."""
    x = np.asarray(x, dtype=np.float64)
    n = x.shape[0]
    means = cluster_means(x, m, range(n - m + 1))
    diffs = means[m:] - means[:-m]  # ybar_{t+m} - ybar_t, t = 0..N-2m
    return float(np.sum(diffs**2) / (2 * (n - 2 * m + 1)))


def allan_to_loop(x, m: int) -> float:
    """Tau overlap AV by the definition: consecutive disjoint cluster means."""
    x = np.asarray(x, dtype=np.float64)
    k = x.shape[0] // m
    means = cluster_means(x, m, range(0, k * m, m))
    diffs = np.diff(means)
    return float(np.sum(diffs**2) / (2 * (k - 1)))


def exact_allan(x, factors, type: str) -> list[float]:
    """AV in exact rational arithmetic over the float64 values of x.

    Every float64 is a dyadic rational, so x * 2**k is an integer for a
    common k; sums and squares are then exact Python integers.
    """
    values = [Fraction(float(v)) for v in np.asarray(x, dtype=np.float64)]
    denominator = max(v.denominator for v in values)
    ints = np.array([int(v * denominator) for v in values], dtype=object)
    cumulative = np.concatenate([np.array([0], dtype=object), np.cumsum(ints)])
    n = len(values)
    out = []
    for m in map(int, factors):
        if type == "mo":
            b = np.arange(n - 2 * m + 1)
        else:
            b = np.arange(n // m - 1) * m
        d = cumulative[b + 2 * m] - 2 * cumulative[b + m] + cumulative[b]
        total = sum(int(v) * int(v) for v in d)
        out.append(float(Fraction(total, 2 * m * m * len(b) * denominator * denominator)))
    return out
