"""The efficient step of the noise report: the selected model refitted with the levels' full covariance.

The selection (:mod:`avar.fit.report.sensor_fit`) weighs each level by its own
degrees of freedom, as if the levels were independent. They are not: a
random walk's last octaves are 80 % correlated. Once the model is chosen,
its parameters theta (per-sample scales, correlation times, frequencies) are
refitted by generalized least squares, the GMWM with efficient weights
(Guerrier et al. 2013)::

    theta = argmin (nu_hat - nu(theta))' W (nu_hat - nu(theta)),   W = (S + D)^-1,

S the exact covariance of the estimates under the selected model
(:func:`~avar.fit.report.level_covariance.level_covariance`) and D the model
discrepancy floor, diag((DISCREPANCY nu)^2): no sum of processes describes
a real sensor to better than that, and without it the shortest taus, known
to 0.1 %, would dictate the fit. The parameters' covariance is the sandwich
of W around S at the new estimate (:mod:`avar.fit.report.sandwich`).

The step is kept only when it keeps every term (no scale at its bound 0),
lowers the weighted criterion and, given a fit check, fits as many levels as
the maximum-likelihood model; otherwise that model stays, with the same
covariance.

References
----------
S. Guerrier, J. Skaloud, Y. Stebler, M.-P. Victoria-Feser, "Wavelet-variance-based
estimation for composite stochastic processes", JASA 108(503), 2013.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

from avar.fit.report.level_covariance import level_covariance
from avar.fit.report.sandwich import parameter_covariance
from avar.fit.report.sensor_fit import SensorFit
from avar.fit.report.sensor_terms import DISCREPANCY, Component, weight_edf

__all__ = ["efficient_fit", "non_overlapping_fit", "model_levels"]


#: Smallest eigenvalue kept in the levels' correlation: the sums over lags are exact to about
#: 1e-3, so a direction of smaller variance is not known to exist and must not be trusted.
EIGEN_FLOOR = 1e-3


def model_levels(components: tuple[Component, ...], n: int, factors: np.ndarray) -> np.ndarray:
    """The maximal-overlap estimates' covariance under ``components``, its correlation's eigenvalues
    raised to :data:`EIGEN_FLOOR` (the variances kept)."""
    levels = level_covariance(components, n, factors)
    spread = np.sqrt(np.diag(levels))
    values, vectors = np.linalg.eigh(levels / np.outer(spread, spread))
    correlation = (vectors * np.maximum(values, EIGEN_FLOOR)) @ vectors.T
    unit = np.sqrt(np.diag(correlation))
    return correlation / np.outer(unit, unit) * np.outer(spread, spread)


def non_overlapping_fit(fit: SensorFit, n: int, variances: np.ndarray) -> SensorFit:
    """The maximum-likelihood fit of non-overlapping ("to") estimates with their covariance: the
    maximal-overlap levels' correlation under the model, rescaled to the estimates' ``variances``
    (from Greenhall's EDF). An approximation (the two estimators' correlations differ somewhat),
    so the fit itself is not reweighted by it."""
    levels = model_levels(fit.components, n, fit.factors)
    scale = np.sqrt(np.asarray(variances, dtype=np.float64) / np.diag(levels))
    levels = levels * np.outer(scale, scale)
    covariance = parameter_covariance(fit.components, fit.factors, weight_edf(fit.edf), levels)
    return dataclasses.replace(fit, covariance=covariance, levels=levels)


def _free_shape(kind: str, shape: float) -> float:
    """The unbounded coordinate of a shape: -log(-log phi) of an AR1, logit(2 f) of a SIN."""
    return -math.log(-math.log(shape)) if kind == "AR1" else math.log(2.0 * shape / (1.0 - 2.0 * shape))


def _pack(components: tuple[Component, ...]) -> np.ndarray:
    shapes = [_free_shape(c.kind, c.shape) for c in components if c.kind in ("AR1", "SIN")]
    return np.concatenate([np.ones(len(components)), shapes])


def _bounds(components: tuple[Component, ...], factors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Scales >= 0; shapes within the selection's range: correlation times of 2 samples to m_max / 4,
    periods of 2.2 samples to 2.7 m_max (beyond, an AR1 or a sinusoid mimics white noise or a ramp)."""
    top = float(factors[-1])  # the ranges of sensor_fit._Problem
    ranges = {"AR1": (math.exp(-0.5), math.exp(-4.0 / max(top, 8.0))), "SIN": (0.37 / max(top, 1.0), 0.45)}
    low, high = [0.0] * len(components), [np.inf] * len(components)
    for c in components:
        if c.kind in ranges:
            a, b = ranges[c.kind]
            a, b = min(a, c.shape), max(b, c.shape)
            low.append(_free_shape(c.kind, a))
            high.append(_free_shape(c.kind, b))
    return np.array(low), np.array(high)


def _unpack(start: tuple[Component, ...], free: np.ndarray) -> tuple[Component, ...]:
    out, at = [], len(start)
    for c, ratio in zip(start, free):
        shape = c.shape
        if c.kind == "AR1":
            shape = math.exp(-math.exp(-float(np.clip(free[at], -40.0, 40.0))))
            at += 1
        elif c.kind == "SIN":
            shape = 0.5 / (1.0 + math.exp(-float(np.clip(free[at], -40.0, 40.0))))
            at += 1
        out.append(Component(c.kind, c.scale * float(ratio), shape))
    return tuple(out)


def efficient_fit(fit: SensorFit, n: int, check: Callable[[np.ndarray], float] | None = None) -> SensorFit:
    """The efficient step from a selected model (see the module docstring).

    Parameters
    ----------
    fit : SensorFit
        The selected maximum-likelihood model.
    n : int
        Series length (samples) of the maximal-overlap estimates.
    check : callable, optional
        ``check(implied_av) -> share`` of the levels that fit; the step must not lower it.

    Returns
    -------
    SensorFit
        With ``levels`` (the estimates' covariance) and the sandwich covariance.
    """
    from scipy.linalg import cho_factor, cho_solve, solve_triangular
    from scipy.optimize import least_squares

    factors, nu_hat = fit.factors, fit.nu_hat
    start = fit.components
    levels = model_levels(start, n, factors)
    spread = levels + np.diag((DISCREPANCY * fit.implied()) ** 2)
    lower = np.linalg.cholesky(spread)
    weights = cho_solve(cho_factor(spread), np.eye(factors.size))

    def residual(free: np.ndarray) -> np.ndarray:
        implied = np.sum([c.av(factors) for c in _unpack(start, free)], axis=0)
        return solve_triangular(lower, nu_hat - implied, lower=True)

    first = _pack(start)
    chosen = start
    if start:
        bounds = _bounds(start, factors)
        try:
            found = least_squares(residual, first, bounds=bounds, method="trf", x_scale=1.0, max_nfev=400,
                                  ftol=1e-12, xtol=1e-12, gtol=1e-12)
        except (ValueError, np.linalg.LinAlgError):
            found = None
        if (found is not None and np.all(found.x[:len(start)] > 1e-6)
                and found.cost < 0.5 * float(np.sum(residual(first) ** 2))):
            candidate = _unpack(start, found.x)
            implied = np.sum([c.av(factors) for c in candidate], axis=0)
            if check is None or check(implied) >= check(fit.implied()):
                chosen = candidate
    if chosen is not start:
        levels = model_levels(chosen, n, factors)
    covariance = parameter_covariance(chosen, factors, weights, levels)
    return dataclasses.replace(fit, components=chosen, covariance=covariance, levels=levels)
