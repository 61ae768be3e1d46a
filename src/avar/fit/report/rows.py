"""The rows of a noise report: every fitted term of one channel in SI and customary units.

From a :class:`~avar.fit.report.sensor_fit.SensorFit` (per-sample variances) to
the continuous-time coefficients an engineer compares with a datasheet, at
a sampling rate f (Hz), in data units u:

=====  ==========================  ===================================  ===========
term   coefficient                 from the per-sample variance c        unit
=====  ==========================  ===================================  ===========
QN     quantization Q              sqrt(c) / f                           u s
WN     angle/velocity random walk  sqrt(c / f)                           u / sqrt(Hz)
FN     bias instability B          sqrt(c) (AD plateau 0.664 B)          u
RW     rate/accel. random walk K   sqrt(c f)                             u / s / sqrt(Hz)
DR     ramp R                      sqrt(c) f                             u / s
AR1    Gauss-Markov sigma, T       sqrt(c / (1 - phi^2)); -1 / (f ln phi)  u; s
SIN    sinusoid amplitude, f0      sqrt(2 c); shape * f                  u; Hz
=====  ==========================  ===================================  ===========

Intervals: the squared coefficient c with sampling variance v is a scaled
chi-square with 2 c^2 / v degrees of freedom; shapes get a normal interval
(on the log scale for a correlation time). Where the selection kept one of
bias instability B and random walk K and left the other out, the kept one's
interval is the union of the selected model's and the encompassing model's
(the two refitted together; :func:`~avar.fit.report.uncertainty.encompassing_scale`):
the selection between them is uncertain too. A term left out of the model is
``absent``, except the three an engineer always needs (N, B, K): those are
``bound``, with the upper end of the enlarged model's interval of the report's
confidence, worded everywhere by :func:`bound_words` (``one-sided 97.5 % upper
bound`` at confidence 0.95: the 97.5 % quantile, the upper end of a two-sided
95 % interval).

**Groups.** Every row is ``IEEE 952`` (the five power laws, the in-run bias
stability, and Gauss-Markov and sinusoidal terms of the sensor's noise, IEEE 952
Annex C.1.6-7) or ``sensor filtering``: a term that models the sensor's own
output filtering or a vibration rather than its noise. A term is sensor filtering
when its Allan deviation peaks within the first :data:`FILTER_SAMPLES` = 16 sample
periods (4 octaves of the grid), where a digital sensor's anti-alias and
decimation filters shape the output and the white noise is not yet read cleanly:
a Gauss-Markov term of correlation time T <= 16 / (1.89 rate) (its deviation
peaks at 1.89 T, i.e. T within 8.5 samples of the grid's floor of 1 sample), a
sinusoid of frequency f0 >= 0.371 rate / 16 = rate / 43 (its deviation peaks at
0.371 / f0). Exports read the IEEE 952 terms N, B, K only.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd

from avar.fit.report.noise_terms import ACCEL, GYRO, TERM_NAMES, customary, to_si, unit_of
from avar.fit.report.sensor_fit import SensorFit, term_bound
from avar.fit.report.uncertainty import encompassing_scale
from avar.fit.terms import POWER_LAWS

__all__ = ["channel_rows", "minimum_row", "bound_words", "group_of", "BOUNDED", "ROW_COLUMNS", "IEEE_952",
           "SENSOR_FILTERING", "FILTER_SAMPLES"]

#: Terms reported as a bound when the selection leaves them out.
BOUNDED = ("WN", "FN", "RW")
ROW_COLUMNS = ["Channel", "Sensor", "Term", "Process", "Status", "Value", "Lower", "Upper", "Unit", "Customary",
               "Customary lower", "Customary upper", "Customary unit", "Tau (s)", "Group", "Note"]
#: The groups of the ``Group`` column.
IEEE_952, SENSOR_FILTERING = "IEEE 952", "sensor filtering"
#: A term whose Allan deviation peaks within this many sample periods models the sensor's filtering.
FILTER_SAMPLES = 16.0
#: Where the Allan deviation of a Gauss-Markov term (times T) and of a sinusoid (times its period) peaks.
GAUSS_MARKOV_PEAK, SINUSOID_PEAK = 1.89, 0.371
#: The coefficient of each IEEE term from its per-sample variance c at f Hz (the process class's ``coefficient``).
CONVERSIONS = {cls.name: cls.coefficient for cls in POWER_LAWS}
DEG = math.pi / 180.0
G0 = 9.80665


def bound_words(confidence: float) -> str:
    """The one wording of a bound of a term the data do not resolve, in every table, printout and export.

    The bound is the upper end of the two-sided interval of ``confidence``: the
    quantile 1 - (1 - confidence) / 2 of a one-sided bound.

    >>> bound_words(0.95)
    'one-sided 97.5 % upper bound'
    """
    return f"one-sided {100.0 * (1.0 - (1.0 - confidence) / 2.0):g} % upper bound"


def group_of(kind: str, shape: float | None) -> str:
    """``"sensor filtering"`` for a term whose Allan deviation peaks within :data:`FILTER_SAMPLES` samples
    (a Gauss-Markov term of phi = ``shape``, a sinusoid of ``shape`` cycles per sample), else ``"IEEE 952"``.

    >>> group_of("AR1", math.exp(-1 / 2)), group_of("SIN", 13.5 / 100), group_of("SIN", 0.5 / 100), group_of("WN", None)
    ('sensor filtering', 'sensor filtering', 'IEEE 952', 'IEEE 952')
    """
    if kind == "AR1" and shape is not None and 0.0 < shape < 1.0:
        peak = GAUSS_MARKOV_PEAK * -1.0 / math.log(shape)
    elif kind == "SIN" and shape:
        peak = SINUSOID_PEAK / shape
    else:
        return IEEE_952
    return SENSOR_FILTERING if peak <= FILTER_SAMPLES else IEEE_952


def _chi2_interval(c: float, variance: float, significance: float) -> tuple[float, float]:
    from scipy.special import chdtri

    if not (variance > 0 and c > 0):
        return c, c
    edf = 2.0 * c * c / variance
    return c * edf / chdtri(edf, significance / 2.0), c * edf / chdtri(edf, 1.0 - significance / 2.0)


def _row(channel: str, kind: str | None, term: str, process: str, status: str, unit: str, values: tuple,
         customary_unit: str = "", customary_values: tuple = (pd.NA, pd.NA, pd.NA), tau: Any = pd.NA,
         note: str = "", group: str = IEEE_952) -> dict[str, Any]:
    return {"Channel": channel, "Sensor": kind or "", "Term": term, "Process": process, "Status": status,
            "Value": values[0], "Lower": values[1], "Upper": values[2], "Unit": unit,
            "Customary": customary_values[0], "Customary lower": customary_values[1],
            "Customary upper": customary_values[2], "Customary unit": customary_unit, "Tau (s)": tau,
            "Group": group, "Note": note}


def _ieee_row(channel: str, kind: str | None, unit: str | None, process: str, status: str,
              values: tuple, note: str = "") -> dict[str, Any]:
    si = tuple(pd.NA if v is pd.NA else to_si(v, kind, unit) for v in values)
    custom, custom_unit = (pd.NA,) * 3, ""
    if kind in (GYRO, ACCEL):
        custom_unit = customary(process, 1.0, kind).unit
        custom = tuple(pd.NA if v is pd.NA else customary(process, v, kind).value for v in si)
    name = TERM_NAMES[kind][process]
    if process == "FN":
        name += " B (AD = 0.664 B)"  # IEEE 952's convention, stated
    return _row(channel, kind, name, process, status, unit_of(process, kind, unit), si, custom_unit, custom, note=note)


def channel_rows(channel: str, kind: str | None, unit: str | None, fit: SensorFit, rate: float,
                 significance: float) -> list[dict[str, Any]]:
    """The rows of one channel: IEEE terms (present, bound or absent), then Gauss-Markov and sinusoid terms."""
    rows = []
    by_kind: dict[str, list[int]] = {}
    for k, component in enumerate(fit.components):
        by_kind.setdefault(component.kind, []).append(k)
    for process, convert in CONVERSIONS.items():
        if process in by_kind:
            k = by_kind[process][0]
            c = fit.components[k].scale
            low, high = _chi2_interval(c, fit.scale_variance(k), significance)
            wider = encompassing_scale(fit, k)
            if wider is not None:  # B or K without the other: the union with the encompassing model's interval
                other = _chi2_interval(*wider, significance) if wider.scale > 1e-300 else \
                    (0.0, _normal_quantile(significance) * math.sqrt(max(wider.variance, 0.0)))
                low, high = min(low, other[0]), max(high, other[1])
            rows.append(_ieee_row(channel, kind, unit, process, "present",
                                  (convert(c, rate), convert(low, rate), convert(high, rate))))
        elif process in BOUNDED:
            bound = convert(max(term_bound(fit, process, 1.0 - significance / 2.0), 0.0), rate)
            rows.append(_ieee_row(channel, kind, unit, process, "bound", (pd.NA, 0.0, bound),
                                  note=f"not resolved by the data: {bound_words(1.0 - significance)}"))
        else:
            rows.append(_ieee_row(channel, kind, unit, process, "absent", (pd.NA,) * 3, note="rejected by the selection"))
    data_unit = unit or "u"
    z = _normal_quantile(significance)
    for number, k in enumerate(by_kind.get("AR1", []), start=1):
        component = fit.components[k]
        phi, c = component.shape, component.scale
        low, high = _chi2_interval(c, fit.scale_variance(k), significance)
        spread = 1.0 / (1.0 - phi * phi)
        sigma = tuple(to_si(math.sqrt(v * spread), kind, unit) for v in (c, low, high))
        time = -1.0 / (rate * math.log(phi))
        se_log = math.sqrt(max(fit.shape_variance(k), 0.0)) / (phi * abs(math.log(phi)))
        times = (time, time * math.exp(-z * se_log), time * math.exp(z * se_log))
        label, group = f"Gauss-Markov {number}", group_of("AR1", phi)
        rows.append(_row(channel, kind, f"{label} sigma", f"AR1_{number}", "present",
                         _si_unit(kind, unit, data_unit), sigma, tau=time, group=group))
        rows.append(_row(channel, kind, f"{label} correlation time", f"AR1_{number}.T", "present", "s", times,
                         group=group))
    for number, k in enumerate(by_kind.get("SIN", []), start=1):
        component = fit.components[k]
        c = component.scale
        low, high = _chi2_interval(c, fit.scale_variance(k), significance)
        amplitude = tuple(to_si(math.sqrt(2.0 * v), kind, unit) for v in (c, low, high))
        hertz = component.shape * rate
        spread = z * math.sqrt(max(fit.shape_variance(k), 0.0)) * rate
        group = group_of("SIN", component.shape)
        rows.append(_row(channel, kind, f"Sinusoid {number} amplitude", f"SIN_{number}", "present",
                         _si_unit(kind, unit, data_unit), amplitude, tau=1.0 / hertz, group=group))
        rows.append(_row(channel, kind, f"Sinusoid {number} frequency", f"SIN_{number}.f", "present", "Hz",
                         (hertz, max(hertz - spread, 0.0), hertz + spread), group=group))
    return rows


#: The AD minimum is read where the level averages at least this many non-overlapping clusters
#: (tau <= duration / 8): a minimum from a handful of clusters is mostly chance.
MIN_CLUSTERS = 8


def minimum_row(channel: str, kind: str | None, unit: str | None, tau: np.ndarray, adev: np.ndarray,
                lower: np.ndarray, upper: np.ndarray, duration: float | None = None) -> dict[str, Any]:
    """The Allan-deviation minimum (the datasheets' in-run bias stability), with its band.

    Taken over the well-sampled levels, tau <= ``duration`` / :data:`MIN_CLUSTERS` (at least 8
    non-overlapping clusters; ``duration`` = N / rate, s); when the minimum over every level
    lies beyond, the row's Note gives it with its tau.
    """
    tau = np.asarray(tau, dtype=np.float64)
    adev = np.asarray(adev, dtype=np.float64)
    well = np.ones(tau.size, dtype=bool) if duration is None else tau <= duration / MIN_CLUSTERS
    if not well.any():
        well[0] = True
    at = int(np.flatnonzero(well)[np.nanargmin(adev[well])])
    overall = int(np.nanargmin(adev))
    si = tuple(to_si(float(v[at]), kind, unit) for v in (adev, lower, upper))
    custom, custom_unit = (pd.NA,) * 3, ""
    if kind == GYRO:
        custom, custom_unit = tuple(v / DEG * 3600.0 for v in si), "deg/h"
    elif kind == ACCEL:
        custom, custom_unit = tuple(v / (G0 * 1e-6) for v in si), "ug"
    note = f"the empirical minimum over the levels with at least {MIN_CLUSTERS} clusters, with its chi-squared band"
    if overall != at:
        lowest = to_si(float(adev[overall]), kind, unit)
        shown = lowest / DEG * 3600.0 if kind == GYRO else lowest / (G0 * 1e-6) if kind == ACCEL else lowest
        note += (f"; the global minimum {shown:.4g} {custom_unit or _si_unit(kind, unit, unit or 'u')} at "
                 f"tau = {tau[overall]:g} s averages fewer than {MIN_CLUSTERS} clusters")
    return _row(channel, kind, "AD minimum (in-run bias stability)", "MIN", "measured",
                _si_unit(kind, unit, unit or "u"), si, custom_unit, custom, tau=float(tau[at]), note=note)


def _si_unit(kind: str | None, unit: str | None, fallback: str) -> str:
    if unit is not None and kind == GYRO:
        return "rad/s"
    if unit is not None and kind == ACCEL:
        return "m/s^2"
    return fallback


def _normal_quantile(significance: float) -> float:
    from scipy.special import ndtri

    return float(ndtri(1.0 - significance / 2.0))
