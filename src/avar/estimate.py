"""The empirical Allan variance: :func:`avar`.

Validation and tau grids live here; the loops are in :mod:`avar._kernels`.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from avar import _kernels
from avar._validation import as_series
from avar.results import AllanVariance

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
    if isinstance(taus, str):
        grid = taus.lower()
        if grid == "octave":
            return 2 ** np.arange(1, n.bit_length() - 1, dtype=np.int64)
        if grid == "decade":
            decades = 10 ** np.arange(0, len(str(largest)), dtype=np.int64)
            factors = np.sort(np.outer(decades, [1, 2, 4]).ravel())
            return factors[factors <= largest]
        if grid == "all":
            return np.arange(1, largest + 1, dtype=np.int64)
        raise ValueError(f"unknown tau grid {taus!r}; use one of {NAMED_GRIDS} or an array of taus in seconds")
    requested = np.atleast_1d(np.asarray(taus))
    if requested.dtype.kind not in "iuf" or requested.ndim != 1 or requested.size == 0:
        raise TypeError("taus must be 'octave', 'decade', 'all' or a non-empty 1-D array of averaging times (s)")
    requested = requested.astype(np.float64)
    if not np.all(np.isfinite(requested)):
        raise ValueError("taus must be finite averaging times in seconds")
    factors = np.round(requested * freq)
    low, high = 1.0 / freq, largest / freq
    outside = (factors < 1) | (factors > largest)
    if outside.any():
        raise ValueError(
            f"taus {requested[outside].tolist()} are outside the valid range "
            f"[{low:g}, {high:g}] s (averaging factors 1..{largest} at freq = {freq:g} Hz, N = {n})"
        )
    return np.unique(factors.astype(np.int64))


#: Bytes of cumulative sums (12 per sample and channel) held at once: wide
#: inputs are processed in batches of channels that reuse one workspace, so
#: memory stays bounded and fresh pages are faulted in only once.
CUMSUM_BUDGET = 1 << 28


class _Workspace:
    """The cumulative-sum buffers, kept between calls while they fit the budget.

    Faulting in fresh pages costs about as much as the cumulative sum itself,
    so repeated calls (bootstrap replicates, channel batches, notebooks) reuse
    one pair of buffers of at most ``CUMSUM_BUDGET`` bytes. A call that finds
    them in use by another thread, or needs more, allocates its own.
    """

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.hi = np.empty(0, dtype=np.float64)
        self.lo = np.empty(0, dtype=np.float32)

    def arrays(self, rows: int, columns: int, reuse: bool) -> tuple[np.ndarray, np.ndarray]:
        size = rows * columns
        if reuse and 12 * size <= CUMSUM_BUDGET:
            if self.hi.size < size:
                self.hi = np.empty(size, dtype=np.float64)
                self.lo = np.empty(size, dtype=np.float32)
            return self.hi[:size].reshape(rows, columns), self.lo[:size].reshape(rows, columns)
        return np.empty((rows, columns), dtype=np.float64), np.empty((rows, columns), dtype=np.float32)


_WORKSPACE = _Workspace()


def allan_variance_columns(data: np.ndarray, factors: np.ndarray, type: str) -> np.ndarray:
    """Allan variance of every column of ``data`` at cluster sizes ``factors``.

    ``data`` is a finite float64 array of shape (N, C); returns shape (C, L).
    The series are centred on their means and scaled by a power of two before
    the compensated cumulative sums (see :mod:`avar._kernels`), so the result
    is as exact as the float64 input allows. Columns are processed in batches
    that fit ``CUMSUM_BUDGET``; each column's result does not depend on the
    batching.
    """
    n, channels = data.shape
    factors = np.asarray(factors, dtype=np.int64)
    centre, low, high = _kernels.column_moments(data)
    with np.errstate(over="ignore"):
        span = np.maximum(high - centre, centre - low)  # inf only for |x| near the float64 limit
    _, exponent = np.frexp(np.where((span > 0) & np.isfinite(span), span, 1.0))
    exponent = np.clip(exponent, -1000, 1000)  # 2**-exponent stays a normal float64
    scale = np.ldexp(1.0, -exponent)
    strides = factors if type == "to" else np.ones_like(factors)
    counts = n_differences(n, factors, type)
    batch = max(1, min(channels, CUMSUM_BUDGET // (12 * (n + 1))))
    sums = np.empty((channels, factors.shape[0]))
    owned = _WORKSPACE.lock.acquire(blocking=False)
    try:
        hi, lo = _WORKSPACE.arrays(batch, n + 1, reuse=owned)
        for first in range(0, channels, batch):
            last = min(channels, first + batch)
            k = last - first
            _kernels.centred_cumsum(data[:, first:last], centre[first:last], scale[first:last], hi[:k], lo[:k])
            sums[first:last] = _kernels.squared_difference_sums(hi[:k], lo[:k], factors, strides, counts)
    finally:
        if owned:
            _WORKSPACE.lock.release()
    unscale = np.ldexp(1.0, exponent)[:, None]
    with np.errstate(over="ignore"):
        allan = sums / (2.0 * factors.astype(np.float64) ** 2 * counts) * unscale * unscale
    if not np.all(np.isfinite(allan)):
        raise ValueError(
            "the Allan variance overflows float64 (the data reach "
            f"{np.max(np.maximum(np.abs(low), np.abs(high))):.3g}); rescale the data, e.g. to other units"
        )
    return allan


def relative_errors(n: int, factors: np.ndarray) -> np.ndarray:
    """The R package's relative error of the Allan deviation, 1 / sqrt(2 (N / m - 1))."""
    return 1.0 / np.sqrt(2.0 * (n / np.asarray(factors, dtype=np.float64) - 1.0))


def avar(x: Any, type: str = "mo", freq: float | None = None, taus: Any = "octave"):
    """Empirical Allan variance of a series (or of every channel of an IMU).

    With x_1..x_N the series, m the cluster size, tau = m / freq and
    ybar_t(m) the mean of the m values starting at t:

    * ``type="mo"`` (maximal overlap), for 1 <= m <= N / 2::

          AV(m) = sum_{t=1}^{N-2m+1} (ybar_{t+m}(m) - ybar_t(m))**2 / (2 (N - 2m + 1))

    * ``type="to"`` (tau overlap: non-overlapping clusters, every pair of
      consecutive cluster means; the NIST SP 1065 "ADEV"), with
      K = floor(N / m)::

          AV(m) = sum_{k=1}^{K-1} (ybar_{k+1} - ybar_k)**2 / (2 (K - 1))

    Each level costs O(number of differences) from compensated cumulative sums
    of the mean-removed float64 series, accurate to a few ulps of exact
    arithmetic even with large offsets, drifts and random walks.

    Parameters
    ----------
    x : array_like, pandas.Series or avar.IMU
        1-D real series (any real dtype, computed in float64). A Series with a
        regular DatetimeIndex or TimedeltaIndex gives the sampling rate when
        ``freq`` is omitted.
    type : {"mo", "to"}
        Estimator.
    freq : float, optional
        Sampling frequency in Hz (default 1, or the rate of the time index).
    taus : {"octave", "decade", "all"} or array_like of float
        Tau grid; see :func:`averaging_factors`. ``"octave"`` (m = 2, 4, ...,
        2**(floor(log2 N) - 1)) reproduces the R package.

    Returns
    -------
    AllanVariance
        Or :class:`avar.ImuAllanVariance` for an IMU.

    Notes
    -----
    Unlike R ``avar`` 0.1.3, the "mo" sum keeps its last difference (R drops
    it but still divides by N - 2m + 1, so its values are low and its largest
    level is 0 for power-of-two lengths), and "to" uses every consecutive
    pair of cluster means (R uses only the disjoint pairs 1-2, 3-4, ...).

    References
    ----------
    D. B. Percival and P. Guttorp, "Long-memory processes, the Allan variance
    and wavelets", 1994. W. J. Riley, "Handbook of Frequency Stability
    Analysis", NIST SP 1065, 2008.

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> x = np.random.default_rng(42).standard_normal(10_000)
    >>> res = avar.avar(x, freq=100.0)
    >>> res.levels[:3]
    array([0.02, 0.04, 0.08])
    >>> res.averaging_factors[:3]
    array([2, 4, 8])
    >>> bool(abs(res.allan[0] * 2 - 1) < 0.05)  # white noise: AV(m) = sigma2 / m
    True
    >>> avar.avar([892, 809, 823, 798, 671, 644, 883, 903, 677], taus=[1, 2]).adev
    array([91.22945..., 85.95287...])
    """
    from avar.imu import IMU

    kind = check_type(type)
    if isinstance(x, IMU):
        if freq is not None:
            raise ValueError("an IMU carries its own freq; do not pass freq with an IMU")
        from avar.imu import imu_avar

        return imu_avar(x, kind, taus)
    values, rate = as_series(x, freq)
    n = values.shape[0]
    factors = averaging_factors(n, rate, taus)
    allan = allan_variance_columns(values[:, None], factors, kind)[0]
    return AllanVariance(
        levels=factors / rate,
        averaging_factors=factors,
        allan=allan,
        errors=relative_errors(n, factors),
        n_differences=n_differences(n, factors, kind),
        type=kind,
        freq=rate,
        n=n,
    )
