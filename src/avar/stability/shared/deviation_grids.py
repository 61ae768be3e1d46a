"""The deviation family's estimators: term counts, largest averaging factors, tau grids.

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
========  ===========================  =====================  ==========

Every level with at least one term exists (Stable32 and NIST compute a
level from a single term); ``allantools`` drops levels with n = 1 (its
``remove_small_ns``), so it lacks the largest level of some grids.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from avar.stability.shared.grids import grid_factors

ESTIMATORS = ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev")

#: Kernel code of every estimator (see :mod:`avar._kernels.classic.levels`).
KERNEL_CODES = {"adev": 0, "oadev": 0, "mdev": 2, "tdev": 2, "hdev": 1, "ohdev": 1, "totdev": 3}

#: Long names, for labels and summaries.
LONG_NAMES = {
    "adev": "Allan deviation",
    "oadev": "overlapping Allan deviation",
    "mdev": "modified Allan deviation",
    "tdev": "time deviation",
    "hdev": "Hadamard deviation",
    "ohdev": "overlapping Hadamard deviation",
    "totdev": "total deviation",
}

#: Smallest number of phase points of every estimator (one term at m = 1).
MIN_PHASE_POINTS = {"adev": 3, "oadev": 3, "mdev": 3, "tdev": 3, "hdev": 4, "ohdev": 4, "totdev": 3}


def max_factor(estimator: str, n_phase: int) -> int:
    """Largest averaging factor with at least one term (0 when there is none).

    >>> [max_factor(e, 1001) for e in ESTIMATORS]
    [500, 500, 333, 333, 333, 333, 1000]
    """
    n = int(n_phase)
    if estimator in ("adev", "oadev"):
        return max(0, (n - 1) // 2)
    if estimator in ("mdev", "tdev"):
        return max(0, n // 3)
    if estimator in ("hdev", "ohdev"):
        return max(0, (n - 1) // 3)
    return max(0, n - 1)


def term_counts(estimator: str, n_phase: int, factors: np.ndarray) -> np.ndarray:
    """Number of terms n(m) of every level (no gaps), as in the table above.

    >>> term_counts("adev", 1001, np.array([1, 10, 100])).tolist()
    [999, 99, 9]
    """
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
    }
    return counts[estimator]


def term_ranges(estimator: str, n_phase: int, factors: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stride, first and one-past-last term index of every level, for the kernels.

    Term ``k`` starts at phase point ``k * stride``; TOTDEV's term ``k`` is
    centred on point ``k`` (k = 1 .. N - 2).
    """
    m = np.asarray(factors, dtype=np.int64)
    counts = term_counts(estimator, n_phase, m)
    strides = m.copy() if estimator in ("adev", "hdev") else np.ones_like(m)
    first = np.ones_like(m) if estimator == "totdev" else np.zeros_like(m)
    return strides, first, first + counts


def deviation_factors(estimator: str, n_phase: int, rate: float = 1.0, taus: Any = "octave") -> np.ndarray:
    """Averaging factors m of a tau grid for ``n_phase`` phase points.

    Parameters
    ----------
    estimator : str
        One of :data:`ESTIMATORS`.
    n_phase : int
        Number of phase points.
    rate : float
        Sampling rate in Hz; explicit taus are converted with m = round(tau rate).
    taus : {"octave", "decade", "all"} or array_like of float
        ``"octave"``: m = 1, 2, 4, ... (from m = 1, as Stable32);
        ``"decade"``: m = 1, 2, 4 times 10**k; ``"all"``: every m; all up to
        :func:`max_factor`. An array: averaging times in seconds, rounded to
        whole m, sorted, duplicates dropped; a tau outside the valid range
        raises ``ValueError`` naming that range.

    Returns
    -------
    ndarray of int64, increasing.

    Examples
    --------
    >>> deviation_factors("oadev", 1001).tolist()
    [1, 2, 4, 8, 16, 32, 64, 128, 256]
    >>> deviation_factors("mdev", 1001, taus="decade").tolist()
    [1, 2, 4, 10, 20, 40, 100, 200]
    >>> deviation_factors("totdev", 11, rate=10.0, taus=[0.1, 0.5, 0.5, 1.0]).tolist()
    [1, 5, 10]
    """
    largest = max_factor(estimator, n_phase)
    return grid_factors(taus, rate, largest, first_octave=0,
                        context=f"of {estimator} (averaging factors 1..{largest} at rate = {rate:g} Hz "
                                f"with {n_phase} phase points)")


def levels_with_terms(statistic: str, n: np.ndarray, arrays: tuple, missing: str | None) -> tuple:
    """``(n, *arrays)`` cut to the levels with at least one term, the first array the variances.

    ``missing`` names the data's NaN values when there are any (only then can a
    level lose every term): no level left is an error naming them. Variances
    that overflowed are an error too.

    >>> levels_with_terms("adev", np.array([3, 0]), (np.array([1.0, 2.0]),), "the 1 NaN value(s) of data")
    (array([3]), array([1.]))
    """
    if missing is not None:
        keep = n > 0
        if not keep.any():
            raise ValueError(f"no {statistic} term avoids {missing} at these taus")
        n, arrays = n[keep], tuple(a[keep] for a in arrays)
    if not np.all(np.isfinite(arrays[0])):
        raise ValueError(f"{statistic} overflows float64; rescale the data, e.g. to other units")
    return (n, *arrays)
