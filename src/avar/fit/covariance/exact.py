"""The covariance of the maximal-overlap AV estimates by FFT from the increments' autocovariance: every lag summed.

For increments d of autocovariance gamma_d(h) and mean omega (WN, QN, RW, AR1
and DR; :func:`increment_autocovariance`), the cross-covariance of the
Allan-filtered series (:mod:`avar.fit.covariance.formula`) is the double convolution

    gamma_jk(h) = sum_u C_jk(u) gamma_d(h - u),   C_jk(u) = sum_b g_j(b + u) g_k(b),

both convolutions by FFT, and the formula's sum runs over every lag. As N grows
this tends to the spectral form (2 / N) int |H_j(f)|^2 |H_k(f)|^2 S_d(f)^2 df of
Percival & Walden (2000, sec. 8.3), here without the large-sample approximation.
It is the GMWM's efficient weight (:func:`avar.gmwm`, ``weights="efficient"``) and
the plain twin of :mod:`avar.fit.covariance.structure`.

References
----------
D. B. Percival, A. T. Walden, Wavelet Methods for Time Series Analysis, 2000, ch. 8.
S. Guerrier, J. Skaloud, Y. Stebler, M.-P. Victoria-Feser, JASA 108(503), 2013
(the efficient weight matrix of the GMWM is the inverse of this covariance).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np

from avar.fit.covariance.formula import allan_filter, level_counts, pair_counts, summand
from avar.fit.terms import components_of
from avar.models import AR1, DR, QN, RW, WN

__all__ = ["SUPPORTED", "IncrementMoments", "increment_autocovariance", "exact_covariance"]

#: The processes whose increments' autocovariance is implemented here.
SUPPORTED = (WN, QN, RW, DR, AR1)
#: Relative size below which the geometric tail of an AR1 autocovariance is cut.
AR1_TAIL = 1e-17


class IncrementMoments(NamedTuple):
    """The first differences' autocovariance at lags 0..H and their mean."""

    gamma: np.ndarray
    mean: float


def increment_autocovariance(model: Any, n: int) -> IncrementMoments:
    """Autocovariance gamma_d(0..H) of the first differences of ``model`` and their mean.

    Closed forms per process (per-sample parameters of :mod:`avar.models.processes`):
    WN 2 sigma2, -sigma2 at lags 0, 1; QN (d = sqrt(q2) times the second difference
    of a unit-variance white noise) 6 q2, -4 q2, q2 at lags 0, 1, 2; RW gamma2 at
    lag 0; AR1 with c(h) = sigma2 phi^|h| / (1 - phi^2): 2 c(0) - 2 c(1) at 0 and
    2 c(h) - c(h - 1) - c(h + 1) at h >= 1; DR contributes the mean |omega|.

    Parameters
    ----------
    model : NoiseModel or sequence of processes or components
        A sum of WN, QN, RW, DR and AR1 (:func:`avar.fit.terms.components_of`).
    n : int
        Series length N.

    Returns
    -------
    IncrementMoments
        gamma_d at lags 0..H and the mean; H = min(n - 1, max(3, the lag where the
        slowest AR1 tail falls below 1e-17 relative)).

    Examples
    --------
    >>> gamma, mean = increment_autocovariance(WN(sigma2=2.0) + RW(gamma2=1.0) + DR(omega=0.5), 100)
    >>> gamma.tolist(), mean
    ([5.0, -2.0, 0.0, 0.0], 0.5)
    """
    terms = components_of(model)
    lags = 3
    for term in terms:
        if issubclass(term.process, AR1) and term.shape != 0.0 and term.scale > 0.0:
            lags = max(lags, int(np.ceil(np.log(AR1_TAIL) / np.log(abs(term.shape)))) + 2)
    lags = max(1, min(lags, n - 1))
    gamma = np.zeros(lags + 1)
    mean = 0.0
    for term in terms:
        process, scale = term.process, term.scale
        if issubclass(process, WN):
            gamma[:2] += [2.0 * scale, -scale][: gamma.size]
        elif issubclass(process, QN):
            gamma[:3] += [6.0 * scale, -4.0 * scale, scale][: gamma.size]
        elif issubclass(process, RW):
            gamma[0] += scale
        elif issubclass(process, DR):
            mean += math.sqrt(scale)
        elif issubclass(process, AR1):
            h = np.arange(lags + 2, dtype=np.float64)
            c = scale * term.shape**h / (1.0 - term.shape**2)
            gamma[0] += 2.0 * (c[0] - c[1])
            gamma[1:] += 2.0 * c[1:-1] - c[:-2] - c[2:]
        else:
            names = [cls.name for cls in SUPPORTED]
            raise ValueError(f"no autocovariance of the increments of {term.kind} is implemented (only of "
                             f"{', '.join(names[:-1])} and {names[-1]})")
    return IncrementMoments(gamma, mean)


def exact_covariance(model: Any, n: int, factors: np.ndarray) -> np.ndarray:
    """Exact Gaussian covariance of the maximal-overlap AV estimates at ``factors`` (every lag summed).

    Parameters
    ----------
    model : NoiseModel or sequence of processes or components
        A sum of WN, QN, RW, DR and AR1 (per-sample parameters).
    n : int
        Series length N.
    factors : array_like of int
        Averaging factors m_j, 1 <= m_j <= N / 2.

    Returns
    -------
    ndarray, shape (len(factors), len(factors))

    Examples
    --------
    >>> cov = exact_covariance(WN(sigma2=1.0), 10_000, [1, 2])
    >>> bool(abs(cov[0, 0] / (2 * 1.0 / 10_000) - 1.5) < 0.01)   # var of the lag-1 AV of white noise: 3 / N
    True
    """
    from scipy.signal import fftconvolve

    factors = np.asarray(factors, dtype=np.int64)
    gamma, mean = increment_autocovariance(model, n)
    two_sided = np.concatenate([gamma[:0:-1], gamma])  # lags -H..H
    lags = gamma.size - 1
    filters = [allan_filter(int(m)) for m in factors]
    counts = level_counts(n, factors)
    means = mean * factors / np.sqrt(2.0)
    out = np.empty((factors.size, factors.size))
    for j in range(factors.size):
        for k in range(j, factors.size):
            g_j, g_k = filters[j], filters[k]
            # C(u) for u = -(len_k - 1) .. len_j - 1, then gamma_jk(h) for h = u_min - H .. u_max + H
            cross = fftconvolve(g_j, g_k[::-1])
            values = fftconvolve(cross, two_sided)
            h = np.arange(values.size) - (g_k.size - 1) - lags
            m_j, m_k = counts[j], counts[k]
            pairs = pair_counts(m_j, m_k, h)
            keep = pairs > 0
            pairs, values = pairs[keep].astype(np.float64), values[keep]
            out[j, k] = out[k, j] = np.dot(pairs, summand(values, means[j] * means[k])) / (m_j * m_k)
    return out
