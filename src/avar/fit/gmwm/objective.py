"""Objective, weights, starting values and optimizer of :func:`avar.gmwm`.

With nu_hat_j the empirical Allan variance at averaging factors m_j and
nu_j(theta) the model's (the sum of its processes' closed forms), the
estimator minimizes (nu_hat - nu(theta))' W (nu_hat - nu(theta)). With the
Haar wavelet the maximal-overlap wavelet variance is AV / 2, so this is the
generalized method of wavelet moments (Guerrier et al. 2013) with weight 4 W.

It runs in two steps, each a Levenberg-Marquardt least-squares fit
(``scipy.optimize.least_squares``) over the unconstrained parameters of
:class:`~avar.fit.gmwm.model.ModelSpec`:

1. log scale: minimize sum_j (edf_j / 2) (log nu_hat_j - log nu_j(theta))^2,
   from a few starting points (below), keeping the best. ``2 / edf_j``
   approximates var(log nu_hat_j), with edf_j = (N - 2 m_j + 1) / m_j for the
   "mo" estimator (number of nearly independent differences; Percival &
   Walden 2000, sec. 8.4) and K_j - 1 for "to".
2. ``weights="diagonal"``: W = diag(1 / s_j^2) with s_j = nu_j(theta_1)
   sqrt(2 / edf_j), the approximate standard deviation of nu_hat_j at the
   step-1 fit theta_1 (a two-step GMM: weights from a consistent first step,
   residuals on the linear scale, where nu_hat is unbiased, so the log bias
   -1 / edf_j of step 1 does not reach the estimates). ``"full"``: W the
   inverse of a covariance matrix of nu_hat (from a short parametric
   bootstrap at theta_1, see :mod:`avar.fit.gmwm.bootstrap`); ``"efficient"``:
   W the inverse of the exact Gaussian covariance of nu_hat at theta_1
   (:mod:`avar.fit.covariance.exact`), the optimal GMM weight.
   ``"identity"``: step 1 alone, with edf_j = 2 (unweighted log scale).

Starting values: each process whose values are not given starts on the
tangent from below of the empirical curve: with every scale parameter set to
1 (and phi to a trial correlation time), its AV is multiplied by the largest
factor c that keeps it under nu_hat at every scale, and by 1/2 (the line of
the slope fits, touching the curve where that process dominates). A process
with a ``phi`` tries correlation times spread over the scales (several AR1
get distinct ones), giving three starting points; each gets a few
iterations and the best is carried to convergence.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from avar.fit.gmwm.implied import ImpliedAllanVariance
from avar.fit.gmwm.model import ModelSpec, transform_of

__all__ = ["equivalent_dof", "implied_av", "starting_points", "fit_av", "GmwmFit"]

#: Tolerances of the least-squares steps (tight: exact theory is recovered to ~1e-9).
TOLERANCE = 1e-12
#: Positions (fraction of the log scale range) of the trial correlation times.
TRIAL_POSITIONS = (0.2, 0.5, 0.8)
#: Function evaluations given to each starting point before the best one is finished.
SCREEN_EVALUATIONS = 6
WEIGHTINGS = ("diagonal", "full", "efficient", "identity")


def equivalent_dof(n: int, factors: np.ndarray, counts: np.ndarray, type: str) -> np.ndarray:
    """edf_j: (N - 2 m + 1) / m for "mo", K - 1 for "to", at least 1."""
    edf = counts / factors if type == "mo" else counts.astype(np.float64)
    return np.maximum(np.asarray(edf, dtype=np.float64), 1.0)


def implied_av(spec: ModelSpec, theta: np.ndarray, factors: np.ndarray) -> np.ndarray:
    """The model's Allan variance at ``factors``."""
    return np.asarray(spec.model(theta).theoretical_av(factors), dtype=np.float64)


def _tangent(cls: type, values: dict[str, float], factors: np.ndarray, nu_hat: np.ndarray) -> dict[str, float]:
    """Scale the positive parameters of one process so its AV touches nu_hat / 2 from below."""
    scaled = [key for key in values if transform_of(key).kind == "log"]
    base = np.asarray(cls(**values).theoretical_av(factors))
    doubled = np.asarray(cls(**{k: v * 2.0 if k in scaled else v for k, v in values.items()}).theoretical_av(factors))
    positive = (base > 0) & (doubled > 0)
    if not scaled or not positive.any():
        return values
    power = float(np.median(np.log2(doubled[positive] / base[positive])))  # AV scales as s**power
    ratio = float(np.min(nu_hat[positive] / base[positive])) / 2.0
    factor = ratio ** (1.0 / power) if power > 0 else 1.0
    return {k: v * factor if k in scaled else v for k, v in values.items()}


def starting_points(spec: ModelSpec, factors: np.ndarray, nu_hat: np.ndarray) -> list[np.ndarray]:
    """Unconstrained starting vectors (see the module docstring)."""
    unset_phi = [k for k, (cls, start) in enumerate(zip(spec.classes, spec.starts))
                 if start is None and ("phi" in spec.fields[k] or "f" in spec.fields[k])]
    positions = TRIAL_POSITIONS if unset_phi else (0.5,)
    low, high = np.log(factors[0]), np.log(factors[-1])
    points = []
    for shift in positions:
        theta: list[float] = []
        for k, (cls, start) in enumerate(zip(spec.classes, spec.starts)):
            given = start.parameters if start is not None else None
            if given is not None and all(v != 0 or transform_of(key).kind != "log" for key, v in given.items()):
                theta.extend(given.values())
                continue
            values = {f.name: 1.0 for f in fields(cls)}
            if "phi" in values or "f" in values:
                rank = unset_phi.index(k) if k in unset_phi else 0
                spot = (rank + shift) / max(len(unset_phi), 1)
                scale = float(np.exp(low + spot * (high - low)))  # a trial correlation time or period (samples)
                if "phi" in values:
                    values["phi"] = float(np.exp(-1.0 / scale))
                else:  # a sinusoid whose Allan variance peaks near m = 0.37 / f
                    values["f"] = min(0.37 / scale, 0.45)
            theta.extend(_tangent(cls, values, factors, nu_hat).values())
        points.append(spec.free(np.array(theta)))
    return points


def _least_squares(residuals: Callable, jacobian: Callable, start: np.ndarray, max_nfev: int | None = None) -> Any:
    from scipy.optimize import least_squares

    with np.errstate(over="ignore"):  # trial steps far out (a variance of e^300) overflow harmlessly
        return least_squares(residuals, start, jac=jacobian, method="lm", xtol=TOLERANCE, ftol=TOLERANCE,
                             gtol=TOLERANCE, max_nfev=max_nfev)


def _log_problem(implied: ImpliedAllanVariance, nu_hat: np.ndarray, root_w: np.ndarray) -> tuple[Callable, Callable]:
    log_nu = np.log(nu_hat)
    tiny = np.finfo(np.float64).tiny

    def residuals(free: np.ndarray) -> np.ndarray:
        return root_w * (log_nu - np.log(np.maximum(implied.value(free), tiny)))

    def jacobian(free: np.ndarray) -> np.ndarray:
        return -(root_w / np.maximum(implied.value(free), tiny))[:, None] * implied.jacobian(free)

    return residuals, jacobian


def _linear_problem(implied: ImpliedAllanVariance, nu_hat: np.ndarray, whitener: np.ndarray) -> tuple[Callable, Callable]:
    def residuals(free: np.ndarray) -> np.ndarray:
        gap = nu_hat - implied.value(free)
        return whitener * gap if whitener.ndim == 1 else whitener @ gap

    def jacobian(free: np.ndarray) -> np.ndarray:
        slope = implied.jacobian(free)
        return -(whitener[:, None] * slope if whitener.ndim == 1 else whitener @ slope)

    return residuals, jacobian


@dataclass(frozen=True)
class GmwmFit:
    """Outcome of :func:`fit_av`: parameters, objective, step-1 fit and the whitener used."""

    theta: np.ndarray
    objective: float
    first: np.ndarray
    whitener: np.ndarray
    converged: bool


def whitener_of(covariance: np.ndarray) -> np.ndarray:
    """L' with L L' = inverse(covariance): residuals L' d have d' W d as sum of squares."""
    precision = np.linalg.inv(covariance)
    return np.linalg.cholesky(0.5 * (precision + precision.T)).T


def fit_av(
    spec: ModelSpec, factors: np.ndarray, nu_hat: np.ndarray, edf: np.ndarray, weights: str,
    starts: list[np.ndarray] | None = None, covariance: Callable[[np.ndarray], np.ndarray] | None = None,
    whitener: np.ndarray | None = None,
) -> GmwmFit:
    """Fit ``spec`` to the Allan variances ``nu_hat`` at ``factors`` (both steps).

    ``starts``: unconstrained starting vectors (default :func:`starting_points`).
    ``covariance(theta_1)``: the covariance of nu_hat for ``weights="full"`` or ``"efficient"``;
    ``whitener``: a fixed step-2 weight instead, with one start: step 2 alone
    runs (the bootstrap refits reuse the data's weights, so a replicate
    costs one least-squares run from the data's estimate).
    """
    if len(factors) < spec.size:
        raise ValueError(
            f"the model has {spec.size} parameters but the Allan variance only {len(factors)} scales; "
            "use a finer tau grid (taus='all' or more taus) or fewer processes"
        )
    root_w = np.sqrt(edf / 2.0) if weights != "identity" else np.ones_like(edf)
    implied = ImpliedAllanVariance(spec, factors)
    if whitener is not None and weights != "identity":  # a bootstrap refit: step 2 from the data's fit
        final = _least_squares(*_linear_problem(implied, nu_hat, whitener), starts[0])
        theta = spec.theta(final.x)
        return GmwmFit(spec.canonical(theta), 2.0 * final.cost, theta, whitener, bool(final.success))
    log_problem = _log_problem(implied, nu_hat, root_w)
    points = starts if starts is not None else starting_points(spec, factors, nu_hat)
    if len(points) > 1:  # screen the starting points with a few iterations, then finish the best
        screened = [_least_squares(*log_problem, start, SCREEN_EVALUATIONS) for start in points]
        points = [min(screened, key=lambda found: found.cost).x]
    best = _least_squares(*log_problem, points[0])
    first = spec.theta(best.x)
    if weights == "identity":
        return GmwmFit(spec.canonical(first), 2.0 * best.cost, first, root_w, bool(best.success))
    if whitener is None:
        if weights == "diagonal":
            whitener = 1.0 / (implied.value(best.x) * np.sqrt(2.0 / edf))
        else:
            whitener = whitener_of(covariance(first))
    final = _least_squares(*_linear_problem(implied, nu_hat, whitener), best.x)
    return GmwmFit(spec.canonical(spec.theta(final.x)), 2.0 * final.cost, first, whitener, bool(final.success))
