"""Confidence intervals of the Allan deviation: R's relative errors and the chi-squared band."""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from avar._validation import short_repr
from avar.stability.uncertainty.edf import DEFAULT_CONFIDENCE, chi2_bounds, estimator_edf
from avar.stability.uncertainty.noise_id import identify_noise

#: ``avar()`` estimator type -> the deviation whose EDF and noise identification it uses.
TYPE_ESTIMATORS = {"mo": "oadev", "to": "adev"}
CI_KINDS = ("r", "chi2")


def relative_errors(n: int, factors: np.ndarray) -> np.ndarray:
    """The R package's relative error of the Allan deviation, 1 / sqrt(2 (N / m - 1))."""
    return 1.0 / np.sqrt(2.0 * (n / np.asarray(factors, dtype=np.float64) - 1.0))


class IntervalChoice(NamedTuple):
    """The interval ``avar()`` was asked for: ``ci`` ("r" or "chi2") and its ``confidence``.

    ``confidence`` is None for R's band (fixed at adev (1 -/+ 2 errors)).
    """

    ci: str
    confidence: float | None


#: R's band, the default of ``avar()``.
R_BAND = IntervalChoice("r", None)


def check_ci(ci: Any, confidence: Any) -> IntervalChoice:
    """Validate ``avar()``'s ``ci`` and ``confidence``; the confidence defaults to one sigma for "chi2".

    >>> chi2, r_band = check_ci("chi2", None), check_ci("r", None)
    >>> chi2.ci, round(chi2.confidence, 4), r_band
    ('chi2', 0.6827, IntervalChoice(ci='r', confidence=None))
    """
    if not isinstance(ci, str) or ci.lower() not in CI_KINDS:
        raise ValueError(f"ci must be 'r' (R's band adev (1 -/+ 2 errors)) or 'chi2' (chi-squared band "
                         f"from Greenhall's EDF), got {short_repr(ci)}")
    ci = ci.lower()
    if confidence is None:
        return IntervalChoice(ci, DEFAULT_CONFIDENCE if ci == "chi2" else None)
    if ci == "r":
        raise ValueError("confidence applies to ci='chi2' only (R's band is fixed at adev (1 -/+ 2 errors))")
    if isinstance(confidence, (bool, np.bool_)) or not isinstance(confidence, (int, float, np.integer, np.floating)) \
            or not 0 < confidence < 1:
        raise ValueError(f"confidence must be a number in (0, 1), e.g. 0.683 or 0.95, got {short_repr(confidence)}")
    return IntervalChoice(ci, float(confidence))


class Chi2Band(NamedTuple):
    """The noise exponent, EDF and chi-squared bounds of one series' Allan deviation, level by level."""

    alpha: np.ndarray
    edf: np.ndarray
    lci: np.ndarray
    uci: np.ndarray


def chi2_band(column: np.ndarray, factors: np.ndarray, freq: float, type: str, allan: np.ndarray,
              confidence: float) -> Chi2Band:
    """alpha, edf, lci, uci of the Allan deviation sqrt(allan) of one series.

    The series is taken as frequency data y: its phase is x = (0, cumsum(y)) / freq
    (N + 1 points), the noise is identified per level by
    :func:`~avar.stability.uncertainty.noise_id.identify_noise` and the EDF is that of
    "oadev" (type "mo") or "adev" (type "to") by Greenhall's algorithm.
    """
    estimator = TYPE_ESTIMATORS[type]
    y = np.asarray(column, dtype=np.float64)
    phase = np.concatenate(([0.0], np.cumsum(y - y.mean()))) / freq  # the mean (a phase ramp) changes nothing
    alpha = identify_noise(phase, factors, estimator, from_frequency=True)
    edf = estimator_edf(estimator, alpha, factors, phase.size)
    lci, uci = chi2_bounds(np.sqrt(allan), edf, confidence)
    return Chi2Band(alpha, edf, lci, uci)
