"""Checks of a noise report that turn silent mistakes into warnings.

Each function returns warning texts (empty when all is well); none prints.

* :func:`fit_check`: the implied deviation against the empirical band;
* :func:`unit_warnings`: data whose size betrays the wrong unit flag;
* :func:`data_warnings`: clipped, stuck, spiky, moving or too-short channels.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from avar.fit.report.noise_terms import ACCEL, GYRO, GYRO_UNITS

__all__ = ["FitCheck", "fit_check", "unit_warnings", "data_warnings", "FIT_TOLERANCE", "FIT_SHARE", "OUTLIER_MAD"]

#: A level fits when the implied deviation is inside the band or within this relative distance.
FIT_TOLERANCE = 0.10
#: Share of the levels that must fit.
FIT_SHARE = 0.90
#: Robust z of a first difference beyond which a sample counts as an outlier (a Gaussian process,
#: white or integrated, has Gaussian differences: 2e-9 of them beyond 6 robust deviations).
OUTLIER_MAD = 6.0
#: Share of such jumps above which a channel is warned about (heavy tails of real sensors stay below).
OUTLIER_SHARE = 1e-3
#: Range of the 1 s means, in units of their white-noise spread (from the samples' steps), beyond which a
#: log is taken as moving or drifting strongly.
MOVING_RATIO = 100.0
G0 = 9.80665


class FitCheck(NamedTuple):
    """Which levels fit (``fits``), and the ``warning`` when fewer than :data:`FIT_SHARE` do (else None)."""

    fits: np.ndarray
    warning: str | None


def fit_check(channel: str, tau: np.ndarray, adev: np.ndarray, lower: np.ndarray, upper: np.ndarray,
              implied: np.ndarray) -> FitCheck:
    """Which levels fit, and a warning when fewer than 90 % do.

    >>> tau = np.array([1.0, 2.0, 4.0])
    >>> ok, text = fit_check("gx", tau, np.ones(3), np.full(3, 0.9), np.full(3, 1.1), np.array([1.0, 1.05, 2.0]))
    >>> ok.tolist(), text
    ([True, True, False], 'gx: the fitted model departs from the Allan deviation at 1 of 3 levels (tau 4 s: +100 %)')
    """
    ratio = implied / adev
    fits = ((implied >= lower) & (implied <= upper)) | (np.abs(ratio - 1.0) <= FIT_TOLERANCE)
    if fits.mean() >= FIT_SHARE:
        return FitCheck(fits, None)
    bad = np.flatnonzero(~fits)
    shown = ", ".join(f"{tau[j]:.3g} s: {100 * (ratio[j] - 1):+.0f} %" for j in bad[:4])
    more = f" and {bad.size - 4} more" if bad.size > 4 else ""
    return FitCheck(fits, f"{channel}: the fitted model departs from the Allan deviation at {bad.size} of {tau.size} "
                          f"levels (tau {shown}{more})")


def unit_warnings(channel: str, kind: str | None, unit: str, values: np.ndarray, white_density: float | None,
                  from_bag: bool) -> list[str]:
    """Warnings when the data's size contradicts the unit flag (``white_density``: N in data units / sqrt(Hz))."""
    out = []
    mean = float(np.nanmean(values)) if values.size else math.nan
    if from_bag and unit not in ("rad/s", "m/s^2"):
        flag = "--gyro-units rad/s" if kind == GYRO else "--accel-units m/s^2"
        out.append(f"{channel}: ROS bags hold SI units (sensor_msgs/Imu), but the data are read as {unit}; "
                   f"drop the unit flag or pass {flag}")
    if kind == ACCEL:
        if unit == "m/s^2" and 0.8 < abs(mean) < 1.2:
            out.append(f"{channel}: mean {mean:.3g} looks like gravity in g, not m/s^2; pass --accel-units g")
        elif unit == "g" and 7.8 < abs(mean) < 11.8:
            out.append(f"{channel}: mean {mean:.3g} looks like gravity in m/s^2, not g; pass --accel-units m/s^2")
        elif unit == "mg" and 0.8 < abs(mean) < 11.8:
            out.append(f"{channel}: mean {mean:.3g} looks like gravity in g or m/s^2, not mg; pass --accel-units")
    if kind == GYRO and white_density is not None and unit in GYRO_UNITS:
        arw = white_density * GYRO_UNITS[unit] / (math.pi / 180.0) * 60.0  # deg/sqrt(h)
        if unit == "rad/s" and arw > 30.0:
            out.append(f"{channel}: an angle random walk of {arw:.3g} deg/sqrt(h) is implausible for a gyroscope in "
                       "rad/s (57x too high if the data are in deg/s); pass --gyro-units deg/s if they are")
        elif unit == "deg/s" and arw < 1e-4:
            out.append(f"{channel}: an angle random walk of {arw:.3g} deg/sqrt(h) is implausibly low for deg/s; "
                       "pass --gyro-units rad/s if the data are in rad/s")
    return out


def data_warnings(channel: str, kind: str | None, values: np.ndarray, freq: float, levels: int,
                  robust: bool = False) -> list[str]:
    """Clipped, stuck, spiky, moving or too-short channels."""
    out = []
    x = np.asarray(values, dtype=np.float64)
    n = x.size
    if n < 2:
        return out
    low, high = float(np.min(x)), float(np.max(x))
    steps = np.diff(x)
    if high > low:
        for edge, name in ((high, "maximum"), (low, "minimum")):
            share = float(np.mean(x == edge))
            if share > 0.001 and share * n >= 10:
                out.append(f"{channel}: {100 * share:.3g} % of the samples sit at the {name} {edge:.6g} "
                           "(clipped or saturated); the noise terms are unreliable")
        repeated = float(np.mean(steps == 0.0))
        distinct = np.unique(x[: min(n, 100_000)]).size
        if repeated > 0.5 and distinct > 8:
            out.append(f"{channel}: {100 * repeated:.3g} % of consecutive samples repeat (stuck or held output)")
        departure = np.abs(steps - np.median(steps))
        spread = 1.4826 * float(np.median(departure))
        if spread > 0:
            outliers = int(np.count_nonzero(departure > OUTLIER_MAD * spread))
            if outliers > max(10, OUTLIER_SHARE * n):
                remedy = "the robust Allan variance sets them aside" if robust else \
                    "pass --robust (robust=True) to fit the clean process"
                out.append(f"{channel}: {outliers} samples jump beyond {OUTLIER_MAD:g} robust deviations "
                           f"(outliers); {remedy}")
    else:
        out.append(f"{channel}: the channel is constant ({low:.6g}): no noise to fit")
    if levels < 8:
        out.append(f"{channel}: only {levels} levels (N = {n}): too short to resolve bias instability or random walk; "
                   "the model holds at most the terms those levels support")
    window = int(round(freq))
    if kind in (GYRO, ACCEL) and window >= 1 and n >= 8 * window and high > low:
        means = x[: (n // window) * window].reshape(-1, window).mean(axis=1)
        drift = float(np.max(means) - np.min(means))
        white = 1.4826 * float(np.median(np.abs(steps))) / math.sqrt(2.0 * window)  # sample noise over 1 s
        if white > 0 and drift > MOVING_RATIO * white:
            out.append(f"{channel}: the 1 s means range over {drift:.3g}, {drift / white:.0f} times their noise: "
                       "the log moves or drifts strongly (the noise report assumes a sensor at rest)")
    return out
