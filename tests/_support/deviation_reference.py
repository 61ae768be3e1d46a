"""Plain references of the deviation family for the tests: loops over the NIST SP 1065 formulas.

``exact_variance`` works in exact rational arithmetic (``fractions.Fraction``) on the float64
values, so it is the true value of the statistic of the data as given; ``fsum_variance`` is the
same loop in ``math.fsum`` arithmetic, fast enough for a few thousand points.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np


def phase_of(data, data_type: str, number=Fraction):
    """Phase points (0, cumsum(y)) or the data, and a test of whether a term avoids every gap.

    Phase data: a term is valid when none of its points is missing. Frequency
    data (NaN taken as 0 in the sum): when no missing value lies between its
    first and its last point.
    """
    raw = np.asarray(data, dtype=np.float64)
    missing = np.isnan(raw)
    values = [number(0) if gap else number(float(v)) for v, gap in zip(raw, missing)]
    if data_type == "phase":
        return values, lambda points: not any(missing[p] for p in points)
    x = [number(0)]
    for v in values:
        x.append(x[-1] + v)
    return x, lambda points: not missing[min(points) : max(points)].any()


def terms(estimator: str, x: list, m: int, valid) -> list:
    """The list of terms of one level (None for a term that touches a gap)."""
    n = len(x)

    def combo(points):
        if not valid([p for p, _ in points]):
            return None
        return sum((c * x[p] for p, c in points), start=0 * x[points[0][0]])

    if estimator in ("adev", "oadev"):
        step = m if estimator == "adev" else 1
        count = (n - 1) // m - 1 if estimator == "adev" else n - 2 * m
        return [combo([(k * step, 1), (k * step + m, -2), (k * step + 2 * m, 1)]) for k in range(count)]
    if estimator in ("hdev", "ohdev"):
        step = m if estimator == "hdev" else 1
        count = (n - 1) // m - 2 if estimator == "hdev" else n - 3 * m
        return [combo([(k * step, -1), (k * step + m, 3), (k * step + 2 * m, -3), (k * step + 3 * m, 1)])
                for k in range(count)]
    if estimator in ("mdev", "tdev"):
        out = []
        for j in range(n - 3 * m + 1):
            parts = [c * x[i] for i, c in _mdev_points(j, m)]
            out.append(sum(parts[1:], start=parts[0]) if valid([i for i, _ in _mdev_points(j, m)]) else None)
        return out
    if estimator in ("mhdev", "htdev"):
        out = []
        for j in range(n - 4 * m + 1):
            points = _mhdev_points(j, m)
            parts = [c * x[i] for i, c in points]
            out.append(sum(parts[1:], start=parts[0]) if valid([i for i, _ in points]) else None)
        return out
    # totdev: reflection at both ends, terms centred on points 1..N-2 (0-based)
    last = n - 1

    def star(j):
        if j < 0:
            return [(0, 2), (-j, -1)]
        if j > last:
            return [(last, 2), (2 * last - j, -1)]
        return [(j, 1)]

    out = []
    for i in range(1, n - 1):
        points = star(i - m) + [(i, -2)] + star(i + m)
        out.append(combo(points))
    return out




def _mdev_points(j: int, m: int) -> list:
    """Points and coefficients of MDEV's term j: sum_{i=j}^{j+m-1} (x_{i+2m} - 2 x_{i+m} + x_i)."""
    weights: dict[int, int] = {}
    for i in range(j, j + m):
        for p, c in ((i, 1), (i + m, -2), (i + 2 * m, 1)):
            weights[p] = weights.get(p, 0) + c
    return [(p, weights.get(p, 0)) for p in range(j, j + 3 * m)]


def _mhdev_points(j: int, m: int) -> list:
    """Points and coefficients of MHDEV's term j: sum_{i=j}^{j+m-1} (x_{i+3m} - 3 x_{i+2m} + 3 x_{i+m} - x_i)."""
    weights: dict[int, int] = {}
    for i in range(j, j + m):
        for p, c in ((i, -1), (i + m, 3), (i + 2 * m, -3), (i + 3 * m, 1)):
            weights[p] = weights.get(p, 0) + c
    return [(p, weights.get(p, 0)) for p in range(j, j + 4 * m)]


#: Denominator constant K of sigma^2 = sum / (K tau^2 n) (the modified ones also / m^2), and the time
#: deviations' tau^2 / factor.
_K = {"hdev": 6, "ohdev": 6, "mhdev": 6, "htdev": 6}
_MODIFIED = ("mdev", "tdev", "mhdev", "htdev")
_TIME = {"tdev": Fraction(3), "htdev": Fraction(10, 3)}


def exact_variance(estimator: str, data, m: int, data_type: str = "phase", rate: float = 1.0):
    """(variance, number of terms) in exact arithmetic; terms touching a NaN are skipped."""
    x, valid = phase_of(data, data_type)
    values = [t for t in terms(estimator, x, m, valid) if t is not None]
    k = _K.get(estimator, 2)
    tau = Fraction(m) / Fraction(rate)
    tau0 = 1 / Fraction(rate)
    phase_unit = tau0 * tau0 if data_type == "freq" else 1
    total = sum((t * t for t in values), start=Fraction(0)) * phase_unit
    variance = total / (k * tau * tau * len(values))
    if estimator in _MODIFIED:
        variance /= m * m
    if estimator in _TIME:
        variance *= tau * tau / _TIME[estimator]
    return float(variance), len(values)


def fsum_variance(estimator: str, data, m: int, data_type: str = "phase", rate: float = 1.0):
    """(variance, number of terms) with float terms summed by math.fsum (for larger N)."""
    x, valid = phase_of(data, data_type, number=float)
    if data_type == "freq":
        x = [v / rate for v in x]
    values = [t for t in terms(estimator, x, m, valid) if t is not None]
    k = _K.get(estimator, 2)
    tau = m / rate
    variance = math.fsum(t * t for t in values) / (k * tau * tau * len(values))
    if estimator in _MODIFIED:
        variance /= m * m
    if estimator in _TIME:
        variance *= tau * tau / float(_TIME[estimator])
    return variance, len(values)


def nbs14_1000() -> np.ndarray:
    """NIST SP 1065 section 12: n(i) = 16807 n(i-1) mod 2147483647, n(0) = 1234567890, y = n / 2147483647."""
    n = [1234567890]
    for _ in range(999):
        n.append(16807 * n[-1] % 2147483647)
    assert n[1:4] == [395529916, 1209410747, 633705974]
    return np.array(n, dtype=np.float64) / 2147483647
