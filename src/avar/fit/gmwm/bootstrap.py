"""Parametric bootstraps of :func:`avar.gmwm`: the covariance of the empirical AV and the intervals.

Both simulate a fitted model with
:func:`avar.fit.bootstrap.replicate_allan_variances` (chunks of replicates,
one parallel kernel call per chunk for all their Allan variances); the
refits of the interval bootstrap run one after the other (each is a few
milliseconds of Python-bound least squares, which threads would not speed up).
"""

from __future__ import annotations

from collections.abc import Callable
from statistics import NormalDist
from typing import Any

import numpy as np
import pandas as pd

from avar.fit.bootstrap import replicate_allan_variances
from avar.fit.gmwm.model import ModelSpec
from avar.fit.gmwm.objective import GmwmFit, fit_av

__all__ = ["av_covariance", "bootstrap_fits", "interval_table"]


def av_covariance(
    spec: ModelSpec, theta: np.ndarray, n: int, factors: np.ndarray, type: str, replicates: int, seed: Any,
) -> np.ndarray:
    """Covariance of the empirical AV at ``factors`` under the model ``theta`` (for ``weights="full"``).

    The sample covariance S of ``replicates`` simulated Allan variances, shrunk
    towards its diagonal, (1 - l) S + l diag(S) with l = L / replicates (L
    scales), so that it stays well conditioned when replicates are few.
    """
    rng = np.random.default_rng(seed)
    draws = np.concatenate([allan for _, allan in replicate_allan_variances(
        spec.model(theta), n, factors, type, replicates, rng)])
    sample = np.cov(draws, rowvar=False)
    shrink = min(1.0, factors.size / replicates)
    return (1.0 - shrink) * sample + shrink * np.diag(np.diag(sample))


def bootstrap_fits(
    spec: ModelSpec, fit: GmwmFit, n: int, factors: np.ndarray, type: str, edf: np.ndarray, weights: str,
    replicates: int, seed: Any, progress: Callable[[int, int], None] | None = None,
) -> np.ndarray:
    """Estimates of ``replicates`` series simulated from the fit, shape (replicates, parameters).

    Each replicate is refitted from the fit's values with the data's weight
    matrix W held fixed (step 2 only; with ``weights="identity"`` the
    unweighted log fit): the usual fixed-weight GMM bootstrap, one
    least-squares run per replicate (re-estimating W, a bootstrap in itself
    for ``"full"``, would multiply the cost and changes W only at order
    N^-1/2).
    A replicate whose Allan variance has a zero level gives a row of NaN.
    """
    rng = np.random.default_rng(seed)
    start = spec.free(fit.theta)
    out = np.full((replicates, spec.size), np.nan)
    fixed = fit.whitener if weights != "identity" else None
    for first, allan in replicate_allan_variances(spec.model(fit.theta), n, factors, type, replicates, rng, progress):
        for row, nu_hat in enumerate(allan, start=first):
            if np.all(nu_hat > 0):
                out[row] = fit_av(spec, factors, nu_hat, edf, weights, starts=[start], whitener=fixed).theta
    return out


def interval_table(spec: ModelSpec, theta: np.ndarray, draws: np.ndarray, significance: float) -> pd.DataFrame:
    """Estimates, bootstrap standard errors and bias-corrected normal intervals.

    On the unconstrained scale u (log of a variance, atanh phi) the interval is
    c -/+ z s with c = 2 u_hat - median(u*), s = IQR(u*) / 1.349 (robust to the
    few replicates where a variance collapses towards 0) and z the normal
    quantile of 1 - significance / 2 (significance = 1 - confidence); it is mapped back by the transform, so it respects the constraints
    (variances > 0, |phi| < 1). SE is the standard deviation of the replicate
    estimates on the parameters' own scale.
    """
    valid = draws[np.all(np.isfinite(draws), axis=1)]
    if valid.shape[0] < 2:
        raise ValueError("fewer than 2 bootstrap replicates could be refitted; increase B")
    z = -NormalDist().inv_cdf(significance / 2.0)  # accurate for a tiny significance, unlike inv_cdf(1 - s / 2)
    free_hat = spec.free(theta)
    free_draws = np.array([spec.free(row) for row in valid])
    q25, q50, q75 = np.percentile(free_draws, [25.0, 50.0, 75.0], axis=0)
    centre = 2.0 * free_hat - q50
    spread = (q75 - q25) / 1.3489795003921634
    return pd.DataFrame(
        {
            "Estimate": theta,
            "SE": valid.std(axis=0, ddof=1),
            "Lower": spec.theta(centre - z * spread),
            "Upper": spec.theta(centre + z * spread),
        },
        index=pd.Index(spec.labels, name="Parameter"),
    )
