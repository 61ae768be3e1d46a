"""Chi-squared bounds of a deviation, with exact quantiles or Stable32's.

A variance estimate with ``edf`` equivalent degrees of freedom is distributed as
sigma**2 chi2(edf) / edf, so its two-sided interval at a confidence c is
(NIST SP 1065 eq. 45)::

    lci = deviation sqrt(edf / chi2_{1-q}(edf)),  uci = deviation sqrt(edf / chi2_q(edf)),  q = (1 - c) / 2

Two ways to get the quantiles chi2_p(edf):

* ``"exact"``: the inverse regularized incomplete gamma function (SciPy).
* ``"stable32"``: what Stable32 prints. Up to 100 degrees of freedom it
  iterates to the exact quantile; above, it uses the Wilson–Hilferty cube
  (Abramowitz and Stegun 26.4.17)::

      chi2_p(edf) = edf (1 - 2 / (9 edf) + z_p sqrt(2 / (9 edf)))**3

  with the normal quantile z_p of Abramowitz and Stegun 26.2.22,
  z = t - (a0 + a1 t) / (1 + b1 t + b2 t**2), t = sqrt(-2 ln p) for the upper tail
  p <= 1/2, where Stable32 has a1 = 0.27601 (the handbook's 0.27061 with two
  digits swapped). Its bounds differ from the exact ones by at most about 5e-4
  (relative) and reproduce Stable32's printed bounds to their 5 digits
  (``tests/stability/uncertainty/test_chi2.py``).

The deviation catalogue (``avar.adev`` ... ``avar.theoh``) uses Stable32's
quantiles, to print what Stable32 prints; the Allan variance's chi-squared band
and the noise report use the exact ones. Either set is one call away:
``chi2_bounds(result.deviation, result.edf, quantiles="exact")``.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from avar._validation import short_repr
from avar.stability.shared.confidence import DEFAULT_CONFIDENCE, ONE_SIGMA, format_confidence  # noqa: F401 (re-exported)

QUANTILES = ("exact", "stable32")
#: The quantiles of the deviation catalogue's bounds: Stable32's, to print what it prints.
CATALOGUE_QUANTILES = "stable32"
#: Above this EDF Stable32 takes the Wilson–Hilferty approximation instead of iterating.
STABLE32_EXACT_UP_TO = 100.0
#: Abramowitz and Stegun 26.2.22 as Stable32 has it: (a0, a1, b1, b2), a1 with its digits swapped.
STABLE32_NORMAL_QUANTILE = (2.30753, 0.27601, 0.99229, 0.04481)


class Bounds(NamedTuple):
    """Lower and upper confidence bounds of a deviation (its units)."""

    lower: np.ndarray
    upper: np.ndarray


def chi2_bounds(deviation: Any, edf: Any, confidence: float = DEFAULT_CONFIDENCE,
                quantiles: str = "exact") -> Bounds:
    """Chi-squared confidence bounds of a deviation with ``edf`` degrees of freedom.

    ``lci = deviation sqrt(edf / chi2.isf(q, edf))`` and ``uci = deviation
    sqrt(edf / chi2.ppf(q, edf))`` with q = (1 - confidence) / 2 (NIST SP 1065
    eq. 45). The upper quantile comes from the survival function so that
    confidences near 1 keep their precision. Both bounds are positive for a
    positive deviation. At a low confidence (below about 0.4) the central
    chi-squared interval lies around its median, below edf, and would exclude
    the estimate itself: the bounds are then widened to the deviation, so that
    lci <= deviation <= uci always (a wider, conservative interval).

    Parameters
    ----------
    deviation : array_like of float
        Deviations, >= 0.
    edf : array_like of float
        Equivalent degrees of freedom, > 0 (NaN gives NaN bounds); broadcast
        against ``deviation``.
    confidence : float
        Two-sided confidence level in (0, 1); default one sigma, 0.6827 (what
        Stable32 prints as 0.683).
    quantiles : {"exact", "stable32"}
        The chi-squared quantiles: exact, or Stable32's (exact up to 100
        degrees of freedom, Wilson–Hilferty above; see the module's notes).

    Returns
    -------
    (lci, uci) : tuple of ndarray

    Examples
    --------
    >>> lci, uci = chi2_bounds(0.2, 999.0)
    >>> round(float(lci), 5), round(float(uci), 5)
    (0.19567, 0.20463)
    >>> [round(float(b), 6) for b in chi2_bounds(0.2, 999.0, quantiles="stable32")]
    [0.195696, 0.204603]
    >>> [b.round(3).tolist() for b in chi2_bounds([1.0, 1.0], [1.0, 10.0], confidence=0.95)]
    [[0.446, 0.699], [31.91, 1.755]]
    >>> [b.round(3).tolist() for b in chi2_bounds([1.0], [1.0], confidence=0.1)]  # lci widened to the estimate
    [[1.0], [1.673]]
    """
    from scipy.special import chdtri, gammaincinv  # what chi2.isf / chi2.ppf call, without their overhead

    deviation, edf = _real_array(deviation, "deviation"), _real_array(edf, "edf")
    if not (np.isfinite(deviation).all() and (deviation >= 0).all()):
        raise ValueError(f"deviation must be finite and >= 0, got {short_repr(deviation)}")
    if (edf <= 0).any() or np.isinf(edf).any():
        raise ValueError(f"edf must be positive and finite (NaN allowed), got {short_repr(edf)}")
    if isinstance(confidence, (bool, np.bool_)) or not isinstance(confidence, (int, float, np.integer, np.floating)) \
            or not 0 < confidence < 1:
        raise ValueError(f"confidence must be a number in (0, 1), e.g. 0.683 or 0.95, got {short_repr(confidence)}")
    if not isinstance(quantiles, str) or quantiles not in QUANTILES:
        raise ValueError(f"quantiles must be 'exact' or 'stable32', got {short_repr(quantiles)}")
    tail = (1.0 - float(confidence)) / 2.0
    # uci is inf only where the lower chi-squared quantile underflows (EDF << 1 at a confidence near 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        upper, lower = chdtri(edf, tail), 2.0 * gammaincinv(edf / 2.0, tail)  # chi2.isf, chi2.ppf (tail, edf)
        if quantiles == "stable32":
            upper, lower = np.array(upper, dtype=np.float64), np.array(lower, dtype=np.float64)
            large = edf > STABLE32_EXACT_UP_TO
            z = _stable32_upper_normal_quantile(tail)
            upper[large], lower[large] = _wilson_hilferty(edf[large], z), _wilson_hilferty(edf[large], -z)
        lci, uci = deviation * np.sqrt(edf / upper), deviation * np.sqrt(edf / lower)
        return Bounds(np.minimum(lci, deviation), np.maximum(uci, deviation))


def _stable32_upper_normal_quantile(tail: float) -> float:
    """z with Q(z) = tail (tail <= 1/2; above, -z of 1 - tail), Abramowitz and Stegun 26.2.22 as Stable32."""
    a0, a1, b1, b2 = STABLE32_NORMAL_QUANTILE
    p = min(tail, 1.0 - tail)
    t = np.sqrt(-2.0 * np.log(p))
    z = t - (a0 + a1 * t) / (1.0 + b1 * t + b2 * t * t)
    return float(z if tail <= 0.5 else -z)


def _wilson_hilferty(nu: np.ndarray, z: float) -> np.ndarray:
    """chi2 quantile of ``nu`` degrees of freedom at the normal quantile z (A&S 26.4.17), floored at 0."""
    h = 2.0 / (9.0 * nu)
    return nu * np.maximum(1.0 - h + z * np.sqrt(h), 0.0) ** 3


def _real_array(values: Any, name: str) -> np.ndarray:
    array = np.asarray(values)
    if array.dtype.kind not in "iuf" or isinstance(values, (bool, np.bool_)):
        raise TypeError(f"{name} must be a real number or array, got {short_repr(values)}")
    return array.astype(np.float64)
