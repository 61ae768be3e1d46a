"""The lag-1 noise identification's loops, by NumPy for short records and compiled for long ones.

:func:`lag1_alphas` and :func:`running_sums` are what :mod:`avar.stability.uncertainty.noise_id`
calls: up to :data:`NUMPY_POINTS` phase points while the kernels of
:mod:`avar._kernels.uncertainty.lag1` are not compiled yet (or when
:mod:`avar._kernels.runtime.paths` forces it) they take the NumPy twins here, with nothing to
compile; otherwise the kernels (2 to 8 times faster warm). Both follow Riley and
Greenhall's rule as Stable32 applies it (see :func:`decimated_alpha`); they differ only in
rounding, which moves rho by about 1e-15: alpha is the same but where 2 rho falls that close
to a half-integer (or rho to 0.25).

References
----------
W. J. Riley and C. A. Greenhall, "Power law noise identification using the lag 1
autocorrelation", Proc. 18th European Frequency and Time Forum, 2004.
"""

from __future__ import annotations

import numpy as np

from avar._kernels.runtime.paths import numpy_path
from avar._kernels.uncertainty.lag1 import lag1_kernels, lag1_levels, lag1_levels_split
from avar._kernels.uncertainty.noise_id import running_sum

#: Phase records of at most this many points take the NumPy twins while the kernels are not
#: compiled yet (:func:`avar._kernels.runtime.paths.numpy_path`; warm, the kernels are faster).
NUMPY_POINTS = 1 << 20


def _rho(w: np.ndarray) -> float:
    """rho = r1 / (1 + r1) of ``w`` with r1 = (sum c_i c_{i+1} / n) / (sum c_i**2 / (n - 1)),
    c = w less its mean (Stable32's form); NaN when w is constant."""
    centred = w - np.mean(w)
    power = float(np.einsum("i,i", centred, centred))
    if not power > 0.0:
        return np.nan
    r1 = float(np.einsum("i,i", centred[:-1], centred[1:])) / power * (w.size - 1.0) / w.size
    return r1 / (1.0 + r1)


def decimated_alpha(x: np.ndarray, m: int, dmax: int, line: float) -> float:
    """alpha of x[0], x[m], x[2m], ... by the lag-1 autocorrelation: the NumPy twin of
    :func:`avar._kernels.uncertainty.lag1.lag1_alpha_decimated`.

    With z the K = (N - 1) // m + 1 decimated points and t = i - (K - 1) / 2: ``line`` NaN
    (phase integrated from frequency data) removes z's least-squares line (the mean
    frequency); ``line`` a number (phase data, ``x`` lacking ``line * i``) gives z the line
    back and removes only its mean, as Stable32. The differences (d >= 1) are those of
    the least-squares residuals (a large frequency offset keeps its digits). Then z is
    differenced until rho < 0.25 or d = ``dmax``, and alpha = 2 - round(2 rho) - 2 d
    (round half to even). NaN for a constant series.

    >>> round(decimated_alpha(np.random.default_rng(0).standard_normal(1000), 1, 2, np.nan))
    2
    """
    z = x[::m]
    k = z.size
    t = np.arange(k, dtype=np.float64) - (k - 1) / 2.0
    slope = float(np.einsum("i,i", t, z)) / (k * (k * k - 1.0) / 12.0)
    residual = z - (float(np.mean(z)) + slope * t)
    w = residual if np.isnan(line) else z + (line * m) * t
    for d in range(dmax + 1):
        if d:
            residual = residual[1:] - residual[:-1]
            w = residual
        rho = _rho(w)
        if np.isnan(rho):
            return np.nan
        if rho < 0.25 or d >= dmax:
            return float(2.0 - np.round(2.0 * rho) - 2.0 * d)
    return np.nan


def with_drift(x: np.ndarray, drift: float) -> np.ndarray:
    """``x + drift * k (k - 1) / 2`` (k = 0 .. N - 1), with one temporary rather than five (the
    kernels add it point by point, with the same bits).

    >>> with_drift(np.zeros(4), 2.0).tolist()
    [0.0, 0.0, 2.0, 6.0]
    """
    seen = np.arange(-1.0, x.size - 1.0)  # k - 1
    seen *= np.arange(x.size, dtype=np.float64)
    seen *= 0.5 * drift  # exact halving: (p / 2) drift and p (drift / 2) round alike
    seen += x
    return seen


def lag1_alphas(x: np.ndarray, factors: np.ndarray, dmax: int, line: float, drift: float = 0.0) -> np.ndarray:
    """:func:`decimated_alpha` (or its kernel) of every factor; ``x`` contiguous finite float64
    phase, every factor leaving at least 3 decimated points. ``drift``: ``x`` lacks ``drift * k (k - 1) / 2``
    (a removed linear frequency drift), which the method sees (:func:`with_drift`; the kernels add it on the fly)."""
    if numpy_path(x.size, NUMPY_POINTS, lag1_kernels(factors.size)):
        seen = with_drift(x, drift) if drift else x
        return np.array([decimated_alpha(seen, m, int(dmax), line) for m in factors.tolist()], dtype=np.float64)
    found = np.empty(factors.size)
    (lag1_levels_split if found.size > 1 else lag1_levels)(x, factors, int(dmax), float(line), found, float(drift))
    return found


def running_sums(x: np.ndarray, drift: float, step: int) -> np.ndarray:
    """R(n)'s running sum of the phase ``x_i + drift i (i - 1) / 2`` at every ``step``-th index,
    ``out[q] = sum_{i < q step}`` for q = 0 .. N // step (by NumPy, or the kernel
    :func:`avar._kernels.uncertainty.noise_id.running_sum`: block sums, then their running sum).

    >>> running_sums(np.arange(5.0), 0.0, 2).tolist()
    [0.0, 1.0, 6.0]
    """
    n = x.size
    if numpy_path(n, NUMPY_POINTS, (running_sum,)):
        blocks = n // step
        values = x[: blocks * step]
        if drift:
            i = np.arange(blocks * step, dtype=np.float64)
            values = values + drift * (i * (i - 1.0) / 2.0)
        out = np.zeros(blocks + 1)
        np.cumsum(values.reshape(blocks, step).sum(axis=1), out=out[1:])
        return out
    out = np.empty(n // step + 1)
    running_sum(x, drift, step, out)
    return out
