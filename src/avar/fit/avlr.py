"""Allan variance linear regression (AVLR, the slope method): :func:`avlr`.

One implementation for a single series and for IMU data: :func:`fit_channels`
fits a group of channels (a series is a group of one; an IMU sensor type is
the group of its axes, pooled as R ``avar`` 0.1.3's ``avlr.imu_avar`` does, or
fitted axis by axis). The slopes, coefficients and units are in
:mod:`avar.fit.slopes`; the bootstrap in :mod:`avar.fit.bootstrap`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from avar._validation import check_replicates, check_seed
from avar._vocabulary import CONFIDENCE_95, check_rate, renamed, resolve_confidence
from avar.fit.results import SUFFIXES, AvlrResult, ImuAvlrResult
from avar.fit.slopes import PROCESSES, check_scale_selections, fit_slopes, implied_allan_deviation, per_sample_model
from avar.imu import ACCELEROMETER, GYROSCOPE, IMU
from avar.models import NoiseModel
from avar.stability.allan.estimator import avar as allan_variance
from avar.stability.allan.results import AllanVariance, ImuAllanVariance

__all__ = ["avlr", "fit_channels", "ChannelFit"]


def avlr(
    x: Any,
    qn: Any = None,
    wn: Any = None,
    rw: Any = None,
    dr: Any = None,
    ci: bool = False,
    B: int = 100,
    confidence: float = CONFIDENCE_95,
    seed: Any = None,
    *,
    alpha: float | None = None,
    rate: float | None = None,
    freq: float | None = None,
    qn_gyro: Any = None,
    wn_gyro: Any = None,
    rw_gyro: Any = None,
    dr_gyro: Any = None,
    qn_acc: Any = None,
    wn_acc: Any = None,
    rw_acc: Any = None,
    dr_acc: Any = None,
    per_axis: bool = False,
    auto: bool = False,
) -> Any:
    """Allan variance linear regression: fit WN, QN, RW and DR on chosen scales.

    Each selected process is fitted on its own scales by the fixed-slope
    log-log regression of :func:`fit_slopes`: WN sigma = exp(mean(log AD +
    log(tau) / 2)), QN Q = exp(mean(log AD + log tau)) / sqrt(3), RW gamma =
    sqrt(3) exp(mean(log AD - log(tau) / 2)), DR omega = sqrt(2) exp(mean(log
    AD - log tau)); units as in the table of :mod:`avar.fit.slopes` (with the rate in
    Hz: sigma in u/sqrt(Hz), Q in u s, gamma in u/s^(1/2), omega in u/s).

    Parameters
    ----------
    x : array_like, pandas.Series or AllanVariance
        A 1-D series (its Allan variance is computed with the defaults of
        :func:`avar.avar`: type "mo", octave grid, the rate ``rate``, else of a
        time index, else 1 Hz) or an :class:`~avar.AllanVariance` of any type and rate.
    qn, wn, rw, dr : int, range, sequence of int or "auto", optional
        1-based scale numbers (level j of the Allan variance) on which to
        fit each process; at least one is required (or ``auto=True``).
        ``"auto"``: the scales where the process dominates, found by
        :func:`avar.fit.auto_scales.auto_scales` (an error when it dominates
        nowhere); the chosen scales are in ``scales_used``.
    ci : bool
        Also compute parametric bootstrap intervals (for IMU data: per sensor
        type, the pooled estimator refitted on B simulated IMUs, or per axis).
    B : int
        Bootstrap replicates (>= 2).
    confidence : float
        Confidence level of the bootstrap intervals, in (0, 1); default 0.95.
    seed : None, int or numpy.random.Generator
        Seed of the bootstrap simulations.
    alpha : float, optional
        R's argument: 1 - ``confidence`` (``alpha=0.05`` is ``confidence=0.95``), kept
        so that R code ports line by line; give one of them.
    rate : float, optional
        Sampling rate (Hz) of a series ``x`` (an Allan variance or IMU carries its own).
    freq : float, optional
        R's name of ``rate`` (as in :func:`avar.avar`); give one of them.
    qn_gyro, wn_gyro, rw_gyro, dr_gyro, qn_acc, wn_acc, rw_acc, dr_acc
        For an :class:`~avar.ImuAllanVariance` (or :class:`~avar.IMU`) ``x``
        only: the scales of each process of the gyroscopes and the
        accelerometers, pooled over the axes of each sensor type as R
        ``avlr.imu_avar`` does: theta = exp(mean over axes k and scales j of
        (log AD_k(tau_j) - b log tau_j)) / c.
    per_axis : bool
        For IMU data only: fit every axis separately instead of jointly.
    auto : bool
        Fit every process that :func:`~avar.fit.auto_scales.auto_scales` finds
        dominant somewhere, on its scales (processes given explicitly keep
        their scales). For IMU data the scales are found per sensor type on
        the mean Allan variance of its axes.

    Returns
    -------
    AvlrResult
        Or :class:`~avar.ImuAvlrResult` for IMU data.

    Notes
    -----
    The bootstrap simulates the fitted per-sample model (:attr:`AvlrResult.model`)
    ``B`` times at the length ``N`` and rate of the Allan variance, computes
    the same estimator at the same averaging factors, refits on the same
    scales and reports 2 theta - mean(theta*), the bootstrap SD and the
    intervals estimate -/+ z SD, z the normal quantile of (1 + confidence) / 2.
    Unlike R ``avar`` 0.1.3 it simulates at the data's rate (R always used freq = 1) and uses the
    normal quantile (R used the density, so its intervals were 8 times
    too narrow). A progress bar is drawn on stderr when ``B * N`` is large
    and stderr is a terminal.

    References
    ----------
    IEEE Std 952-1997, annex C (slope method). S. Guerrier, J. Lee et al.,
    R package ``avar`` 0.1.3.

    Examples
    --------
    >>> from avar.models import RW, WN
    >>> x = (WN(sigma2=1) + RW(gamma2=1e-6)).simulate(100_000, seed=1)
    >>> fit = avlr(x, wn=range(1, 8), rw=range(12, 16))
    >>> fit.estimates.round(4)
    WN    0.9836
    RW    0.0008
    dtype: float64
    >>> print(avlr(x, wn=range(1, 8), ci=True, B=20, seed=2).ci.round(3))
        Estimate     SD  Lower  Upper
    WN     0.984  0.006  0.972  0.997
    """
    level = resolve_confidence(confidence, alpha, deprecated=False)
    rate, rate_name = renamed("rate", rate, "freq", freq, deprecated=False)
    if rate is not None and isinstance(x, (AllanVariance, ImuAllanVariance, IMU)):
        raise ValueError(f"{rate_name} applies to a series; this {type(x).__name__} carries its own rate "
                         f"({x.freq:g} Hz)")
    imu_requested = {
        GYROSCOPE: {"QN": qn_gyro, "WN": wn_gyro, "RW": rw_gyro, "DR": dr_gyro},
        ACCELEROMETER: {"QN": qn_acc, "WN": wn_acc, "RW": rw_acc, "DR": dr_acc},
    }
    for flag, value in (("per_axis", per_axis), ("auto", auto)):
        if not isinstance(value, (bool, np.bool_)):
            raise TypeError(f"{flag} must be True or False, got {value!r}")
    if isinstance(x, (ImuAllanVariance, IMU)):
        if any(v is not None for v in (qn, wn, rw, dr)):
            raise ValueError("IMU data take qn_gyro .. dr_acc (and per_axis), not qn/wn/rw/dr")
        bootstrap = _check_bootstrap(ci, B, level) if ci is not False else None
        return _imu_avlr(x, imu_requested, bool(per_axis), bool(auto), bootstrap, check_seed(seed))
    given = sorted(p.lower() + SUFFIXES[kind] for kind, sel in imu_requested.items() for p, v in sel.items()
                   if v is not None)
    if given or per_axis:
        raise ValueError(f"{given or ['per_axis']} apply to IMU data only; for one series use qn, wn, rw, dr")
    if isinstance(x, AllanVariance):
        av = x
    elif rate is None:
        av = allan_variance(x)
    else:
        av = allan_variance(x, "mo", check_rate(rate, rate_name))
    if len(av) < 2:
        raise ValueError(f"x has an Allan variance of {len(av)} level(s); AVLR needs at least 2 levels")
    requested = resolve_auto({"QN": qn, "WN": wn, "RW": rw, "DR": dr}, av, bool(auto))
    selections = check_scale_selections(requested, len(av))
    replicates, (level, significance) = _check_bootstrap(ci, B, level)
    seed = check_seed(seed)

    fit = fit_channels({None: av}, selections, av.freq, per_axis=False)
    estimates = fit.estimates
    table = None
    if ci:
        from avar.fit.bootstrap import parametric_bootstrap

        table = parametric_bootstrap(estimates, fit.models[None], av, selections, replicates, significance, seed)
    return AvlrResult(
        estimates=estimates,
        scales_used=selections,
        av=av,
        implied_ad=fit.implied[None],
        implied_ad_decomp=fit.decomposition[None],
        model=fit.models[None],
        ci=table,
        confidence=level if ci else None,
        replicates=replicates if ci else None,
    )


def _check_bootstrap(ci: Any, B: Any, level: tuple[float, float]) -> tuple[int, tuple[float, float]]:
    """(replicates, (confidence, significance)) of validated bootstrap options."""
    if not isinstance(ci, (bool, np.bool_)):
        raise TypeError(f"ci must be True or False, got {ci!r}")
    replicates = check_replicates(B, "B", minimum=2)
    return replicates, level


@dataclass(frozen=True)
class ChannelFit:
    """The fit of a group of channels: a joint Series, or a per-channel table."""

    estimates: pd.Series | pd.DataFrame
    models: dict[Any, NoiseModel]
    implied: dict[Any, np.ndarray]
    decomposition: dict[Any, dict[str, np.ndarray]]


def fit_channels(
    channels: Mapping[Any, AllanVariance], selections: Mapping[str, np.ndarray], freq: float, per_axis: bool
) -> ChannelFit:
    """AVLR of a group of channels on validated scale selections: the one implementation.

    A single series is a group of one channel. Jointly (``per_axis=False``),
    the fixed-slope regression pools every selected (channel, scale) pair
    into one model shared by the group; per axis, each channel gets its own
    fit and the estimates are a table channel x process.
    """
    models, implied, decomposition, rows = {}, {}, {}, {}
    if per_axis:
        for name, av in channels.items():
            rows[name] = fit_slopes(av.levels, av.adev, selections)
            models[name] = per_sample_model(rows[name], freq)
            decomposition[name] = _implied(rows[name], av)
        estimates = pd.DataFrame.from_dict(rows, orient="index", dtype=np.float64)
        estimates.columns.name = "Process"
    else:
        fitted = fit_slopes([av.levels for av in channels.values()], [av.adev for av in channels.values()], selections)
        estimates = pd.Series(fitted, dtype=np.float64)
        model = per_sample_model(fitted, freq)
        for name, av in channels.items():
            models[name] = model
            decomposition[name] = _implied(fitted, av)
    for name in channels:
        implied[name] = np.sum(list(decomposition[name].values()), axis=0)
    return ChannelFit(estimates, models, implied, decomposition)


def _implied(estimates: Mapping[str, float], av: AllanVariance) -> dict[str, np.ndarray]:
    return {p: implied_allan_deviation(p, v, av.levels) for p, v in estimates.items()}


def resolve_auto(requested: Mapping[str, Any], av: AllanVariance, auto: bool, suffix: str = "") -> dict[str, Any]:
    """Replace ``"auto"`` selections (and, with ``auto``, the missing ones) by automatic scales."""
    for process, value in requested.items():
        if isinstance(value, str) and value != "auto":
            raise TypeError(f"{process.lower()}{suffix} must be scale numbers (an int, a range or a list) or 'auto', "
                            f"got the string {value!r}")
    wanted = [p for p, v in requested.items() if isinstance(v, str)]
    if not wanted and not auto:
        return dict(requested)
    from avar.fit.auto_scales import auto_scales

    found = auto_scales(av).selection()
    resolved = dict(requested)
    for process in requested:
        if process in wanted:
            if process not in found:
                raise ValueError(f"{process.lower()}{suffix}='auto': the {process} process dominates no scale of "
                                 f"this Allan variance ({auto_scales(av).describe()}); give its scales explicitly")
            resolved[process] = found[process]
        elif auto and requested[process] is None and process in found:
            resolved[process] = found[process]
    return resolved


def _pooled(channels: Mapping[str, AllanVariance]) -> AllanVariance:
    """The mean Allan variance of the channels of one sensor type (their common levels)."""
    first = next(iter(channels.values()))
    size = min(len(av) for av in channels.values())
    mean = np.mean([av.allan[:size] for av in channels.values()], axis=0)
    return AllanVariance(levels=first.levels[:size], averaging_factors=first.averaging_factors[:size], allan=mean,
                         errors=first.errors[:size], n_differences=first.n_differences[:size], type=first.type,
                         freq=first.freq, n=first.n)


def _imu_avlr(imu_av: Any, requested: Mapping[str, Mapping[str, Any]], per_axis: bool,
              auto: bool = False, bootstrap: tuple[int, tuple[float, float]] | None = None,
              seed: Any = None) -> ImuAvlrResult:
    """One :func:`fit_channels` per sensor type of an IMU (R ``avlr.imu_avar``)."""
    if isinstance(imu_av, IMU):
        imu_av = allan_variance(imu_av)
    requested = {kind: (resolve_auto(sel, _pooled(imu_av.channels_of(kind)), auto, SUFFIXES[kind])
                        if kind in imu_av.present_types else sel) for kind, sel in requested.items()}
    short = {name: len(av) for name, av in imu_av.channels.items() if len(av) < 2}
    if short:
        raise ValueError(f"channels {short} have fewer than 2 levels; AVLR needs at least 2 levels")
    present = imu_av.present_types
    unknown = [kind for kind in present if kind not in requested]
    if unknown:
        raise ValueError(
            f"unknown sensor type(s) {unknown}; the IMU AVLR fits {GYROSCOPE} and {ACCELEROMETER} channels"
        )
    for kind, selections in requested.items():
        given = [p.lower() + SUFFIXES[kind] for p in PROCESSES if selections[p] is not None]
        if kind not in present and given:
            raise ValueError(f"{', '.join(given)} given but the IMU has no {kind.lower()} channels")
        if kind in present and not given:
            names = ", ".join(p.lower() + SUFFIXES[kind] for p in PROCESSES)
            raise ValueError(
                f"the IMU has {kind.lower()} channels but no process is selected for them; give one of {names}"
            )
    estimates, scales_used, models, implied, decomposition, intervals = {}, {}, {}, {}, {}, {}
    rng = np.random.default_rng(seed)
    for kind in present:
        channels = imu_av.channels_of(kind)
        n_levels = min(len(av) for av in channels.values())
        selections = check_scale_selections(requested[kind], n_levels, SUFFIXES[kind])
        scales_used[kind] = selections
        fit = fit_channels(channels, selections, imu_av.freq, per_axis)
        if per_axis:
            axis_of = dict(zip(imu_av.channels, imu_av.axes))
            fit.estimates.index = [axis_of[name] for name in fit.estimates.index]
        estimates[kind] = fit.estimates
        if bootstrap is not None:
            from avar.fit.bootstrap import imu_bootstrap

            intervals[kind] = imu_bootstrap(fit.estimates, fit.models, channels, selections, per_axis,
                                            bootstrap[0], bootstrap[1][1], rng)
        models.update(fit.models)
        implied.update(fit.implied)
        decomposition.update(fit.decomposition)
    return ImuAvlrResult(
        imu_av=imu_av,
        per_axis=per_axis,
        estimates=estimates,
        scales_used=scales_used,
        models={name: models[name] for name in imu_av.channels},
        implied_ad={name: implied[name] for name in imu_av.channels},
        implied_ad_decomp={name: decomposition[name] for name in imu_av.channels},
        ci=intervals if bootstrap is not None else None,
        confidence=bootstrap[1][0] if bootstrap is not None else None,
        replicates=bootstrap[0] if bootstrap is not None else None,
    )
