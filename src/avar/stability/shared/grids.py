"""Tau grids of the Allan variance: estimator names, cluster sizes and term counts."""

from __future__ import annotations

from typing import Any

import numpy as np

from avar._validation import short_repr

ESTIMATOR_TYPES = ("mo", "to")
NAMED_GRIDS = ("octave", "decade", "all")


def check_type(type: Any) -> str:
    """Validate the estimator name, ``"mo"`` or ``"to"``."""
    if not isinstance(type, str) or type.lower() not in ESTIMATOR_TYPES:
        raise ValueError(
            f"unknown Allan variance type {type!r}; use 'mo' (maximal overlap) or 'to' (tau overlap)"
        )
    return type.lower()


def max_averaging_factor(n: int) -> int:
    """Largest valid cluster size: floor(N / 2), for both estimators.

    "mo" needs N - 2m + 1 >= 1 differences, "to" needs floor(N / m) >= 2
    cluster means; both hold exactly when m <= N / 2.
    """
    return n // 2


def n_differences(n: int, factors: np.ndarray, type: str) -> np.ndarray:
    """Squared differences averaged at each cluster size m.

    "mo": N - 2m + 1; "to": floor(N / m) - 1.
    """
    factors = np.asarray(factors, dtype=np.int64)
    return n - 2 * factors + 1 if type == "mo" else n // factors - 1


def averaging_factors(n: int, freq: float = 1.0, taus: Any = "octave") -> np.ndarray:
    """Cluster sizes m of a tau grid for a series of length ``n``.

    Parameters
    ----------
    n : int
        Series length.
    freq : float
        Sampling frequency in Hz; explicit taus are converted with m = tau freq.
    taus : {"octave", "decade", "all"} or array_like of float
        ``"octave"``: m = 2, 4, ..., 2**J with J = floor(log2 N) - 1 (the
        grid of the R package). ``"decade"``: m = 1, 2, 4 times 10**k.
        ``"all"``: every m from 1 to floor(N / 2). An array: averaging times
        in seconds, rounded to whole m, sorted, duplicates dropped; a tau
        outside the valid range raises ``ValueError`` naming that range.

    Returns
    -------
    ndarray of int64, increasing.

    Examples
    --------
    >>> averaging_factors(100).tolist()
    [2, 4, 8, 16, 32]
    >>> averaging_factors(100, taus="decade").tolist()
    [1, 2, 4, 10, 20, 40]
    >>> averaging_factors(100, freq=10.0, taus=[0.1, 0.5, 0.5, 2.0]).tolist()
    [1, 5, 20]
    """
    n = int(n)
    largest = max_averaging_factor(n)
    return grid_factors(taus, freq, largest, first_octave=1,
                        context=f"(averaging factors 1..{largest} at freq = {freq:g} Hz, N = {n})")


def grid_factors(taus: Any, rate: float, largest: int, first_octave: int, context: str) -> np.ndarray:
    """Averaging factors 1 <= m <= ``largest`` of a named grid or of explicit taus (s) at ``rate`` Hz.

    The one grid builder of every estimator: ``"octave"`` is m = 2**first_octave,
    ..., the largest power of two <= ``largest``; ``"decade"`` 1, 2, 4 x 10**k;
    ``"all"`` 1..largest; an array of taus is rounded to whole m, sorted and
    deduplicated, and a tau outside the range raises ``ValueError`` naming it,
    the valid range in seconds and ``context`` (the estimator, N, rate).
    """
    if isinstance(taus, str):
        grid = taus.lower()
        if grid == "octave":
            return 2 ** np.arange(first_octave, largest.bit_length(), dtype=np.int64)
        if grid == "decade":
            decades = 10 ** np.arange(0, len(str(largest)), dtype=np.int64)
            factors = np.sort(np.outer(decades, [1, 2, 4]).ravel())
            return factors[factors <= largest]
        if grid == "all":
            return np.arange(1, largest + 1, dtype=np.int64)
        raise ValueError(f"unknown tau grid {taus!r}; use one of {NAMED_GRIDS} or an array of taus in seconds")
    try:
        requested = np.atleast_1d(np.asarray(taus))
    except ValueError:  # ragged
        requested = np.empty((0, 0))
    if requested.dtype.kind not in "iuf" or requested.ndim != 1 or requested.size == 0:
        raise TypeError(
            f"taus must be 'octave', 'decade', 'all' or a non-empty 1-D array of averaging times (s), "
            f"got {short_repr(taus)}"
        )
    requested = requested.astype(np.float64)
    if not np.all(np.isfinite(requested)):
        raise ValueError(f"taus must be finite averaging times in seconds, got {short_repr(requested.tolist())}")
    factors = np.round(requested * rate)
    outside = (factors < 1) | (factors > largest)
    if outside.any():
        raise ValueError(
            f"taus {short_repr(requested[outside].tolist())} are outside the valid range "
            f"[{1 / rate:g}, {largest / rate:g}] s {context}"
        )
    return np.unique(factors.astype(np.int64))
