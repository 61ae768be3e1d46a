"""Greenhall's BasicSum of the EDF of finite-difference variances (numba, NumPy for few rows).

The loops of :func:`avar.stability.uncertainty.edf.greenhall_edf` (Greenhall and Riley
2003, eqs. 7-10), one level per row, over at most J_max + 1 lags each.
:func:`greenhall_sums` takes them in NumPy for a few rows (nothing to compile:
a noise report's levels) and compiled for many (every tau of a long series).
The plain twin is the NumPy transcription in the tests (and
``allantools.edf_greenhall``, which they compare).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from avar._kernels.runtime.paths import numpy_path

#: C(2d, d + k) for d = 1, 2, 3 and k = -d .. d (row d, column d + k).
_BINOMIAL = np.array([[0, 0, 0, 0, 0, 0, 0], [1, 2, 1, 0, 0, 0, 0], [1, 4, 6, 4, 1, 0, 0], [1, 6, 15, 20, 15, 6, 1]],
                     dtype=np.float64)


@njit(cache=True)
def _sw(t, alpha):
    """s_w(t) (eq. 7): the generalized autocovariance of power-law phase noise."""
    a = abs(t)
    log = np.log(a) if a > 0.0 else 0.0
    if alpha == 2:
        return -a
    if alpha == 1:
        return t**2 * log
    if alpha == 0:
        return a**3
    if alpha == -1:
        return -(t**4) * log
    if alpha == -2:
        return -(a**5)
    if alpha == -3:
        return t**6 * log
    return a**7


@njit(cache=True)
def sz(t, f, alpha, d):
    """s_z(t) (eqs. 8-9): the d-th difference of s_x with filter F (inf: the unmodified limit)."""
    total = 0.0
    finite = np.isfinite(f)
    h = 1.0 / f if finite else 0.0
    for k in range(-d, d + 1):
        s = t + k
        if finite:
            sx = f * f * (2.0 * _sw(s, alpha) - _sw(s - h, alpha) - _sw(s + h, alpha))
        else:
            sx = _sw(s, alpha + 2)
        sign = 1.0 if k % 2 == 0 else -1.0
        total += sign * _BINOMIAL[d, d + k] * sx
    return total


@njit(cache=True)
def basic_sums(j, m, s, f, alpha, d, norm, denominator, out):
    """``out[i] = BasicSum(J, M, S, F) / (scale**2 denominator)`` of every row (1 / edf).

    BasicSum = sum over lags l = 0 .. J of w_l s_z(l / S)**2, w_0 = 1,
    w_l = 2 (1 - l / M) for 0 < l < J, w_J = 1 - J / M; ``scale`` is
    ``norm[i]``, or s_z(0) of the row's own F where ``norm[i]`` is NaN.
    """
    for i in range(j.shape[0]):
        total = 0.0
        top = int(np.floor(j[i]))
        for lag in range(top + 1):
            lf = float(lag)
            if lag == 0:
                weight = 1.0
            elif lf < j[i]:
                weight = 2.0 * (1.0 - lf / m[i])
            elif lf == j[i]:
                weight = 1.0 - j[i] / m[i]
            else:
                weight = 0.0
            value = sz(lf / s[i], f[i], alpha[i], d)
            total += weight * value * value
        scale = norm[i] if not np.isnan(norm[i]) else sz(0.0, f[i], alpha[i], d)
        out[i] = total / (scale * scale * denominator[i])


#: :func:`greenhall_sums` takes the compiled loops once they are compiled (in this process or
#: numba's cache: 10 to 100 times faster than NumPy's sums), and NumPy's up to NUMPY_COLD_ROWS rows
#: while they are not (:mod:`avar._kernels.runtime.paths`: nothing to compile for a first call).
#: NUMPY_ROWS: the rows of a typical call (a long record's octave levels, a noise report's).
NUMPY_ROWS = 256
NUMPY_COLD_ROWS = 1 << 14
#: The dispatch's route (:func:`avar._kernels.runtime.paths.numpy_path`): one set lookup once compiled.
_ROUTE = ("greenhall_sums",)


def _sw_branch(t, a, alpha):
    """:func:`_sw` of the one noise exponent ``alpha`` (an int) elementwise: only its own power."""
    if alpha in (1, -1, -3):
        with np.errstate(divide="ignore", invalid="ignore"):
            log = np.where(a > 0.0, np.log(np.where(a > 0.0, a, 1.0)), 0.0)
        return t**2 * log if alpha == 1 else (-(t**4) * log if alpha == -1 else t**6 * log)
    if alpha == 2:
        return -a
    if alpha == 0:
        return a**3
    return -(a**5) if alpha == -2 else a**7


def _numpy_sw(t, alpha):
    """:func:`_sw` elementwise (each element's own exponent, computed for its group of exponents only)."""
    a = np.abs(t)
    values = np.unique(alpha)
    if values.size == 1:
        return _sw_branch(t, a, int(values[0])) + np.zeros(np.broadcast(t, alpha).shape)
    t, a, alpha = np.broadcast_arrays(t, a, alpha)
    out = np.empty(t.shape)
    for value in values.tolist():
        where = alpha == value
        out[where] = _sw_branch(t[where], a[where], int(value))
    return out


def _numpy_sz(t, f, alpha, d):
    """:func:`sz` elementwise (the same terms in the same order)."""
    finite = np.isfinite(f)
    every, some = bool(np.all(finite)), bool(np.any(finite))
    h = np.where(finite, 1.0 / np.where(finite, f, 1.0), 0.0)
    ff = np.where(finite, f, 0.0)
    total = np.zeros(np.broadcast(t, f, alpha).shape)
    for k in range(-d, d + 1):
        s = t + k
        if some:
            sx = ff * ff * (2.0 * _numpy_sw(s, alpha) - _numpy_sw(s - h, alpha) - _numpy_sw(s + h, alpha))
        if not every:
            sx = np.where(finite, sx, _numpy_sw(s, alpha + 2)) if some else _numpy_sw(s, alpha + 2)
        total += (1.0 if k % 2 == 0 else -1.0) * _BINOMIAL[d, d + k] * sx
    return total


def greenhall_sums(j, m, s, f, alpha, d, norm, denominator):
    """:func:`basic_sums` of every row, returned: by the compiled loops, or in NumPy (at most
    J_max + 1 lags a row) for up to :data:`NUMPY_COLD_ROWS` rows while the loops are not compiled
    yet (or when NumPy is forced)."""
    if not numpy_path(j.shape[0], NUMPY_COLD_ROWS, (basic_sums,), route=_ROUTE):
        out = np.empty(j.shape[0])
        basic_sums(j, m, s, f, alpha, d, norm, denominator, out)
        return out
    lags = np.arange(int(np.floor(j.max())) + 1, dtype=np.float64)[None, :]
    jj, mm = j[:, None], m[:, None]
    weights = np.where(lags == 0, 1.0, np.where(lags < jj, 2.0 * (1.0 - lags / mm),
                                                np.where(lags == jj, 1.0 - jj / mm, 0.0)))
    value = _numpy_sz(lags / s[:, None], f[:, None], alpha[:, None], d)
    scale = np.where(np.isnan(norm), _numpy_sz(np.zeros(j.shape[0]), f, alpha, d), norm)
    return np.sum(weights * value * value, axis=1) / (scale * scale * denominator)
