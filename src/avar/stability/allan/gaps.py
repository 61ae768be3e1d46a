"""The Allan variance of a series with gaps: ``avar(x, nan_policy="omit")``.

NaN marks a missing value. Every difference of cluster means whose 2m values
include a NaN is skipped: the "mo" estimator is then OADEV**2 of the series
taken as frequency data, and "to" is ADEV**2, both from
:func:`avar.stability.classic.core.deviation_levels`, and
``n_differences`` counts the differences used.
"""

from __future__ import annotations

import sys
from typing import Any, NamedTuple

import numpy as np

from avar._validation import as_series, short_repr
from avar.stability.allan.intervals import R_BAND, IntervalChoice, relative_errors
from avar.stability.allan.results import AllanVariance
from avar.stability.classic.core import deviation_levels
from avar.stability.classic.deviations import noise_exponents
from avar.stability.shared.grids import averaging_factors
from avar.stability.shared.inputs import NAN_POLICIES
from avar.stability.uncertainty.edf import chi2_bounds, estimator_edf, gap_scaled_edf

TYPE_ESTIMATORS = {"mo": "oadev", "to": "adev"}


def check_nan_policy(nan_policy: Any) -> bool:
    """``True`` for "omit", ``False`` for "raise"."""
    if not isinstance(nan_policy, str) or nan_policy not in NAN_POLICIES:
        raise ValueError(f"nan_policy must be 'raise' (NaN is an error) or 'omit' (skip the differences "
                         f"that touch a NaN), got {short_repr(nan_policy)}")
    return nan_policy == "omit"


class GappySeries(NamedTuple):
    """A 1-D series holding NaN (:func:`series_with_gaps`)."""

    #: float64 samples, NaN where a value is missing.
    values: np.ndarray
    #: Sampling rate (Hz).
    rate: float


def series_with_gaps(x: Any, freq: Any) -> GappySeries | None:
    """The :class:`GappySeries` of float64 values (NaN kept) and rate of a 1-D series holding NaN;
    None when it holds none.

    Everything but the NaN is validated by :func:`avar._validation.as_series`.
    """
    pd = sys.modules.get("pandas")  # not loaded: x cannot be a pandas object
    series = pd is not None and isinstance(x, pd.Series)
    raw = x.to_numpy() if series else x
    try:
        array = np.asarray(raw)
    except (TypeError, ValueError):
        return None
    if array.ndim != 1 or array.dtype.kind != "f" or isinstance(array, np.ma.MaskedArray):
        return None
    missing = np.isnan(array)
    if not missing.any():
        return None
    if missing.all():
        raise ValueError("x holds only NaN values")
    filled = x.fillna(0.0) if series else np.where(missing, 0.0, array)
    checked = as_series(filled, freq)
    values = np.array(checked.values, dtype=np.float64)
    values[missing] = np.nan
    return GappySeries(values, checked.rate)


def allan_variance_with_gaps(values: np.ndarray, freq: float, type: str, taus: Any,
                             band: IntervalChoice = R_BAND) -> AllanVariance:
    """Allan variance of a series with NaN gaps, skipping the differences that touch one.

    Levels left without a difference are dropped. With ``band.ci == "chi2"`` (an
    :class:`~avar.stability.allan.intervals.IntervalChoice`) the noise is identified on the
    longest gap-free stretch and the EDF is scaled by the fraction of differences used.
    """
    n = values.shape[0]
    factors = averaging_factors(n, freq, taus)
    estimator = TYPE_ESTIMATORS[type]
    levels = deviation_levels(estimator, values, factors, "freq", freq)
    allan, counts = levels.variance, levels.n_terms
    keep = counts > 0
    if not keep.any():
        raise ValueError("no difference of cluster means avoids the NaN values of x at these taus")
    factors, allan, counts = factors[keep], allan[keep], counts[keep]
    extra: dict[str, Any] = {}
    if band.ci == "chi2":
        alpha = noise_exponents(estimator, values, "freq", freq, factors)
        edf = gap_scaled_edf(estimator_edf(estimator, alpha, factors, n + 1), counts, estimator, n + 1, factors)
        lci, uci = chi2_bounds(np.sqrt(allan), edf, band.confidence)
        extra = dict(ci=band.ci, confidence=band.confidence, alpha=alpha, edf=edf, chi2_lci=lci, chi2_uci=uci)
    return AllanVariance(levels=factors / freq, averaging_factors=factors, allan=allan,
                         errors=relative_errors(n, factors), n_differences=counts, type=type, freq=freq, n=n,
                         name=None, **extra)
