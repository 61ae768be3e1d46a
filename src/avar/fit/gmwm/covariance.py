"""Exact covariance of the maximal-overlap Allan variance under a Gaussian model (``weights="efficient"``).

For a series x_1..x_N whose first differences d_t = x_t - x_{t-1} are
stationary with autocovariance gamma_d(h) and mean omega (WN, QN, RW, AR1
and DR all qualify), the maximal-overlap AV at averaging factor m is

    nu_hat(m) = (1 / M) sum_{s=1}^{M} W_s(m)^2,   M = N - 2 m + 1,
    W_s(m) = (ybar_{s+m}(m) - ybar_s(m)) / sqrt(2) = sum_{l=1}^{2m-1} g_m(l) d_{s+l},

a quadratic form in d with the triangular filter g_m(l) = min(l, 2m - l) / (m sqrt(2))
(whose sum is m / sqrt(2), so E W_s(m) = mu_m = omega m / sqrt(2)). The
cross-covariance of the filtered series is

    gamma_jk(h) = Cov(W_s(m_j), W_{s+h}(m_k)) = sum_u C_jk(u) gamma_d(h - u),
    C_jk(u) = sum_b g_j(b + u) g_k(b),

and for Gaussian d (Isserlis) the covariance of two AV estimates is exactly

    Cov(nu_hat_j, nu_hat_k) = 1 / (M_j M_k) sum_h c_jk(h) [2 gamma_jk(h)^2 + 4 mu_j mu_k gamma_jk(h)],

with c_jk(h) = #{s : 1 <= s <= M_j, 1 <= s + h <= M_k} the number of pairs
at lag h. Both convolutions run by FFT. As N grows this tends to the
spectral form (2 / N) int |H_j(f)|^2 |H_k(f)|^2 S_d(f)^2 df of Percival &
Walden (2000, sec. 8.3), here without the large-sample approximation.

Quantization noise (uniform, not Gaussian) is treated as Gaussian with the
same autocovariance: its fourth cumulant is ignored.

References
----------
D. B. Percival, A. T. Walden, Wavelet Methods for Time Series Analysis, 2000, ch. 8.
S. Guerrier, J. Skaloud, Y. Stebler, M.-P. Victoria-Feser, JASA 108(503), 2013
(the efficient weight matrix of the GMWM is the inverse of this covariance).
"""

from __future__ import annotations

import numpy as np

from avar.models import AR1, DR, QN, RW, WN, NoiseModel

__all__ = ["check_supported", "increment_autocovariance", "mo_av_covariance"]

#: Relative size below which the geometric tail of an AR1 autocovariance is cut.
AR1_TAIL = 1e-17


def increment_autocovariance(model: NoiseModel, n: int) -> tuple[np.ndarray, float]:
    """Autocovariance gamma_d(0..H) of the first differences of ``model`` and their mean.

    Closed forms per process (per-sample parameters of :mod:`avar.models.processes`):
    WN 2 sigma2, -sigma2 at lags 0, 1; QN (d = sqrt(q2) times the second difference
    of a unit-variance white noise) 6 q2, -4 q2, q2 at lags 0, 1, 2; RW gamma2 at
    lag 0; AR1 with c(h) = sigma2 phi^|h| / (1 - phi^2): 2 c(0) - 2 c(1) at 0 and
    2 c(h) - c(h - 1) - c(h + 1) at h >= 1; DR contributes the mean omega.

    Returns
    -------
    (ndarray, float)
        gamma_d at lags 0..H and the mean; H = min(n - 1, max(3, the lag where the
        slowest AR1 tail falls below 1e-17 relative)).

    Examples
    --------
    >>> gamma, mean = increment_autocovariance(WN(sigma2=2.0) + RW(gamma2=1.0) + DR(omega=0.5), 100)
    >>> gamma.tolist(), mean
    ([5.0, -2.0, 0.0, 0.0], 0.5)
    """
    lags = 3
    for process in model.components:
        if isinstance(process, AR1) and process.phi != 0.0 and process.sigma2 > 0.0:
            lags = max(lags, int(np.ceil(np.log(AR1_TAIL) / np.log(abs(process.phi)))) + 2)
    lags = max(1, min(lags, n - 1))
    gamma = np.zeros(lags + 1)
    mean = 0.0
    for process in model.components:
        if isinstance(process, WN):
            gamma[:2] += [2.0 * process.sigma2, -process.sigma2][: gamma.size]
        elif isinstance(process, QN):
            gamma[:3] += [6.0 * process.q2, -4.0 * process.q2, process.q2][: gamma.size]
        elif isinstance(process, RW):
            gamma[0] += process.gamma2
        elif isinstance(process, DR):
            mean += process.omega
        elif isinstance(process, AR1):
            h = np.arange(lags + 2, dtype=np.float64)
            c = process.sigma2 * process.phi**h / (1.0 - process.phi**2)
            gamma[0] += 2.0 * (c[0] - c[1])
            gamma[1:] += 2.0 * c[1:-1] - c[:-2] - c[2:]
        else:
            raise ValueError(f"weights='efficient' needs the autocovariance of every process; {process.name} "
                             "has none implemented (WN, QN, RW, DR and AR1 do): use weights='full'")
    return gamma, mean


def check_supported(classes: tuple[type, ...], type: str) -> None:
    """Raise ValueError unless the AV is "mo" and every process has an autocovariance here."""
    if type != "mo":
        raise ValueError(f"weights='efficient' needs a maximal-overlap ('mo') Allan variance, got type {type!r}; "
                         "use weights='full' or 'diagonal'")
    unknown = [cls.name for cls in classes if not issubclass(cls, (WN, QN, RW, DR, AR1))]
    if unknown:
        raise ValueError(f"weights='efficient' supports WN, QN, RW, DR and AR1, not {unknown}; use weights='full'")


def _filter(m: int) -> np.ndarray:
    """g_m(l), l = 1..2m-1: the Allan filter on the first differences."""
    ell = np.arange(1, 2 * m, dtype=np.float64)
    return np.minimum(ell, 2 * m - ell) / (m * np.sqrt(2.0))


def mo_av_covariance(model: NoiseModel, n: int, factors: np.ndarray) -> np.ndarray:
    """Exact Gaussian covariance of the maximal-overlap AV estimates at ``factors`` (see the module docstring).

    Parameters
    ----------
    model : NoiseModel
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
    >>> cov = mo_av_covariance(WN(sigma2=1.0), 10_000, [1, 2])
    >>> bool(abs(cov[0, 0] / (2 * 1.0 / 10_000) - 1.5) < 0.01)   # var of the lag-1 AV of white noise: 3 / N
    True
    """
    from scipy.signal import fftconvolve

    factors = np.asarray(factors, dtype=np.int64)
    gamma, mean = increment_autocovariance(model, n)
    two_sided = np.concatenate([gamma[:0:-1], gamma])  # lags -H..H
    lags = gamma.size - 1
    filters = [_filter(int(m)) for m in factors]
    counts = n - 2 * factors + 1
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
            pairs = np.minimum(m_j, m_k - h) - np.maximum(1, 1 - h) + 1
            keep = pairs > 0
            pairs, values = pairs[keep].astype(np.float64), values[keep]
            total = 2.0 * np.dot(pairs, values * values) + 4.0 * means[j] * means[k] * np.dot(pairs, values)
            out[j, k] = out[k, j] = total / (m_j * m_k)
    return out
