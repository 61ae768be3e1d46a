"""The empirical Allan variance: :func:`avar`.

Validation at the public boundary; tau grids in :mod:`avar.stability.shared.grids`;
the loops in :mod:`avar._kernels`, reached through
:func:`avar.stability.allan.columns.allan_variance_columns`.
"""

from __future__ import annotations

import sys
from typing import Any

import numpy as np

from avar._validation import (
    SHIFT_LIMIT,
    as_float64,
    as_series,
    check_freq,
    check_length,
    check_numeric_dtype,
    shift_huge,
)
from avar.imu import IMU
from avar.stability.allan.columns import allan_variance_columns
from avar.stability.allan.intervals import R_BAND, IntervalChoice, check_ci, chi2_band, relative_errors
from avar.stability.allan.results import AllanVariance, ImuAllanVariance
from avar.stability.shared.grids import averaging_factors, check_type
from avar.stability.shared.term_counts import n_differences


def avar(x: Any, type: str = "mo", freq: float | None = None, taus: Any = "octave", ci: str = "r",
         confidence: float | None = None, nan_policy: str = "raise", *, rate: float | None = None):
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
    x : array_like, pandas.Series, avar.IMU or dask.array.Array
        1-D real series (any real dtype, read in place; memory maps stream). A
        Series with a regular DatetimeIndex or TimedeltaIndex gives the
        sampling rate when ``freq`` is omitted. A 1-D Dask array that fits
        in memory is computed once and handed to the NumPy path (whatever its
        chunks: the graph never grows with them); a larger one is computed
        chunk by chunk (chunks merged to at least 2**22 samples) on the active
        scheduler (a ``distributed.Client`` included), to the same values (see
        :mod:`avar.stability.allan.dask`).
    type : {"mo", "to"}
        Estimator.
    freq : float, optional
        Sampling frequency in Hz (default 1, or the rate of the time index): R's name, an
        alias of ``rate``.
    taus : {"octave", "decade", "all"} or array_like of float
        Tau grid; see :func:`averaging_factors`. ``"octave"`` (m = 2, 4, ...,
        2**(floor(log2 N) - 1)) reproduces the R package.
    ci : {"r", "chi2"}
        Confidence band of the Allan deviation, the result's ``lci``/``uci``.
        ``"r"`` (default): R's adev (1 -/+ 2 errors), errors = 1 / sqrt(2 (N / m
        - 1)), about 95% for many terms, negative where m > N / 3.
        ``"chi2"``: the chi-squared band adev sqrt(edf / chi2(edf)) (NIST SP
        1065 eq. 45), positive at every level; the noise alpha is identified
        per level (lag-1 autocorrelation, :mod:`avar.stability.uncertainty.noise_id`) on the
        phase x = (0, cumsum(x)) / freq, and the EDF is Greenhall's for OADEV
        (type "mo") or ADEV (type "to") (:mod:`avar.stability.uncertainty.edf`). The
        result then also carries ``alpha``, ``edf`` and ``confidence``.
    confidence : float, optional
        Confidence level of the ``"chi2"`` band, in (0, 1); default one sigma
        (0.6827, Stable32's 0.683).
    nan_policy : {"raise", "omit"}
        NaN in a series: an error (default), or gaps whose differences are
        skipped: every difference of cluster means that touches a NaN is left
        out and ``n_differences`` counts those used ("mo" is then OADEV**2 of
        ``x`` as frequency data, "to" ADEV**2; see :mod:`avar.stability.allan.gaps`).
    rate : float, optional
        Sampling rate in Hz, the library's name for R's ``freq`` (give one of them).

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
    >>> band = avar.avar(x, freq=100.0, ci="chi2")
    >>> band.alpha[:3], band.edf[:2].round(1)
    (array([0, 0, 0]), array([5416.9, 3074.8]))
    >>> bool(np.all((band.lci > 0) & (band.lci <= band.adev) & (band.adev <= band.uci)))
    True
    """
    if rate is not None:
        if freq is not None:
            raise TypeError("give rate= or freq= (R's alias of rate), not both")
        freq = rate
    kind = check_type(type)
    band = check_ci(ci, confidence)
    if _is_dask_array(x):
        return _dask_allan_variance(x, freq, kind, taus, band, nan_policy)
    if nan_policy != "raise":  # checked, and gaps computed, by the deviation family's kernels: loaded on demand
        from avar.stability.allan.gaps import allan_variance_with_gaps, check_nan_policy, series_with_gaps

        gappy = series_with_gaps(x, freq) if check_nan_policy(nan_policy) and not isinstance(x, IMU) else None
        if gappy is not None:
            return allan_variance_with_gaps(gappy.values, gappy.rate, kind, taus, band)
    if isinstance(x, IMU):
        if freq is not None:
            raise ValueError("an IMU carries its own freq; do not pass freq with an IMU")
        data = x.data
        if data.dtype.kind in "iu" or max(float(data.max()), -float(data.min())) >= SHIFT_LIMIT:
            # integers beyond 2**53 (converted without loss) or values near the float64 limit
            # (shifted by their midrange): channel by channel
            channels = {}
            for j, channel in enumerate(x.channels):
                column = shift_huge(as_float64(np.ascontiguousarray(data[:, j])))
                channels.update(allan_variance_table(column[:, None], (channel,), x.freq, kind, taus, band))
        else:
            channels = allan_variance_table(x.data, x.channels, x.freq, kind, taus, band)
        return ImuAllanVariance(
            sensor=x.name,
            freq=x.freq,
            n=x.n,
            channels=channels,
            sensor_types=x.sensor_types,
            axes=x.axes,
            units=x.units,
        )
    series = as_series(x, freq, native=True)
    return allan_variance_table(series.values[:, None], (None,), series.rate, kind, taus, band)[None]


def allan_variance_table(
    data: np.ndarray, names: tuple, freq: float, type: str, taus: Any, band: IntervalChoice = R_BAND,
    columns: Any = None,
) -> dict[Any, AllanVariance]:
    """Allan variance of every column of a validated (N, C) table, keyed by column name.

    The one estimation path: a series is a table of one column, an IMU a table
    of its channels, and every column shares the tau grid and one pass of the
    kernels; each column's result equals that of the column alone. ``band``
    (:class:`~avar.stability.allan.intervals.IntervalChoice`): with ``ci="chi2"`` each column also
    gets its chi-squared band.
    ``columns`` computes the (C, L) Allan variances (default the kernels; the Dask backend for Dask arrays).
    """
    n = data.shape[0]
    factors = averaging_factors(n, freq, taus)
    allan = (columns or allan_variance_columns)(data, factors, type)
    levels = factors / freq
    errors = relative_errors(n, factors)
    counts = n_differences(n, factors, type)
    results = {}
    for j, name in enumerate(names):
        extra: dict[str, Any] = {}
        if band.ci == "chi2":
            chi2 = chi2_band(data[:, j], factors, freq, type, allan[j], band.confidence)
            extra = dict(ci=band.ci, confidence=band.confidence, alpha=chi2.alpha, edf=chi2.edf,
                         chi2_lci=chi2.lci, chi2_uci=chi2.uci)
        results[name] = AllanVariance(levels=levels, averaging_factors=factors, allan=allan[j], errors=errors,
                                      n_differences=counts, type=type, freq=freq, n=n, name=name, **extra)
    return results


def _is_dask_array(x: Any) -> bool:
    dask_array = sys.modules.get("dask.array")  # not loaded: x cannot be a Dask array
    return dask_array is not None and isinstance(x, dask_array.Array)


def _dask_allan_variance(x: Any, freq: Any, type: str, taus: Any, band: IntervalChoice,
                         nan_policy: str) -> AllanVariance:
    """A 1-D Dask array: computed into memory and handed to the NumPy path when it fits
    (:func:`avar.stability.allan.dask.fits_in_memory`), else chunk by chunk on the active
    scheduler with chunks of at least :data:`~avar.stability.allan.dask.MIN_CHUNK` samples
    (:mod:`avar.stability.allan.dask`): the task graph stays bounded whatever the input's chunks."""
    from avar.stability.allan.dask import allan_variance_dask, fits_in_memory, known_chunks

    if x.ndim != 1:
        raise ValueError(f"x must be 1-D, got a Dask array of shape {x.shape}")
    check_numeric_dtype(np.empty(0, dtype=x.dtype), "x")
    x = known_chunks(x)
    if fits_in_memory(x):
        return avar(np.asarray(x.compute()), type=type, freq=freq, taus=taus, ci=band.ci, confidence=band.confidence,
                    nan_policy=nan_policy)
    if band.ci != "r" or nan_policy != "raise":
        raise ValueError("a Dask array larger than memory takes ci='r' and nan_policy='raise' (noise "
                         "identification and gaps need the series in memory)")
    check_length(int(x.shape[0]), "x")
    rate = 1.0 if freq is None else check_freq(freq)
    return allan_variance_table(x[:, None], (None,), rate, type, taus, band, columns=allan_variance_dask)[None]
