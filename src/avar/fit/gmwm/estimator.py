"""The joint estimator: :func:`gmwm`, a sum of processes fitted at all scales at once.

The model is parsed in :mod:`avar.fit.gmwm.model`, its Allan variance and
Jacobian come from :mod:`avar.fit.gmwm.implied`, the weights and the
optimizer from :mod:`avar.fit.gmwm.objective`, the bootstraps from
:mod:`avar.fit.gmwm.bootstrap`; the results are in :mod:`avar.fit.gmwm.results`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pandas as pd

from avar._validation import as_series, check_replicates, check_seed
from avar._vocabulary import CONFIDENCE_95, complement, resolve_confidence
from avar.fit.gmwm.model import ModelSpec, parse_model
from avar.fit.gmwm.objective import WEIGHTINGS, equivalent_dof, fit_av
from avar.fit.gmwm.results import GmwmResult, ImuGmwmResult
from avar.imu import ACCELEROMETER, GYROSCOPE, IMU
from avar.recording import Recording
from avar.stability.allan.estimator import avar as allan_variance
from avar.stability.allan.results import AllanVariance, ImuAllanVariance
from avar.stability.shared.grids import octave_factors

__all__ = ["gmwm", "empirical_allan_variance", "fit_allan_variance"]

#: Replicates of the parametric bootstrap behind ``weights="full"``.
FULL_REPLICATES = 200


def gmwm(
    x: Any, model: Any = None, *, taus: Any = "octave", weights: str = "diagonal", ci: bool = False, B: int = 100,
    confidence: float = CONFIDENCE_95, seed: Any = None, model_gyro: Any = None, model_acc: Any = None,
    alpha: float | None = None,
) -> GmwmResult | ImuGmwmResult:
    """Fit a sum of latent processes to the Allan variance at all scales at once (GMWM).

    Minimizes over theta (nu_hat - nu(theta))' W (nu_hat - nu(theta)), where
    nu_hat_j is the maximal-overlap Allan variance at averaging factor m_j and
    nu_j(theta) the model's (the sum of the processes' closed forms). With the
    Haar wavelet the wavelet variance is AV / 2, so this is the generalized
    method of wavelet moments of Guerrier et al. (2013), consistent where the
    slope method (:func:`avar.avlr`, each process read off a few scales as if
    the others were absent) is not (Guerrier, Molinari & Stebler 2016).

    Parameters
    ----------
    x : array_like, pandas.Series, Recording, AllanVariance, IMU or ImuAllanVariance
        A series (its "mo" Allan variance is computed on ``taus``; the rate
        comes from a time index or a one-column Recording, else 1 Hz), an Allan variance of any type
        (with its ``n_samples``, fitted on its own levels), or IMU data.
    model : str, process class, list or NoiseModel
        The processes to fit: ``"WN + RW + AR1"``, ``[avar.WN, avar.AR1]``, or
        instances whose values start the optimizer (``avar.WN(sigma2=1) +
        avar.RW(gamma2=1e-6)``). Any ``Process`` subclass (flicker noise
        included) works; see :mod:`avar.fit.gmwm.model` for the constraints
        (variances > 0 by a log, ``|phi| < 1`` by atanh). Repeated AR1 terms are
        ordered by phi (correlation time).
    taus : "octave" or as in :func:`avar.avar`
        Scales: ``"octave"`` is m = 1, 2, 4, ... 2**(floor(log2 N) - 1) (the
        octave grid of ``avar`` plus m = 1, which separates QN from WN).
    weights : {"diagonal", "full", "efficient", "identity"}
        ``"diagonal"`` (default): W = diag(1 / var(nu_hat_j)) with the
        asymptotic approximation var(nu_hat_j) = 2 nu_j(theta_1)^2 / edf_j,
        edf_j = (N - 2 m_j + 1) / m_j, at a first log-scale fit theta_1: a closed
        form, so a fit costs milliseconds. ``"full"``: W the inverse of the
        covariance of nu_hat from a short parametric bootstrap (200 series) at
        theta_1: it captures the correlation between neighbouring scales, which
        has no simple closed form for a sum of processes, at the price of
        simulating 200 series. ``"efficient"``: W the inverse of the exact
        Gaussian covariance of nu_hat at theta_1, computed from the
        autocovariance of the first differences
        (:mod:`avar.fit.covariance.exact`; "mo" AV of WN, QN, RW, DR and AR1
        only): the asymptotically optimal weighting, without simulation.
        ``"identity"``: unweighted on the log scale.
    ci : bool
        Parametric bootstrap: simulate the fitted model ``B`` times at the same
        N, refit each, report standard errors and intervals (see
        :func:`avar.fit.gmwm.bootstrap.interval_table`).
    B : int
        Bootstrap replicates (>= 2).
    confidence : float
        Confidence level of the bootstrap intervals, in (0, 1); default 0.95.
    seed : None, int or numpy.random.Generator
        Seed of the bootstraps.
    model_gyro, model_acc
        For IMU data: the model of the gyroscope and accelerometer channels,
        each channel fitted on its own (``ci`` applies to every channel).

    Returns
    -------
    GmwmResult
        Or :class:`~avar.fit.gmwm.results.ImuGmwmResult` for IMU data.

    References
    ----------
    S. Guerrier, J. Skaloud, Y. Stebler, M.-P. Victoria-Feser, "Wavelet-variance-based
    estimation for composite stochastic processes", JASA 108(503), 2013.
    S. Guerrier, R. Molinari, Y. Stebler, "Theoretical limitations of Allan
    variance-based regression for time series model estimation", IEEE SPL 23(5), 2016.
    D. B. Percival, A. T. Walden, Wavelet Methods for Time Series Analysis, 2000, ch. 8.

    Examples
    --------
    >>> from avar.models import RW, WN
    >>> truth = WN(sigma2=1.0) + RW(gamma2=1e-6)
    >>> fit = gmwm(truth.simulate(100_000, seed=1), "WN + RW")
    >>> fit.estimates.round(3)
    WN.sigma2    0.993
    RW.gamma2    0.000
    dtype: float64
    >>> exact = AllanVariance(levels=octave_factors(10**5), averaging_factors=octave_factors(10**5),
    ...     allan=truth.theoretical_av(octave_factors(10**5)), errors=np.zeros(16),
    ...     n_differences=10**5 - 2 * octave_factors(10**5) + 1, type="mo", freq=1.0, n=10**5)
    >>> bool(np.allclose(gmwm(exact, "WN + RW").estimates, [1.0, 1e-6], rtol=1e-9))
    True
    """
    if weights not in WEIGHTINGS:
        raise ValueError(f"weights must be one of {list(WEIGHTINGS)}, got {weights!r}")
    if not isinstance(ci, (bool, np.bool_)):
        raise TypeError(f"ci must be True or False, got {ci!r}")
    replicates = check_replicates(B, "B", minimum=2)
    seed = check_seed(seed)
    confidence, significance = resolve_confidence(confidence, alpha)
    options = {"weights": weights, "ci": bool(ci), "replicates": replicates, "confidence": confidence,
               "significance": significance}
    if isinstance(x, (IMU, ImuAllanVariance)):
        if model is not None:
            raise ValueError("IMU data take model_gyro and model_acc (one model per sensor type), not model")
        return _imu_gmwm(x, {GYROSCOPE: model_gyro, ACCELEROMETER: model_acc}, taus, seed, options)
    if model_gyro is not None or model_acc is not None:
        raise ValueError("model_gyro and model_acc apply to IMU data only; for one series give model")
    if model is None:
        raise ValueError("model is required: e.g. 'WN + RW' or [avar.WN, avar.RW]")
    spec = parse_model(model)
    return fit_allan_variance(empirical_allan_variance(x, taus), spec, seed=seed, **options)


def empirical_allan_variance(x: Any, taus: Any) -> AllanVariance:
    """The Allan variance a GMWM fits: ``x`` itself, or the "mo" AV of the series on ``taus``."""
    if isinstance(x, AllanVariance):
        if not (isinstance(taus, str) and taus == "octave"):
            raise ValueError("taus applies to a series; an AllanVariance is fitted on its own levels")
        return x
    if isinstance(x, Recording):
        if len(x.names) != 1:
            raise ValueError(f"x is a Recording of {len(x.names)} columns {list(x.names)}; fit one column, "
                             "e.g. avar.gmwm(recording[name], ...) with the rate given, or read an IMU")
        values, rate = as_series(x[x.names[0]], x.rate, rate_name="rate")
    else:
        values, rate = as_series(x, None)
    grid = octave_factors(values.size) / rate if isinstance(taus, str) and taus == "octave" else taus
    return allan_variance(values, "mo", rate, taus=grid)


def fit_allan_variance(
    av: AllanVariance, spec: ModelSpec, *, weights: str = "diagonal", ci: bool = False, replicates: int = 100,
    confidence: float = 0.95, significance: float | None = None, seed: Any = None,
) -> GmwmResult:
    """The GMWM fit of one validated Allan variance: the one implementation for series and IMU channels.

    ``significance`` (1 - ``confidence``, its :func:`~avar._validation.complement` by default) sets the
    intervals' normal quantile.
    """
    if significance is None:
        significance = complement(confidence)
    factors = np.asarray(av.averaging_factors, dtype=np.int64)
    nu_hat = np.asarray(av.allan, dtype=np.float64)
    if not np.all(np.isfinite(nu_hat) & (nu_hat > 0)):
        zero = av.levels[~(nu_hat > 0)].tolist()
        raise ValueError(f"the Allan variance is zero or not finite at tau = {zero}; the fit needs positive "
                         "values at every scale (a constant or exactly linear series has no noise to fit)")
    edf = equivalent_dof(av.n, factors, np.asarray(av.n_differences), av.type)
    rng = np.random.default_rng(seed)
    covariance = None
    if weights == "efficient":
        from avar.fit.covariance.exact import exact_covariance

        check_efficient(spec, av.type)

        def covariance(theta: np.ndarray) -> np.ndarray:
            return exact_covariance(spec.model(theta), av.n, factors)
    elif weights == "full":
        from avar.fit.gmwm.bootstrap import av_covariance

        def covariance(theta: np.ndarray) -> np.ndarray:
            return av_covariance(spec, theta, av.n, factors, av.type, FULL_REPLICATES, rng)

    fit = fit_av(spec, factors, nu_hat, edf, weights, covariance=covariance)
    model = spec.model(fit.theta)
    table = None
    if ci:
        from avar.fit.gmwm.bootstrap import bootstrap_fits, interval_table

        draws = bootstrap_fits(spec, fit, av.n, factors, av.type, edf, weights, replicates, rng)
        table = interval_table(spec, fit.theta, draws, significance)
    decomposition = {label: np.asarray(p.theoretical_av(factors), dtype=np.float64)
                     for label, p in zip(spec.component_labels, model.components)}
    return GmwmResult(
        estimates=pd.Series(fit.theta, index=list(spec.labels), dtype=np.float64),
        model=model, av=av, implied_av=np.sum(list(decomposition.values()), axis=0), decomposition=decomposition,
        objective=fit.objective, weights=weights, ci=table, confidence=confidence if ci else None,
        replicates=replicates if ci else None, converged=fit.converged,
    )


def check_efficient(spec: ModelSpec, type: str) -> None:
    """Raise ValueError unless the AV is "mo" and every process has an exact covariance
    (:data:`avar.fit.covariance.exact.SUPPORTED`)."""
    from avar.fit.covariance.exact import SUPPORTED

    if type != "mo":
        raise ValueError(f"weights='efficient' needs a maximal-overlap ('mo') Allan variance, got type {type!r}; "
                         "use weights='full' or 'diagonal'")
    unknown = [cls.name for cls in spec.classes if not issubclass(cls, SUPPORTED)]
    if unknown:
        names = [cls.name for cls in SUPPORTED]
        raise ValueError(f"weights='efficient' supports {', '.join(names[:-1])} and {names[-1]}, not {unknown}; "
                         "use weights='full'")


def _imu_gmwm(x: Any, models: dict[str, Any], taus: Any, seed: Any, options: dict[str, Any]) -> ImuGmwmResult:
    """One :func:`fit_allan_variance` per channel, with the model of its sensor type."""
    if isinstance(x, IMU):
        grid = octave_factors(x.n_samples) / x.rate if isinstance(taus, str) and taus == "octave" else taus
        x = allan_variance(x, taus=grid)
    elif not (isinstance(taus, str) and taus == "octave"):
        raise ValueError("taus applies to an IMU; an ImuAllanVariance is fitted on its own levels")
    present = x.present_types
    for kind, argument in ((GYROSCOPE, "model_gyro"), (ACCELEROMETER, "model_acc")):
        if kind in present and models[kind] is None:
            raise ValueError(f"the IMU has {kind.lower()} channels; give {argument} (e.g. 'WN + RW')")
        if kind not in present and models[kind] is not None:
            raise ValueError(f"{argument} given but the IMU has no {kind.lower()} channels")
    specs = {kind: parse_model(models[kind]) for kind in present}
    seeds = np.random.default_rng(seed).spawn(len(x.channels))
    fits = {name: fit_allan_variance(av, specs[kind], seed=child, **options)
            for (name, av), kind, child in zip(x.channels.items(), x.sensor_types, seeds)}
    return ImuGmwmResult(imu_av=x, fits=fits)
