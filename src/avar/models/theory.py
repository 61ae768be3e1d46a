"""Theoretical Allan variance of stationary latent processes (closed forms).

Every function returns the Allan variance AV(n) of one process at averaging factor
``n`` (the cluster size in samples; the averaging time is ``tau = n / freq``). All
parameters are *per sample*: a model fitted at sampling frequency ``freq`` must be
converted to per-sample parameters before being passed here.

The functions follow R ``avar`` 0.1.3 (same names, same argument order, same formulas,
from Zhang 2008) and are vectorized: every argument may be a scalar or an array-like,
and the arguments are broadcast together with NumPy rules. The result is a Python
``float`` when every argument is a scalar, otherwise a ``float64`` ndarray.

References
----------
N. F. Zhang, "Allan variance of time series models for measurement data",
Metrologia 45(5):549-561, 2008. doi:10.1088/0026-1394/45/5/009
H. Xu, S. Guerrier, R. Molinari, Y. Zhang, "A study of the Allan variance for
constant-mean non-stationary processes", IEEE Signal Processing Letters
24(8):1257-1260, 2017. doi:10.1109/LSP.2017.2722222
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from avar.models.arguments import as_float_array, as_nonnegative, as_phi, as_whole

__all__ = ["av_wn", "av_qn", "av_rw", "av_dr", "av_ar1"]


def _finish(result: np.ndarray, *inputs: np.ndarray) -> float | np.ndarray:
    """Python float if every input was a scalar, else a float64 ndarray."""
    if all(a.ndim == 0 for a in inputs):
        return float(result)
    return np.asarray(result, dtype=np.float64)


def _broadcast(*arrays: np.ndarray, names: tuple[str, ...]) -> None:
    try:
        np.broadcast_shapes(*(a.shape for a in arrays))
    except ValueError as exc:
        shapes = ", ".join(f"{nm}{a.shape}" for nm, a in zip(names, arrays))
        raise ValueError(f"arguments cannot be broadcast together: {shapes}") from exc


def _parameter_and_factors(value: Any, name: str, n: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A non-negative parameter and the averaging factors (int and float), broadcastable."""
    parameter = as_nonnegative(value, name)
    m = as_whole(n, "n")
    _broadcast(parameter, m, names=(name, "n"))
    return parameter, m, m.astype(np.float64)


# --------------------------------------------------------------------------- processes
def av_wn(sigma2: Any, n: Any) -> float | np.ndarray:
    r"""Theoretical Allan variance of a stationary white noise.

    .. math:: \mathrm{AV}(n) = \frac{\sigma^2}{n}

    Parameters
    ----------
    sigma2 : float or array_like
        Variance of the white noise per sample (>= 0).
    n : int or array_like of int
        Averaging factor (cluster size) in samples, whole numbers >= 1.

    Returns
    -------
    float or numpy.ndarray
        AV at each ``n`` (in the squared units of the data); a float when all inputs
        are scalars.

    Raises
    ------
    ValueError
        If ``n`` is not a whole number >= 1 or ``sigma2`` is negative or not finite.
    TypeError
        If an argument is not numeric.

    References
    ----------
    Zhang (2008), Metrologia 45(5):549; Xu et al. (2017), IEEE SPL 24(8):1257.

    Examples
    --------
    >>> av_wn(2, 8)
    0.25
    >>> av_wn(1.0, [1, 2, 4])
    array([1.  , 0.5 , 0.25])
    """
    s2, m, _ = _parameter_and_factors(sigma2, "sigma2", n)
    return _finish(s2 / m, s2, m)


def av_qn(Q2: Any, n: Any) -> float | np.ndarray:
    r"""Theoretical Allan variance of a stationary quantization noise.

    .. math:: \mathrm{AV}(n) = \frac{3 Q^2}{n^2}

    Parameters
    ----------
    Q2 : float or array_like
        Quantization noise parameter :math:`Q^2` per sample (>= 0).
    n : int or array_like of int
        Averaging factor (cluster size) in samples, whole numbers >= 1.

    Returns
    -------
    float or numpy.ndarray
        AV at each ``n``; a float when all inputs are scalars.

    References
    ----------
    Zhang (2008), Metrologia 45(5):549; Xu et al. (2017), IEEE SPL 24(8):1257.

    Examples
    --------
    >>> av_qn(2, 8)
    0.09375
    >>> av_qn(1, [1, 2])
    array([3.  , 0.75])
    """
    q2, m, mf = _parameter_and_factors(Q2, "Q2", n)
    return _finish(3.0 * q2 / (mf * mf), q2, m)


def av_rw(omega2: Any, n: Any) -> float | np.ndarray:
    r"""Theoretical Allan variance of a random walk.

    .. math:: \mathrm{AV}(n) = \frac{(2 n^2 + 1)\,\omega^2}{6 n}

    Parameters
    ----------
    omega2 : float or array_like
        Variance of the random-walk increments per sample, :math:`\omega^2` (>= 0).
    n : int or array_like of int
        Averaging factor (cluster size) in samples, whole numbers >= 1.

    Returns
    -------
    float or numpy.ndarray
        AV at each ``n``; a float when all inputs are scalars.

    References
    ----------
    Zhang (2008), Metrologia 45(5):549; Xu et al. (2017), IEEE SPL 24(8):1257.

    Examples
    --------
    >>> av_rw(2, 8)
    5.375
    >>> av_rw(1, [1, 2])
    array([0.5 , 0.75])
    """
    w2, m, mf = _parameter_and_factors(omega2, "omega2", n)
    return _finish((2.0 * mf * mf + 1.0) * w2 / (6.0 * mf), w2, m)


def av_dr(delta: Any, n: Any) -> float | np.ndarray:
    r"""Theoretical Allan variance of a deterministic linear drift.

    .. math:: \mathrm{AV}(n) = \frac{n^2 \delta^2}{2}

    Parameters
    ----------
    delta : float or array_like
        Drift (slope) per sample, :math:`\delta`; any finite real (its sign does not
        matter).
    n : int or array_like of int
        Averaging factor (cluster size) in samples, whole numbers >= 1.

    Returns
    -------
    float or numpy.ndarray
        AV at each ``n``; a float when all inputs are scalars.

    References
    ----------
    Zhang (2008), Metrologia 45(5):549; Xu et al. (2017), IEEE SPL 24(8):1257.

    Examples
    --------
    >>> av_dr(2, 8)
    128.0
    >>> av_dr(0.5, [1, 2])
    array([0.125, 0.5  ])
    """
    d = as_float_array(delta, "delta")
    m = as_whole(n, "n")
    _broadcast(d, m, names=("delta", "n"))
    mf = m.astype(np.float64)
    drift = mf * d  # n delta, then one rounding into the result: no double rounding among subnormals
    return _finish(drift * (drift / 2.0), d, m)


def av_ar1(n: Any, phi: Any, sigma2: Any) -> float | np.ndarray:
    r"""Theoretical Allan variance of a stationary first-order autoregressive process.

    For :math:`X_t = \phi X_{t-1} + \varepsilon_t`, :math:`\varepsilon_t \sim WN(0, \sigma^2)`:

    .. math::

        \mathrm{AV}(n) = \sigma^2\,
        \frac{n - 3\phi - n\phi^2 + 4\phi^{n+1} - \phi^{2n+1}}
             {n^2 (1-\phi)^2 (1-\phi^2)}

    Note the argument order ``(n, phi, sigma2)``, as in R. ``sigma2`` is the
    *innovation* variance; the process variance is ``sigma2 / (1 - phi**2)``.

    The numerator is evaluated in equivalent cancellation-free forms (see the code):
    R's literal expression loses about ``(n (1 - phi))**-3`` ulps as ``phi -> 1``
    (only 4 correct digits at ``phi = 0.9999, n = 1``) and ``1 / (1 + phi)`` ulps as
    ``phi -> -1``; these forms stay within ~1e-14 relative of exact arithmetic.

    Parameters
    ----------
    n : int or array_like of int
        Averaging factor (cluster size) in samples, whole numbers >= 1.
    phi : float or array_like
        Autoregressive coefficient, ``|phi| < 1``.
    sigma2 : float or array_like
        Innovation variance per sample (>= 0).

    Returns
    -------
    float or numpy.ndarray
        AV at each ``n``; a float when all inputs are scalars.

    References
    ----------
    Zhang (2008), Metrologia 45(5):549; Xu et al. (2017), IEEE SPL 24(8):1257.

    Examples
    --------
    >>> round(av_ar1(n=5, phi=0.9, sigma2=1), 10)
    1.3042821876
    >>> av_ar1([1, 2], 0.0, 2.0)   # phi = 0 is white noise: sigma2 / n
    array([2., 1.])
    """
    m = as_whole(n, "n")
    p = as_phi(phi)
    s2 = as_nonnegative(sigma2, "sigma2")
    _broadcast(m, p, s2, names=("n", "phi", "sigma2"))
    mf, pb, s2b = np.broadcast_arrays(m.astype(np.float64), p, s2)
    num = np.empty(mf.shape)
    lo = pb <= 0.5
    # phi <= 1/2: numerator = n (1 - phi^2) - phi E (2 + E) with E = 1 - phi^n taken
    # from expm1, so that both terms are >= 0 when phi < 0 (no cancellation near -1).
    ml, pl = mf[lo], pb[lo]
    with np.errstate(divide="ignore"):
        e_abs = -np.expm1(ml * np.log(np.abs(pl)))  # 1 - |phi|^n (1 when phi = 0)
    e = np.where((pl < 0) & (np.fmod(ml, 2.0) == 1.0), 2.0 - e_abs, e_abs)
    num[lo] = ml * (1.0 - pl) * (1.0 + pl) - pl * e * (2.0 + e)
    # phi > 1/2: with h = -log(phi) and a = n h, the numerator equals
    # phi * (g(a) + 2 n (sinh(h) - h)), g(a) = 2a - 3 + 4 exp(-a) - exp(-2a), a sum of
    # two non-negative terms (R's form cancels to ~(n (1 - phi))^3 of its terms).
    mh, ph = mf[~lo], pb[~lo]
    h = -np.log1p(-(1.0 - ph))
    num[~lo] = ph * (_g(mh * h) + 2.0 * mh * _sinh_minus_x(h))
    den = mf * mf * (1.0 - pb) ** 2 * ((1.0 - pb) * (1.0 + pb))
    return _finish(num / den * s2b, m, p, s2)


def ar1_unit_av(m: np.ndarray, phi: float) -> np.ndarray:
    """Allan variance of an AR(1) of unit innovation variance at factors m, for 1/2 < phi < 1, unchecked.

    The cancellation-free form of :func:`av_ar1` for phi > 1/2, for callers
    that evaluate it many times on validated input (model fitting).

    >>> bool(np.allclose(ar1_unit_av(np.array([1.0, 8.0]), 0.9), av_ar1([1, 8], 0.9, 1.0), rtol=1e-14))
    True
    """
    mf = np.asarray(m, dtype=np.float64)
    h = -math.log(phi)
    num = phi * (_g(mf * h) + 2.0 * mf * _sinh_minus_x(np.full(mf.shape, h)))
    return num / (mf * mf * (1.0 - phi) ** 2 * ((1.0 - phi) * (1.0 + phi)))


# g(a) = 2a - 3 + 4 exp(-a) - exp(-2a) = sum_{k>=3} (-1)^k (4 - 2^k) a^k / k!
_G_COEF = np.array([(-1.0) ** k * (4.0 - 2.0**k) / math.factorial(k) for k in range(3, 28)])
# sinh(x) - x = sum_{k>=1} x^(2k+1) / (2k+1)!
_SH_COEF = np.array([1.0 / math.factorial(2 * k + 1) for k in range(1, 12)])


def _g(a: np.ndarray) -> np.ndarray:
    """2a - 3 + 4 exp(-a) - exp(-2a) without cancellation (series for a < 1)."""
    out = np.empty_like(a)
    small = a < 1.0
    x = a[small]
    out[small] = x**3 * np.polynomial.polynomial.polyval(x, _G_COEF)
    y = a[~small]
    out[~small] = 2.0 * y - 3.0 + 4.0 * np.exp(-y) - np.exp(-2.0 * y)
    return out


def _sinh_minus_x(x: np.ndarray) -> np.ndarray:
    """sinh(x) - x for 0 <= x < 0.7 (the range used), by its Taylor series."""
    return x**3 * np.polynomial.polynomial.polyval(x * x, _SH_COEF)
