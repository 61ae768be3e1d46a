"""Barnes' bias functions B2 and B3 of the two-sample (Allan) variance with dead time, and the correction.

A counter that measures the fractional frequency over tau0 = ``tau`` once every T0 = r tau0 leaves
dead time T0 - tau0 between the measurements (r > 1; r < 1: overlapping measurements). The Allan
variance of such data is biased against the dead-time-free one by factors that depend only on r,
the number n of measurements averaged together, and the noise: mu, the exponent of the Allan
variance sigma_y^2(tau) ~ tau**mu (mu = -alpha - 1 for -3 < alpha < 1, mu = -2 for white and
flicker PM, alpha = 2 and 1).

With the phase structure function D(t) = |t|**(mu + 2) (t**2 ln|t| for mu = 0; a step, 0 at 0
and 1 elsewhere, for mu = -2) and F(A) = 2 D(A) - D(A + 1) - D(|A - 1|):

* B2(r, mu) = sigma^2(2, T, tau) / sigma^2(2, tau, tau) = (2 D(1) + F(r)) / (2 D(1) + F(1))
  (Barnes 1969; D(1) = 1 except for flicker FM, where it is 0), with the closed forms 2/3
  (white PM, r != 1), 1 (white FM, r >= 1), (3 r - 1) / 2 (random-walk FM, r >= 1) and, for
  flicker FM, [2 r**2 ln r - (r + 1)**2 ln(r + 1) - (r - 1)**2 ln|r - 1|] / (-4 ln 2);
* B3(2, n, r, mu) = sigma^2(2, n, T0, tau0) / sigma^2(2, n T0, n tau0): the Allan variance of
  averages of n adjacent dead-time measurements against that of single measurements of n tau0
  every n T0 (the same r, the dead time all at the end) (Barnes and Allan 1990)::

      B3 = [2 n D(1) + n F(n r) - sum_{k=1}^{n-1} (n - k) (2 F(k r) - F((n + k) r) - F((n - k) r))]
           / [2 D(n) + 2 D(n r) - D(n r + n) - D(|n r - n|)]

  from the covariance of two measurements d periods apart, -F(d r) / 2 (D(1) at d = 0). The
  denominator is n**(mu + 2) (2 D(1) + F(r)) (Barnes and Allan's form for the power laws; for
  t**2 ln t the n**2 ln n terms cancel). The sign of the last term is the one the direct sum of
  the covariances gives; the + that reproductions of the formula print would make B3 differ
  from 1 at r = 1.

Numerics: F(A) is a second difference of D; taken directly from three values ~A**(mu + 2) it
loses ~2 log10(A) digits, so beyond A = 4 it is summed from its series in 1/A (B3 keeps ~15
digits up to n r ~ 1e7, where the direct difference was 0.6 % off for flicker FM).

So the Allan variance at tau = n tau0 of the contiguous record is the one measured from the
n-averages divided by B2(r, mu) B3(2, n, r, mu): :func:`dead_time_correction`.

References
----------
J. A. Barnes, "Tables of bias functions, B1 and B2, for variances based on finite samples of
processes with power law spectral densities", NBS Technical Note 375, 1969. J. A. Barnes and
D. W. Allan, "Variances based on data with dead time between the measurements", NIST Technical
Note 1318, 1990. W. J. Riley, NIST SP 1065, 2008, section 5.15 (bias functions).
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np

from avar._validation import short_repr

__all__ = ["bias_b2", "bias_b3", "dead_time_correction", "mu_of_alpha"]


def mu_of_alpha(alpha: Any) -> float:
    """The Allan variance exponent mu (sigma_y^2 ~ tau**mu) of the power-law noise exponent ``alpha``.

    mu = -alpha - 1 for -3 < alpha < 1; mu = -2 for alpha = 1 (flicker PM, as Barnes' tables) and 2.

    >>> [mu_of_alpha(a) for a in (2, 1, 0, -1, -2)]
    [-2.0, -2.0, -1.0, 0.0, 1.0]
    """
    if isinstance(alpha, (bool, np.bool_)) or not isinstance(alpha, numbers.Real) or not math.isfinite(alpha):
        raise TypeError(f"alpha must be a power-law noise exponent (a number), got {short_repr(alpha)}")
    alpha = float(alpha)
    if alpha in (1.0, 2.0):
        return -2.0
    if not -3.0 < alpha < 1.0:
        raise ValueError(f"alpha must be 2, 1 or in (-3, 1) (2 white PM ... -2 random-walk FM), got {alpha:g}")
    return -alpha - 1.0


def _structure(t: np.ndarray, mu: float) -> np.ndarray:
    """D(t) of the phase for Allan exponent mu, up to a constant factor (see the module)."""
    t = np.abs(np.asarray(t, dtype=np.float64))
    if mu == -2.0:
        return (t > 0).astype(np.float64)
    if mu == 0.0:
        safe = np.where(t > 0, t, 1.0)
        return np.where(t > 0, t * t * np.log(safe), 0.0)
    return t ** (mu + 2.0)


#: Beyond this argument F(A) is summed from its series in 1/A: the direct difference of the
#: three D values, each ~A**(mu+2), loses ~2 log10(A) digits (0.5 % of B3 at n r = 1e7).
_SERIES_FROM = 4.0
_SERIES_TERMS = 32  # the terms fall as A**-2: (1/16)**32 is far below double precision


def _f_series(a: np.ndarray, mu: float) -> np.ndarray:
    """F(A) = -(D(A + 1) - 2 D(A) + D(A - 1)) for A >= _SERIES_FROM, from the Taylor series of D:
    -2 sum_{j>=1} D^(2j)(A) / (2j)!, i.e. -2 sum_j C(p, 2j) A**(p - 2j) for D = A**p (p = mu + 2)
    and -(2 ln A + 3) + 4 sum_{j>=2} (2j - 3)! / (2j)! A**(2 - 2j) for D = A**2 ln A (mu = 0)."""
    total = np.zeros_like(a)
    if mu == 0.0:
        for j in range(_SERIES_TERMS, 1, -1):  # smallest terms first
            total += 4.0 * math.factorial(2 * j - 3) / math.factorial(2 * j) * a ** (2.0 - 2 * j)
        return total - (2.0 * np.log(a) + 3.0)
    p = mu + 2.0
    binomials = [1.0]  # C(p, k), k = 0 .. 2 * _SERIES_TERMS
    for k in range(1, 2 * _SERIES_TERMS + 1):
        binomials.append(binomials[-1] * (p - k + 1) / k)
    for j in range(_SERIES_TERMS, 0, -1):
        total += binomials[2 * j] * a ** (p - 2 * j)
    return -2.0 * total


def _f(a: Any, mu: float) -> np.ndarray:
    """F(A) = 2 D(A) - D(A + 1) - D(|A - 1|), A >= 0: directly for small A, from its series beyond."""
    a = np.asarray(a, dtype=np.float64)
    direct = 2.0 * _structure(a, mu) - _structure(a + 1.0, mu) - _structure(a - 1.0, mu)
    if mu == -2.0:
        return direct  # the step: exact
    far = a >= _SERIES_FROM
    if not np.any(far):
        return direct
    return np.where(far, _f_series(np.where(far, a, _SERIES_FROM), mu), direct)


def _check_ratio(r: Any) -> float:
    if isinstance(r, (bool, np.bool_)) or not isinstance(r, numbers.Real) or not math.isfinite(r) or not r > 0:
        raise ValueError(f"r must be the ratio T / tau of the measurement period to its length, > 0 "
                         f"(1: no dead time), got {short_repr(r)}")
    return float(r)


def bias_b2(alpha: Any, r: Any) -> float:
    """Barnes' B2(r, mu): Allan variance with dead time over that without, at the same tau.

    B2 = sigma^2(2, T, tau) / sigma^2(2, tau, tau) = (2 + F(r)) / (2 + F(1)), r = T / tau
    (see :mod:`avar.stability.uncertainty.bias`); B2(1) = 1 for every noise.

    Parameters
    ----------
    alpha : float
        Power-law noise exponent: 2 white PM, 1 flicker PM, 0 white FM, -1 flicker FM,
        -2 random-walk FM (or any value in (-3, 1)).
    r : float
        T / tau: the measurement period over its length (> 0; dead time T - tau for r > 1).

    Returns
    -------
    float

    Examples
    --------
    >>> import avar
    >>> round(avar.bias_b2(2, 3.0), 6), avar.bias_b2(0, 3.0), avar.bias_b2(-2, 3.0)   # 2/3, 1, (3 r - 1) / 2
    (0.666667, 1.0, 4.0)
    """
    mu = mu_of_alpha(alpha)
    r = _check_ratio(r)
    unit = 2.0 * float(_structure(1.0, mu))  # 2 D(1): the variance of two measurements' own terms
    return float((unit + _f(r, mu)) / (unit + _f(1.0, mu)))


def bias_b3(alpha: Any, n: Any, r: Any) -> float:
    """Barnes and Allan's B3(2, n, r, mu): the Allan variance of averages of n dead-time measurements
    over that of single measurements n times as long (the dead time all at the end).

    B3 = sigma^2(2, n, T0, tau0) / sigma^2(2, n T0, n tau0), r = T0 / tau0 (formula: see
    :mod:`avar.stability.uncertainty.bias`). B3 = 1 for n = 1, for r = 1 and for white FM (r >= 1).

    Parameters
    ----------
    alpha : float
        Power-law noise exponent (as :func:`bias_b2`).
    n : int
        Measurements averaged together (>= 1): the averaging factor of the dead-time data.
    r : float
        T0 / tau0 of the single measurements (> 0).

    Returns
    -------
    float

    Examples
    --------
    >>> import avar
    >>> avar.bias_b3(2, 4, 3.0), avar.bias_b3(0, 4, 3.0), avar.bias_b3(-2, 4, 1.0)
    (4.0, 1.0, 1.0)
    """
    mu = mu_of_alpha(alpha)
    r = _check_ratio(r)
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, numbers.Integral) or n < 1:
        raise ValueError(f"n must be a whole number of measurements averaged, >= 1, got {short_repr(n)}")
    n = int(n)
    k = np.arange(1, n, dtype=np.float64)
    inner = (n - k) * (2.0 * _f(k * r, mu) - _f((n + k) * r, mu) - _f((n - k) * r, mu))
    numerator = 2.0 * n * float(_structure(1.0, mu)) + n * float(_f(n * r, mu)) - float(np.sum(inner))
    # the single measurements of n tau0 every n T0: 2 D(n) + 2 D(n r) - D(n r + n) - D(|n r - n|),
    # which is n**(mu + 2) (2 D(1) + F(r)) (for t**2 ln t too: the n**2 ln n terms cancel)
    denominator = float(n) ** (mu + 2.0) * (2.0 * float(_structure(1.0, mu)) + float(_f(r, mu)))
    return float(numerator / denominator)


def dead_time_correction(deviation: Any, alpha: Any, r: Any, n: Any = 1) -> Any:
    """The Allan deviation without dead time, from one measured with it.

    sigma_y(n tau0) = measured / sqrt(B2(r, mu) B3(2, n, r, mu)), where ``measured`` is the Allan
    deviation of the dead-time measurements (length tau0, one every T0 = r tau0) averaged n at a
    time: what :func:`avar.adev` gives for them at averaging factor n as if they were contiguous
    (its tau n T0; the corrected value belongs to tau = n tau0).

    Parameters
    ----------
    deviation : float or array_like
        The measured Allan deviation.
    alpha : float
        The noise's power-law exponent (identified, e.g. ``result.alpha``, or known).
    r : float
        T0 / tau0 (> 0).
    n : int
        The averaging factor of ``deviation`` (default 1).

    Returns
    -------
    float or ndarray
        Same shape as ``deviation``.

    Examples
    --------
    >>> import avar
    >>> avar.dead_time_correction(2.0e-11, alpha=-2, r=3.0)   # random-walk FM: B2 = 4
    1e-11
    """
    factor = math.sqrt(bias_b2(alpha, r) * bias_b3(alpha, n, r))
    values = np.asarray(deviation, dtype=np.float64) / factor
    return float(values) if values.ndim == 0 else values
