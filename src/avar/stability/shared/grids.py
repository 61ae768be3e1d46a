"""Tau grids: the averaging factors m of every estimator, from a named grid or explicit taus.

The one home of grids: R's :func:`averaging_factors` of :func:`avar.avar` (m = 2, 4, ...),
:func:`grid_factors` (the builder every statistic calls), :func:`largest_factor` of every
statistic, the deviation family's :func:`deviation_factors` (m = 1, 2, 4, ..., as Stable32),
the total and Theo statistics' :func:`total_factors` (Theo1: even m, tau = 0.75 m tau0) and
:func:`octave_factors` of the joint estimator. Term counts: :mod:`.term_counts`.
"""

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


def octave_factors(n: int) -> np.ndarray:
    """m = 1, 2, 4, ..., 2**J with J = floor(log2 N) - 1: the octave grid of :func:`avar.avar` plus m = 1.

    >>> octave_factors(100).tolist()
    [1, 2, 4, 8, 16, 32]
    """
    return 2 ** np.arange(0, int(n).bit_length() - 1, dtype=np.int64)


def largest_factor(statistic: str, n_phase: int) -> int:
    """Largest averaging factor m with at least one term (0 when there is none), any statistic.

    N is the number of phase points. Classic statistics: the table of
    :mod:`avar.stability.shared.term_counts`; MTOTDEV, TTOTDEV: floor(N / 3); HTOTDEV:
    floor((N - 1) / 3); MHTOTDEV: floor(N / 4); Theo1 and ThêoH: the largest even m <= N - 1;
    MTIE, TIE rms: N - 1; PDEV: floor((N - 1) / 2).

    >>> [largest_factor(e, 1001) for e in ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev")]
    [500, 500, 333, 333, 333, 333, 1000]
    >>> [largest_factor(e, 1001) for e in ("mhdev", "htdev", "mhtotdev")]
    [250, 250, 250]
    >>> [largest_factor(e, 1001) for e in ("mtotdev", "htotdev", "theo1", "mtie", "pdev")]
    [333, 333, 1000, 1000, 500]
    """
    n = int(n_phase)
    if statistic in ("adev", "oadev", "pdev"):
        return max(0, (n - 1) // 2)
    if statistic in ("mhdev", "htdev", "mhtotdev"):
        return max(0, n // 4)
    if statistic in ("mdev", "tdev", "mtotdev", "ttotdev"):
        return max(0, n // 3)
    if statistic in ("hdev", "ohdev", "htotdev"):
        return max(0, (n - 1) // 3)
    if statistic in ("theo1", "theoh"):
        return max(0, (n - 1) - (n - 1) % 2)
    return max(0, n - 1)  # totdev, mtie, tierms


def max_factor(estimator: str, n_phase: int) -> int:
    """:func:`largest_factor` of a classic statistic (the name :func:`deviation_factors` documents)."""
    return largest_factor(estimator, n_phase)


def deviation_factors(estimator: str, n_phase: int, rate: float = 1.0, taus: Any = "octave", *,
                      statistic: str | None = None) -> np.ndarray:
    """Averaging factors m of a tau grid for ``n_phase`` phase points.

    Parameters
    ----------
    estimator : str
        A classic statistic (:data:`avar.stability.shared.registry.CLASSIC`).
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
    largest = largest_factor(estimator, n_phase)
    return grid_factors(taus, rate, largest, first_octave=0,
                        context=f"of {statistic or estimator} (averaging factors 1..{largest} at rate = {rate:g} Hz "
                                f"with {n_phase} phase points)")


def total_factors(estimator: str, n_phase: int, rate: float, taus: Any, *, statistic: str | None = None) -> np.ndarray:
    """Averaging factors of a tau grid (see :func:`avar.stability.shared.grids.grid_factors`); errors name
    ``statistic`` (default ``estimator``: ThêoH's Theo1 levels say theoh).

    Theo1 (and ThêoH's Theo1 levels) take even m only, tau = 0.75 m tau0:
    ``"octave"`` m = 2, 4, 8, ...; ``"decade"`` the even ones of 1, 2, 4 x
    10**k; ``"all"`` every even m; explicit taus in seconds give m = tau /
    (0.75 tau0), which must be a whole even number.

    >>> total_factors("theo1", 100, 1.0, "octave").tolist(), total_factors("theo1", 100, 1.0, [1.5, 3.0]).tolist()
    ([2, 4, 8, 16, 32, 64], [2, 4])
    """
    largest = largest_factor(estimator, n_phase)
    context = f"of {statistic or estimator} with {n_phase} phase points at rate = {rate:g} Hz"
    if estimator != "theo1":
        return grid_factors(taus, rate, largest, first_octave=0, context=f"{context} (m = 1..{largest})")
    if largest < 2:
        return np.zeros(0, dtype=np.int64)
    if isinstance(taus, str):
        if taus.lower() == "octave":
            return 2 ** np.arange(1, largest.bit_length(), dtype=np.int64)
        factors = grid_factors(taus, rate, largest, first_octave=1, context=context)
        return factors[(factors % 2 == 0)]
    try:
        given = np.asarray(taus, dtype=np.float64)
        scaled = given / 0.75
    except (TypeError, ValueError):
        scaled = taus  # grid_factors names what is wrong
    else:  # the range in Theo1's own taus, not in the m they stand for
        low, high = 1.5 / rate, 0.75 * (largest - largest % 2) / rate
        outside = np.atleast_1d((given < low * (1 - 1e-9)) | (given > high * (1 + 1e-9)))
        if given.ndim <= 1 and outside.any():
            raise ValueError(f"taus {short_repr(np.atleast_1d(given)[outside].tolist())} are outside the valid range "
                             f"[{low:g}, {high:g}] s {context} (tau = 0.75 m / rate, m even)")
    exact = grid_factors(scaled, rate, largest, first_octave=1, context=f"{context} (tau = 0.75 m / rate, m even)")
    requested = np.atleast_1d(scaled) * rate
    odd = (np.abs(requested - np.round(requested)) > 1e-9 * requested) | (np.round(requested) % 2 == 1)
    if odd.any():
        raise ValueError(f"{statistic or estimator} taus must be 0.75 m / rate with m even, got {short_repr((requested[odd] * 0.75 / rate).tolist())} "
                         f"s (m = {short_repr(requested[odd].tolist())})")
    return exact
