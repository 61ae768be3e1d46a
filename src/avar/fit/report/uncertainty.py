"""The uncertainty of a selected sensor model: its parameters' covariance from the levels' exact covariance.

The selection (:mod:`avar.fit.report.sensor_fit`) weighs each level by its own
degrees of freedom, as if the levels were independent. They are not (a random
walk's last octaves are 80 % correlated), and where terms mix, one power law
per level misstates their variances too. The parameters' covariance is
therefore the sandwich (:mod:`avar.fit.report.sandwich`) of the fit's weights
around S, the exact covariance of the maximal-overlap estimates under the
selected model itself (:func:`~avar.fit.covariance.structure.structure_covariance`).

A generalized-least-squares refit with weights S^-1 (the GMWM's efficient
step) was tried and not kept: on 100 simulated 2 h gyros it moved the median
error of K from 10.2 % to 10.2 % without a Gauss-Markov term and from 9.9 %
to 11.6 % with one (``benchmarks/noise_report_real.py``).
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from avar.fit.covariance.structure import ACCURACY, structure_covariance
from avar.fit.report.sandwich import parameter_covariance
from avar.fit.report.sensor_fit import SensorFit, enlarged_fit
from avar.fit.report.sensor_terms import weight_edf
from avar.fit.terms import Component

__all__ = ["with_level_covariance", "non_overlapping_fit", "model_levels", "EIGEN_FLOOR", "COMPETING",
           "STRONG_EVIDENCE", "ScaleEstimate", "encompassing_scale"]

#: Smallest eigenvalue kept in the levels' correlation: the sums over lags are exact to about
#: 1e-3 (:data:`~avar.fit.covariance.structure.ACCURACY`), so a direction of smaller variance is
#: not known to exist and must not be trusted.
EIGEN_FLOOR = ACCURACY


def model_levels(components: tuple[Component, ...], n: int, factors: np.ndarray) -> np.ndarray:
    """The maximal-overlap estimates' covariance under ``components``, its correlation's eigenvalues
    raised to :data:`EIGEN_FLOOR` (the variances kept)."""
    levels = structure_covariance(components, n, factors)
    spread = np.sqrt(np.diag(levels))
    values, vectors = np.linalg.eigh(levels / np.outer(spread, spread))
    correlation = (vectors * np.maximum(values, EIGEN_FLOOR)) @ vectors.T
    unit = np.sqrt(np.diag(correlation))
    return correlation / np.outer(unit, unit) * np.outer(spread, spread)


def with_level_covariance(fit: SensorFit, n: int) -> SensorFit:
    """The fit with ``levels`` (the estimates' covariance under it, ``n`` samples) and its parameters'
    covariance, the sandwich of the fit's weights around ``levels``.

    Examples
    --------
    >>> from avar.fit.report.sensor_fit import fit_sensor_model
    >>> m = 2 ** np.arange(14)
    >>> nu = 1.0 / m + 1e-6 * (2.0 * m**2 + 1) / (6.0 * m)     # WN + RW, exact
    >>> fit = with_level_covariance(fit_sensor_model(m, nu, (2**16 - 2 * m + 1) / m), 2**16)
    >>> fit.levels.shape, bool(fit.covariance[1, 1] > 0)
    ((14, 14), True)
    """
    levels = model_levels(fit.components, n, fit.factors)
    covariance = parameter_covariance(fit.components, fit.factors, weight_edf(fit.edf), levels)
    return dataclasses.replace(fit, covariance=covariance, levels=levels)


def non_overlapping_fit(fit: SensorFit, n: int, variances: np.ndarray) -> SensorFit:
    """The fit of non-overlapping ("to") estimates with their covariance: the maximal-overlap levels'
    correlation under the model, rescaled to the estimates' ``variances`` (from Greenhall's EDF).

    An approximation: the two estimators' correlations between levels differ somewhat.
    """
    levels = model_levels(fit.components, n, fit.factors)
    scale = np.sqrt(np.asarray(variances, dtype=np.float64) / np.diag(levels))
    levels = levels * np.outer(scale, scale)
    covariance = parameter_covariance(fit.components, fit.factors, weight_edf(fit.edf), levels)
    return dataclasses.replace(fit, covariance=covariance, levels=levels)


#: The IEEE terms that compete at the long taus (bias instability B and random walk K): where the selection
#: kept one and left the other out, the kept one's interval also holds the encompassing model's.
COMPETING = ("FN", "RW")
#: Criterion difference (2 log of a Bayes factor, BIC's approximation) above which the data reject the
#: encompassing model outright: Kass & Raftery's "very strong" evidence (> 10).
STRONG_EVIDENCE = 10.0


class ScaleEstimate(NamedTuple):
    """A per-sample ``scale`` and its sampling ``variance``."""

    scale: float
    variance: float


def encompassing_scale(fit: SensorFit, k: int) -> ScaleEstimate | None:
    """The scale of component ``k`` (FN or RW) and its variance in the encompassing long-tau model: the
    selected terms plus the :data:`COMPETING` ones the selection left out, refitted, with the sandwich
    covariance around the levels' exact covariance (:func:`~avar.fit.report.sensor_fit.enlarged_fit`).

    A selection that drops B (its evidence below the penalty) lets K absorb B's share of the long taus, with an
    interval conditional on B = 0: on 2 h simulated gyros with N, B and K, K's 95 % interval held the truth
    in about 0.8 of the draws, B's dropped ones nearly never. The union of the selected model's interval
    and this one (:mod:`avar.fit.report.rows`) holds the truth under either model: the interval of a
    selection between the two, widened by the uncertainty of that selection
    (``benchmarks/bench_simulate_recheck.py --truth-seeds 40``). None when ``k`` is not FN or RW, when
    nothing competing was left out, or when the data reject the encompassing model: its criterion (deviance
    + penalty per parameter, the selection's) above the selected model's by more than :data:`STRONG_EVIDENCE`
    (as when the term left out is absent from the sensor: the fit then zeroes it, or nearly).

    References: R. E. Kass, A. E. Raftery, "Bayes factors", JASA 90(430), 1995; S. T. Buckland, K. P.
    Burnham, N. H. Augustin, "Model selection: an integral part of inference", Biometrics 53(2), 1997.

    Examples
    --------
    >>> from avar.fit.report.sensor_fit import fit_sensor_model
    >>> m = 2 ** np.arange(16)
    >>> nu = 1.0 / m + 1e-7 * (2.0 * m**2 + 1) / (6.0 * m)     # WN + RW, exact
    >>> fit = with_level_covariance(fit_sensor_model(m, nu, (2**18 - 2 * m + 1) / m), 2**18)
    >>> fit.kinds, encompassing_scale(fit, 0), encompassing_scale(fit, 1)   # WN does not compete; no flicker here
    (('WN', 'RW'), None, None)
    """
    kind = fit.components[k].kind
    missing = tuple(other for other in COMPETING if other not in fit.kinds)
    if kind not in COMPETING or not missing:
        return None
    components, covariance, deviance = enlarged_fit(fit, missing)
    if deviance + fit.penalty * len(missing) - fit.deviance > STRONG_EVIDENCE:
        return None
    return ScaleEstimate(components[k].scale, float(covariance[k, k]))
