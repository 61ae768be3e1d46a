"""Term counts: how many terms each level of each estimator averages, gap-free.

N is the number of phase points (frequency data of length M give N = M + 1
phase points) and m the averaging factor, tau = m tau0. Term counts follow
NIST SP 1065 (Riley 2008):

========  ===========================  =====================  ==========
name      terms n(m)                   largest m (n >= 1)     kernel code
========  ===========================  =====================  ==========
adev      floor((N - 1) / m) - 1       floor((N - 1) / 2)     0, stride m
oadev     N - 2m                       floor((N - 1) / 2)     0, stride 1
mdev      N - 3m + 1                   floor(N / 3)           2
tdev      N - 3m + 1                   floor(N / 3)           2
hdev      floor((N - 1) / m) - 2       floor((N - 1) / 3)     1, stride m
ohdev     N - 3m                       floor((N - 1) / 3)     1, stride 1
totdev    N - 2                        N - 1                  3
mhdev     N - 4m + 1                   floor(N / 4)           4
htdev     N - 4m + 1                   floor(N / 4)           4
========  ===========================  =====================  ==========

Every level with at least one term exists (Stable32 and NIST compute a
level from a single term); ``allantools`` drops levels with n = 1 (its
``remove_small_ns``), so it lacks the largest level of some grids.
The largest factors are :func:`avar.stability.shared.grids.largest_factor`'s. R's
:func:`n_differences` of :func:`avar.avar` lives here too.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from avar.stability.shared.registry import CLASSIC


def n_differences(n: int, factors: np.ndarray, type: str) -> np.ndarray:
    """Squared differences averaged at each cluster size m.

    "mo": N - 2m + 1; "to": floor(N / m) - 1.
    """
    factors = np.asarray(factors, dtype=np.int64)
    return n - 2 * factors + 1 if type == "mo" else n // factors - 1


def term_counts(estimator: str, n_phase: int, factors: Any) -> np.ndarray:
    """Number of terms n(m) of every level (no gaps) of a classic, total or Theo statistic.

    Classic: the table above; MTOTDEV, TTOTDEV: N - 3m + 1; HTOTDEV: N - 3m; MHTOTDEV:
    N - 4m + 1; Theo1: (N - m) floor(m / 2).

    >>> term_counts("adev", 1001, np.array([1, 10, 100])).tolist()
    [999, 99, 9]
    >>> term_counts("mtotdev", 100, np.array([1, 33])).tolist(), term_counts("theo1", 100, [2, 98]).tolist()
    ([98, 2], [98, 98])
    """
    if estimator not in CLASSIC:
        return _total_term_counts(estimator, n_phase, factors)
    m = np.asarray(factors, dtype=np.int64)
    n = int(n_phase)
    counts = {
        "adev": (n - 1) // m - 1,
        "oadev": n - 2 * m,
        "mdev": n - 3 * m + 1,
        "tdev": n - 3 * m + 1,
        "hdev": (n - 1) // m - 2,
        "ohdev": n - 3 * m,
        "totdev": np.full_like(m, n - 2),
        "mhdev": n - 4 * m + 1,
        "htdev": n - 4 * m + 1,
    }
    return counts[estimator]


def _total_term_counts(estimator: str, n_phase: int, factors: Any) -> np.ndarray:
    """Terms n(m) of the total and Theo statistics without gaps.

    >>> _total_term_counts("mtotdev", 100, np.array([1, 33])).tolist(), _total_term_counts("theo1", 100, [2, 98]).tolist()
    ([98, 2], [98, 98])
    """
    m = np.asarray(factors, dtype=np.int64)
    n = int(n_phase)
    if estimator in ("mtotdev", "ttotdev"):
        return n - 3 * m + 1
    if estimator == "htotdev":
        return n - 3 * m
    if estimator == "mhtotdev":
        return n - 4 * m + 1
    return (n - m) * (m // 2)


class TermRanges(NamedTuple):
    """Stride, first and one-past-last term index of every level."""

    strides: np.ndarray
    first: np.ndarray
    last: np.ndarray


def term_ranges(estimator: str, n_phase: int, factors: np.ndarray) -> TermRanges:
    """Stride, first and one-past-last term index of every level, for the kernels.

    Term ``k`` starts at phase point ``k * stride``; TOTDEV's term ``k`` is
    centred on point ``k`` (k = 1 .. N - 2).
    """
    m = np.asarray(factors, dtype=np.int64)
    counts = term_counts(estimator, n_phase, m)
    strides = m.copy() if estimator in ("adev", "hdev") else np.ones_like(m)
    first = np.ones_like(m) if estimator == "totdev" else np.zeros_like(m)
    return TermRanges(strides, first, first + counts)


class KeptLevels(NamedTuple):
    """The levels left with at least one term (:func:`levels_with_terms`)."""

    n_terms: np.ndarray
    variance: np.ndarray
    factors: np.ndarray
    #: The deviation of every level kept, when one was given (else None).
    deviation: np.ndarray | None = None


def levels_with_terms(statistic: str, n_terms: np.ndarray, variance: np.ndarray, factors: np.ndarray,
                      missing: str | None, deviation: np.ndarray | None = None) -> KeptLevels:
    """The :class:`KeptLevels`: terms, variances, factors (and ``deviation``, if given) of the
    levels with at least one term.

    ``missing`` names the data's NaN values when there are any (only then can a
    level lose every term): no level left is an error naming them. Variances
    that overflowed are an error too.

    >>> kept = levels_with_terms("adev", np.array([3, 0]), np.array([1.0, 2.0]), np.array([1, 2]),
    ...                          "the 1 NaN value(s) of data")
    >>> kept.n_terms.tolist(), kept.variance.tolist(), kept.factors.tolist(), kept.deviation
    ([3], [1.0], [1], None)
    """
    if missing is not None:
        keep = n_terms > 0
        if not keep.any():
            raise ValueError(f"no {statistic} term avoids {missing} at these taus")
        n_terms, variance, factors = n_terms[keep], variance[keep], factors[keep]
        deviation = None if deviation is None else deviation[keep]
    if not np.all(np.isfinite(variance)):
        raise ValueError(f"{statistic} overflows float64; rescale the data, e.g. to other units")
    return KeptLevels(n_terms, variance, factors, deviation)
