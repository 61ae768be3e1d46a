"""The fixed-slope log-log fit shared by AVLR, its bootstrap and the noise terms.

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
the tau axis: with ``freq`` in Hz, the usual continuous-time coefficients. The
table is the process classes' (:mod:`avar.models`: ``slope``, ``ad_coefficient``,
``coefficient_label``), read here, not restated.
:func:`avar.avlr` (one series, or one model per IMU sensor type pooled over
its axes), its bootstrap and the IEEE 952 noise terms all use these pieces.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from avar._validation import check_whole_numbers, short_repr
from avar.models import DR, QN, RW, WN, NoiseModel, Process

__all__ = ["PROCESSES", "SLOPES", "COEFFICIENTS", "check_scale_selections", "log_mean_estimate", "fit_slopes",
           "implied_allan_deviation", "per_sample_process", "per_sample_model", "parameter_label", "format_scales"]

#: Per-sample process classes, in R's order (the order of estimates and of the fitted model).
PROCESS_CLASSES = {cls.name: cls for cls in (WN, QN, RW, DR)}
#: Processes in R's order.
PROCESSES = tuple(PROCESS_CLASSES)
#: Log-log slope b of AD(tau) = c theta tau**b.
SLOPES = {name: cls.slope for name, cls in PROCESS_CLASSES.items()}
#: Coefficient c of AD(tau) = c theta tau**b.
COEFFICIENTS = {name: cls.ad_coefficient for name, cls in PROCESS_CLASSES.items()}
#: Parameter symbol and unit (u: data unit, s: unit of tau).
PARAMETER_LABELS = {name: cls.coefficient_label for name, cls in PROCESS_CLASSES.items()}


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
        if not isinstance(value, range) and np.ndim(value) > 1:
            raise ValueError(f"{argument} must be a flat list of scale numbers, got shape {np.shape(value)}")
        if isinstance(value, range) and len(value):  # check the ends before expanding the range
            ends = (min(value[0], value[-1]), max(value[0], value[-1]))
            if ends[0] < 1 or ends[1] > n_levels:
                raise ValueError(
                    f"{argument} = {value!r} reaches outside 1..{n_levels} "
                    f"(scales are 1-based level numbers of an Allan variance with {n_levels} levels)"
                )
        scales = check_whole_numbers(value, argument)
        if scales.size == 0:
            raise ValueError(f"{argument} selects no scale; give scale numbers between 1 and {n_levels}")
        outside = scales[(scales < 1) | (scales > n_levels)]
        if outside.size:
            raise ValueError(
                f"{argument} has scale(s) {short_repr(outside.tolist())} outside 1..{n_levels} "
                f"(scales are 1-based level numbers of an Allan variance with {n_levels} levels)"
            )
        if np.unique(scales).size != scales.size:
            raise ValueError(f"{argument} repeats a scale: {short_repr(scales.tolist())}; give each scale once")
        checked[process] = np.sort(scales)
    if not checked:
        names = ", ".join(p.lower() + suffix for p in PROCESSES)
        raise ValueError(f"select at least one process: give scale numbers to one of {names}")
    return checked


def log_mean_estimate(process: str, log_adev: np.ndarray, log_tau: np.ndarray) -> np.ndarray:
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
                f"the {process.lower()} scales {short_repr(scales.tolist())} need finite positive taus and Allan "
                "deviations (the log-log regression takes their logarithms)"
            )
        estimates[process] = float(log_mean_estimate(process, np.log(deviation), np.log(tau)))
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


def format_scales(scales: np.ndarray) -> str:
    """``[1, 2, 3, 5]`` -> ``"1-3, 5"``."""
    runs = np.split(scales, np.flatnonzero(np.diff(scales) != 1) + 1)
    return ", ".join(f"{r[0]}-{r[-1]}" if r.size > 1 else f"{r[0]}" for r in runs)
