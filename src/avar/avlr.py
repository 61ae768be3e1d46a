"""Allan variance linear regression (AVLR, the slope method): :func:`avlr`.

A latent process whose Allan deviation is AD(tau) = c * theta * tau**b has a
straight line of known slope b in log-log coordinates; on scales where that
process dominates, theta follows from the mean intercept::

    theta = exp(mean(log AD(tau_j) - b log tau_j)) / c

==========  =======  ========  =============  ==========================
process     slope b  c         parameter      unit (data unit u, tau in s)
==========  =======  ========  =============  ==========================
WN          -1/2     1         sigma          u s^1/2 (u / sqrt(Hz))
QN          -1       sqrt(3)   Q              u s
RW          +1/2     1/sqrt(3) gamma          u / s^1/2
DR          +1       1/sqrt(2) omega          u / s
==========  =======  ========  =============  ==========================

These are the estimators of R ``avar`` 0.1.3 (``fit_avlr``), in the units of
the tau axis: with ``freq`` in Hz, the usual continuous-time coefficients.
Joint fits (one model per IMU sensor type, pooled over its axes) reuse the
public pieces :func:`check_scale_selections`, :func:`fit_slopes`,
:func:`implied_allan_deviation` and :func:`per_sample_model`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np
import pandas as pd

from avar._validation import check_whole_numbers
from avar.estimate import avar as allan_variance
from avar.models import DR, QN, RW, WN, NoiseModel, Process, check_count, check_real
from avar.results import AllanVariance, ImuAllanVariance, format_frequency, frozen_array, frozen_frame, frozen_series

__all__ = ["PROCESSES", "AvlrResult", "avlr", "check_scale_selections", "fit_slopes",
           "implied_allan_deviation", "per_sample_process", "per_sample_model"]

#: Processes in R's order (the order of estimates and of the fitted model).
PROCESSES = ("WN", "QN", "RW", "DR")
#: Per-sample process classes.
PROCESS_CLASSES = {"WN": WN, "QN": QN, "RW": RW, "DR": DR}
#: Log-log slope b of AD(tau) = c theta tau**b.
SLOPES = {"WN": -0.5, "QN": -1.0, "RW": 0.5, "DR": 1.0}
#: Coefficient c of AD(tau) = c theta tau**b.
COEFFICIENTS = {"WN": 1.0, "QN": np.sqrt(3.0), "RW": 1.0 / np.sqrt(3.0), "DR": 1.0 / np.sqrt(2.0)}
#: Parameter symbol and unit (u: data unit, s: unit of tau).
PARAMETER_LABELS = {"WN": "sigma [u s^1/2]", "QN": "Q [u s]", "RW": "gamma [u s^-1/2]", "DR": "omega [u s^-1]"}


def parameter_label(process: str, unit: str | None = None) -> str:
    """Symbol and unit of a process parameter, ``u`` replaced by the data unit when known.

    >>> parameter_label("WN"), parameter_label("RW", "deg/s")
    ('sigma [u s^1/2]', 'gamma [deg/s s^-1/2]')
    """
    label = PARAMETER_LABELS[process]
    return label.replace("[u ", f"[{unit} ") if unit else label


# --------------------------------------------------------------------------- building blocks
def check_scale_selections(selections: Mapping[str, Any], n_levels: int, suffix: str = "") -> dict[str, np.ndarray]:
    """Validate the scale selections of the processes to fit.

    Parameters
    ----------
    selections : mapping of process name to selection
        Keys among ``"WN", "QN", "RW", "DR"``; a value is None (process not
        fitted), a 1-based scale number, a range or a list/array of them.
    n_levels : int
        Number of levels of the Allan variance: scales run from 1 to n_levels.
    suffix : str
        Appended to the argument name in messages (``"wn" + "_gyro"``).

    Returns
    -------
    dict of process -> sorted int64 array of 1-based scale numbers, in the
    order WN, QN, RW, DR, unselected processes left out. ``ValueError``
    (naming the argument, e.g. ``wn``) when no process is selected or a scale
    is missing, repeated, not whole or out of range.

    Examples
    --------
    >>> check_scale_selections({"rw": None, "wn": range(1, 4)}, 10)
    {'WN': array([1, 2, 3])}
    """
    wanted = {str(key).upper(): value for key, value in selections.items()}
    unknown = set(wanted) - set(PROCESSES)
    if unknown:
        raise ValueError(f"unknown process(es) {sorted(unknown)}; use {list(PROCESSES)}")
    checked = {}
    for process in PROCESSES:
        value = wanted.get(process)
        if value is None:
            continue
        argument = process.lower() + suffix
        if isinstance(value, (str, bytes)):
            raise TypeError(f"{argument} must be scale numbers (an int, a range or a list), got a string")
        if np.ndim(value) > 1:
            raise ValueError(f"{argument} must be a flat list of scale numbers, got shape {np.shape(value)}")
        scales = check_whole_numbers(list(value) if isinstance(value, range) else value, argument)
        if scales.size == 0:
            raise ValueError(f"{argument} selects no scale; give scale numbers between 1 and {n_levels}")
        outside = scales[(scales < 1) | (scales > n_levels)]
        if outside.size:
            raise ValueError(
                f"{argument} has scale(s) {outside.tolist()} outside 1..{n_levels} "
                f"(scales are 1-based level numbers of an Allan variance with {n_levels} levels)"
            )
        if np.unique(scales).size != scales.size:
            raise ValueError(f"{argument} repeats a scale: {scales.tolist()}; give each scale once")
        checked[process] = np.sort(scales)
    if not checked:
        names = ", ".join(p.lower() + suffix for p in PROCESSES)
        raise ValueError(f"select at least one process: give scale numbers to one of {names}")
    return checked


def _log_mean_estimate(process: str, log_adev: np.ndarray, log_tau: np.ndarray) -> np.ndarray:
    """theta = exp(mean(log AD - b log tau)) / c over the last axis (batched)."""
    return np.exp(np.mean(log_adev - SLOPES[process] * log_tau, axis=-1)) / COEFFICIENTS[process]


def _series_list(values: Any) -> list[np.ndarray]:
    """One float64 array per series: a 1-D input is one series, a sequence or 2-D array several."""
    return [np.asarray(v, dtype=np.float64) for v in ([values] if np.ndim(values[0]) == 0 else values)]


def fit_slopes(
    levels: np.ndarray | Sequence[np.ndarray],
    adev: np.ndarray | Sequence[np.ndarray],
    selections: Mapping[str, Any],
) -> dict[str, float]:
    """Fixed-slope log-log regression of one or several pooled Allan deviations.

    For each selected process (see the module table for b and c)::

        theta = exp(mean over (series k, scale j) of (log AD_k(tau_kj) - b log tau_kj)) / c

    With several series (the axes of one IMU sensor type) the scale selection
    is applied to every series and the mean runs over all selected pairs,
    exactly as R ``avar`` pools the axes in ``avlr.imu_avar``.

    Parameters
    ----------
    levels : array_like or sequence of array_like
        Averaging times tau (s) of one series, or one array per series.
    adev : array_like or sequence of array_like
        Allan deviations matching ``levels``; positive on the selected scales.
    selections : mapping of process -> 1-based scale numbers
        As for :func:`check_scale_selections` (validated here against the
        shortest series).

    Returns
    -------
    dict of process -> parameter (float), in the order WN, QN, RW, DR.

    Examples
    --------
    >>> tau = np.array([1.0, 2.0, 4.0, 8.0])
    >>> fit_slopes(tau, 0.3 / np.sqrt(tau), {"WN": [1, 2, 3, 4]})
    {'WN': 0.3}
    >>> fit_slopes([tau, tau], [0.2 / np.sqrt(tau), 0.8 / np.sqrt(tau)], {"WN": [1, 2]})  # geometric mean
    {'WN': 0.4}
    """
    levels_list, adev_list = _series_list(levels), _series_list(adev)
    if len(levels_list) != len(adev_list) or any(t.shape != a.shape or t.ndim != 1 for t, a in zip(levels_list, adev_list)):
        raise ValueError("levels and adev must be matching 1-D arrays (or sequences of them), one per series")
    checked = check_scale_selections(selections, min(t.size for t in levels_list))
    estimates = {}
    for process, scales in checked.items():
        tau = np.concatenate([t[scales - 1] for t in levels_list])
        deviation = np.concatenate([a[scales - 1] for a in adev_list])
        if not np.all(np.isfinite(np.r_[tau, deviation]) & (np.r_[tau, deviation] > 0)):
            raise ValueError(
                f"the {process.lower()} scales {scales.tolist()} need finite positive taus and Allan "
                "deviations (the log-log regression takes their logarithms)"
            )
        estimates[process] = float(_log_mean_estimate(process, np.log(deviation), np.log(tau)))
    return estimates


def implied_allan_deviation(process: str, parameter: float, tau: Any) -> np.ndarray:
    """Allan deviation of one process at averaging times tau: c theta tau**b.

    WN sigma / sqrt(tau); QN sqrt(3) Q / tau; RW gamma sqrt(tau / 3);
    DR omega tau / sqrt(2).

    The drift line differs from R ``avar`` 0.1.3, which draws omega tau / 2
    although its own estimator, omega = sqrt(2) exp(mean(log AD - log tau)),
    inverts AD = omega tau / sqrt(2), the deviation of x_t = omega t
    (AV = omega^2 tau^2 / 2, the closed form ``av_dr``).

    Examples
    --------
    >>> implied_allan_deviation("WN", 2.0, [1.0, 4.0])
    array([2., 1.])
    >>> implied_allan_deviation("DR", np.sqrt(2), 3.0)
    array([3.])
    """
    if process not in PROCESSES:
        raise ValueError(f"unknown process {process!r}; use one of {list(PROCESSES)}")
    tau = np.atleast_1d(np.asarray(tau, dtype=np.float64))
    return COEFFICIENTS[process] * float(parameter) * tau ** SLOPES[process]


def per_sample_process(process: str, parameter: float, freq: float) -> Process:
    """The per-sample process of a parameter fitted in tau units, at rate ``freq`` (Hz).

    Chosen so that the process's closed-form Allan variance equals the
    fit's implied one (see each ``from_continuous``): WN sigma2 = sigma^2 f,
    QN q2 = Q^2 f^2, RW gamma2 = gamma^2 / f (exact for large m), DR
    omega / f per sample.

    Examples
    --------
    >>> per_sample_process("WN", 0.01, 100.0)
    WN(sigma2=0.01)
    >>> per_sample_process("DR", 2.0, 100.0)
    DR(omega=0.02)
    """
    if process not in PROCESSES:
        raise ValueError(f"unknown process {process!r}; use one of {list(PROCESSES)}")
    return PROCESS_CLASSES[process].from_continuous(parameter, freq)


def per_sample_model(estimates: Mapping[str, float], freq: float) -> NoiseModel:
    """Sum of :func:`per_sample_process` over fitted estimates (process -> value).

    Examples
    --------
    >>> per_sample_model({"WN": 0.5, "RW": 0.25}, 4.0)
    WN(sigma2=1) + RW(gamma2=0.015625)
    """
    if not estimates:
        raise ValueError("estimates is empty; give at least one process -> parameter")
    return sum((per_sample_process(p, v, freq) for p, v in estimates.items()), start=0)


# --------------------------------------------------------------------------- result
def format_scales(scales: np.ndarray) -> str:
    """``[1, 2, 3, 5]`` -> ``"1-3, 5"``."""
    runs = np.split(scales, np.flatnonzero(np.diff(scales) != 1) + 1)
    return ", ".join(f"{r[0]}-{r[-1]}" if r.size > 1 else f"{r[0]}" for r in runs)


@dataclass(frozen=True, eq=False)
class AvlrResult:
    """An AVLR fit: estimates, implied Allan deviations and fitted model.

    Build it with :func:`avlr`; the fields are read-only.

    Attributes
    ----------
    estimates : pandas.Series
        WN sigma, QN Q, RW gamma, DR omega of the fitted processes (index in
        that order), in tau units (see :mod:`avar.avlr`).
    scales_used : Mapping[str, ndarray]
        1-based scale numbers each process was fitted on.
    av : AllanVariance
        The Allan variance that was fitted.
    implied_ad : ndarray
        Sum of the processes' implied Allan deviations at every level (as R).
    implied_ad_decomp : Mapping[str, ndarray]
        Implied Allan deviation of every process at every level.
    model : NoiseModel
        The fitted model in per-sample parameters at ``av.freq`` (see
        :func:`per_sample_model`), ready to ``simulate``.
    ci : pandas.DataFrame or None
        With ``avlr(..., ci=True)``: index = process, columns ``Estimate``
        (bias-corrected 2 theta - mean(theta*)), ``SD``, ``Lower``, ``Upper``.
    alpha, replicates : float or None, int or None
        1 - confidence level and number of bootstrap replicates of ``ci``.
    """

    estimates: pd.Series
    scales_used: Mapping[str, np.ndarray]
    av: AllanVariance
    implied_ad: np.ndarray
    implied_ad_decomp: Mapping[str, np.ndarray]
    model: NoiseModel
    ci: pd.DataFrame | None = None
    alpha: float | None = None
    replicates: int | None = None

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        set_field(self, "estimates", frozen_series(self.estimates))
        set_field(self, "implied_ad", frozen_array(self.implied_ad))
        for name in ("scales_used", "implied_ad_decomp"):
            dtype = np.int64 if name == "scales_used" else np.float64
            set_field(self, name, MappingProxyType({k: frozen_array(v, dtype) for k, v in getattr(self, name).items()}))
        if self.ci is not None:
            set_field(self, "ci", frozen_frame(self.ci))

    def summary(self) -> pd.DataFrame:
        """The estimate table, one row per process.

        Columns ``Parameter`` (symbol and unit), ``Value`` (the fit) and,
        when bootstrap intervals were computed, ``Bias-corrected``, ``SD``,
        ``Lower``, ``Upper``.
        """
        table = pd.DataFrame({"Parameter": [parameter_label(p) for p in self.estimates.index], "Value": self.estimates})
        if self.ci is not None:
            table = table.join(self.ci.rename(columns={"Estimate": "Bias-corrected"}))
        table.index.name = "Process"
        return table

    def describe(self) -> str:
        """Fitted processes and their scales, one line."""
        parts = [
            f"{p} on scales {format_scales(s)} (tau {self.av.levels[s[0] - 1]:g} .. {self.av.levels[s[-1] - 1]:g} s)"
            for p, s in self.scales_used.items()
        ]
        return "AVLR fit: " + "; ".join(parts)

    def __str__(self) -> str:
        table = self.summary()
        lines = [self.describe(), "of the " + self.av.describe()]
        if self.ci is not None:
            lines.append(
                f"Bootstrap (B = {self.replicates}): bias-corrected estimates, SD and "
                f"{100 * (1 - self.alpha):g}% normal intervals"
            )
        lines.append(table.to_string(float_format=lambda v: f"{v:.6g}"))
        lines.append(f"Per-sample model at {format_frequency(self.av.freq)}: {self.model!r}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        values = ", ".join(f"{p}={v:.6g}" for p, v in self.estimates.items())
        return f"<AvlrResult {values}{' with CI' if self.ci is not None else ''}>"

    def _repr_html_(self) -> str:
        return f"<p>{self.describe()}<br>{self.av.describe()}</p>" + self.summary().to_html()

    def plot(self, **kwargs: Any):
        """Empirical and implied Allan deviation; see :func:`avar.plotting.plot_avlr`."""
        from avar.plotting import plot_avlr

        return plot_avlr(self, **kwargs)


# --------------------------------------------------------------------------- public entry
def avlr(
    x: Any,
    qn: Any = None,
    wn: Any = None,
    rw: Any = None,
    dr: Any = None,
    ci: bool = False,
    B: int = 100,
    alpha: float = 0.05,
    seed: Any = None,
    *,
    qn_gyro: Any = None,
    wn_gyro: Any = None,
    rw_gyro: Any = None,
    dr_gyro: Any = None,
    qn_acc: Any = None,
    wn_acc: Any = None,
    rw_acc: Any = None,
    dr_acc: Any = None,
    per_axis: bool = False,
) -> Any:
    """Allan variance linear regression: fit WN, QN, RW and DR on chosen scales.

    Each selected process is fitted on its own scales by the fixed-slope
    log-log regression of :func:`fit_slopes`: WN sigma = exp(mean(log AD +
    log(tau) / 2)), QN Q = exp(mean(log AD + log tau)) / sqrt(3), RW gamma =
    sqrt(3) exp(mean(log AD - log(tau) / 2)), DR omega = sqrt(2) exp(mean(log
    AD - log tau)); units as in the table of :mod:`avar.avlr` (with freq in
    Hz: sigma in u/sqrt(Hz), Q in u s, gamma in u/s^(1/2), omega in u/s).

    Parameters
    ----------
    x : array_like, pandas.Series or AllanVariance
        A 1-D series (its Allan variance is computed with the defaults of
        :func:`avar.avar`: type "mo", octave grid, freq from a time index or
        1) or an :class:`~avar.AllanVariance` of any type and freq.
    qn, wn, rw, dr : int, range or sequence of int, optional
        1-based scale numbers (level j of the Allan variance) on which to
        fit each process; at least one is required.
    ci : bool
        Also compute parametric bootstrap intervals.
    B : int
        Bootstrap replicates (>= 2).
    alpha : float
        1 - confidence level, in (0, 1).
    seed : None, int or numpy.random.Generator
        Seed of the bootstrap simulations.
    qn_gyro, wn_gyro, rw_gyro, dr_gyro, qn_acc, wn_acc, rw_acc, dr_acc
        For an :class:`~avar.ImuAllanVariance` (or :class:`~avar.IMU`) ``x``
        only: the scales of each process of the gyroscopes and the
        accelerometers; see :func:`avar.imu_avlr.imu_avlr`.
    per_axis : bool
        For IMU data only: fit every axis separately instead of jointly.

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
    intervals estimate -/+ z_{1-alpha/2} SD. Unlike R ``avar`` 0.1.3 it
    simulates at the data's rate (R always used freq = 1) and uses the
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
    imu_selections = {
        "qn_gyro": qn_gyro, "wn_gyro": wn_gyro, "rw_gyro": rw_gyro, "dr_gyro": dr_gyro,
        "qn_acc": qn_acc, "wn_acc": wn_acc, "rw_acc": rw_acc, "dr_acc": dr_acc,
    }
    from avar.imu import IMU

    if isinstance(x, (ImuAllanVariance, IMU)):
        if any(v is not None for v in (qn, wn, rw, dr)) or ci:
            raise ValueError("IMU data take qn_gyro .. dr_acc (and per_axis), not qn/wn/rw/dr; "
                             "bootstrap intervals (ci=True) are available for single series only")
        from avar.imu_avlr import imu_avlr

        return imu_avlr(x, per_axis=per_axis, **imu_selections)
    given = sorted(name for name, value in imu_selections.items() if value is not None)
    if given or per_axis:
        raise ValueError(f"{given or ['per_axis']} apply to IMU data only; for one series use qn, wn, rw, dr")
    av = x if isinstance(x, AllanVariance) else allan_variance(x)
    if len(av) < 2:
        raise ValueError(f"x has an Allan variance of {len(av)} level(s); AVLR needs at least 2 levels")
    selections = check_scale_selections({"QN": qn, "WN": wn, "RW": rw, "DR": dr}, len(av))
    if not isinstance(ci, (bool, np.bool_)):
        raise TypeError(f"ci must be True or False, got {ci!r}")
    replicates = check_count(B, "B", minimum=2)
    alpha = check_real(alpha, "alpha")
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must be in (0, 1) (e.g. 0.05 for 95% intervals), got {alpha!r}")

    estimates = pd.Series(fit_slopes(av.levels, av.adev, selections), dtype=np.float64)
    decomposition = {p: implied_allan_deviation(p, v, av.levels) for p, v in estimates.items()}
    model = per_sample_model(estimates.to_dict(), av.freq)
    table = None
    if ci:
        from avar.bootstrap import parametric_bootstrap

        table = parametric_bootstrap(estimates, model, av, selections, replicates, alpha, seed)
    return AvlrResult(
        estimates=estimates,
        scales_used=selections,
        av=av,
        implied_ad=np.sum(list(decomposition.values()), axis=0),
        implied_ad_decomp=decomposition,
        model=model,
        ci=table,
        alpha=alpha if ci else None,
        replicates=replicates if ci else None,
    )
