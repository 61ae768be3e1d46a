"""The IMU noise report: :func:`noise_report`, from a log to ARW, bias instability and RRW.

One call, no scales to pick: for every channel, the Allan variance (octave
grid), the joint weighted fit of the IEEE 952 terms
(:mod:`avar.fit.noise_fit`), the scales where each term dominates
(:mod:`avar.fit.auto_scales`), chi-squared intervals, and the terms in SI and
customary units (:mod:`avar.fit.noise_terms`). The result is a
:class:`~avar.fit.report_result.NoiseReport`.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import pandas as pd

from avar._validation import check_real
from avar.fit.auto_scales import auto_scales, level_edf
from avar.fit.noise_fit import TERMS, TermFit, fit_noise_terms
from avar.fit.noise_terms import ACCEL, GYRO, TERM_NAMES, check_unit, customary, to_si, unit_of
from avar.fit.report_result import NoiseReport
from avar.imu import IMU
from avar.stability.allan import avar as allan_variance
from avar.stability.results import AllanVariance, ImuAllanVariance

__all__ = ["noise_report", "term_rows", "infer_sensor_type"]

DEFAULT_UNITS = {GYRO: "rad/s", ACCEL: "m/s^2"}


def infer_sensor_type(name: str) -> str | None:
    """Gyroscope / accelerometer from a column name (``gx``, ``gyro_x``, ``angular_velocity.y``, ``acc_z``).

    >>> [infer_sensor_type(n) for n in ("gyro_x", "angular_velocity.z", "ax", "Accel. Y", "temp")]
    ['Gyroscope', 'Gyroscope', 'Accelerometer', 'Accelerometer', None]
    """
    low = str(name).lower()
    if low.startswith("gyr") or "angular_velocity" in low or low in ("gx", "gy", "gz", "wx", "wy", "wz"):
        return GYRO
    if low.startswith("acc") or "linear_acceleration" in low or low in ("ax", "ay", "az"):
        return ACCEL
    return None


def _columns_of(x: Any) -> Mapping[str, Any]:
    columns = x.columns
    if isinstance(columns, pd.DataFrame):
        return {str(c): columns[c].to_numpy() for c in columns.columns}
    if isinstance(columns, Mapping):
        return {str(k): np.asarray(v) for k, v in columns.items()}
    raise TypeError(f"x.columns must be a DataFrame or a mapping of column name -> values, got {type(columns).__name__}")


def _selected(names: list[str], gyro: Any, accel: Any) -> list[tuple[str, str | None]]:
    """(column, sensor type) pairs: the named gyro/accel columns, or every column with an inferred type."""
    if gyro is None and accel is None:
        return [(name, infer_sensor_type(name)) for name in names]
    chosen = []
    for kind, selector, role in ((GYRO, gyro, "gyro"), (ACCEL, accel, "accel")):
        for name in [selector] if isinstance(selector, str) else list(selector or []):
            if name not in names:
                raise ValueError(f"{role} column {name!r} is not a column of x; the columns are {names}")
            chosen.append((name, kind))
    return chosen


def _channels(x: Any, freq: Any, gyro: Any, accel: Any, taus: Any, type: str, single_kind: str | None) -> tuple:
    """(channels [(name, sensor type, AllanVariance)], source, topic) from any accepted input."""
    if isinstance(x, IMU):
        x = allan_variance(x, type=type, taus=taus)
    if isinstance(x, ImuAllanVariance):
        rows = [(name, kind, av) for (name, av), kind in zip(x.channels.items(), x.sensor_types)]
        return rows, x.sensor, None
    if isinstance(x, AllanVariance):
        return [(x.name or "x", single_kind, x)], None, None
    if isinstance(x, pd.DataFrame) or (hasattr(x, "columns") and hasattr(x, "freq")):
        if isinstance(x, pd.DataFrame):
            values = {str(c): x[c] for c in x.columns}
            rate, source, topic = freq, None, None
        else:
            values = _columns_of(x)
            rate = x.freq if freq is None else freq
            source, topic = getattr(x, "source", None), getattr(x, "topic", None)
        rows = []
        for name, kind in _selected(list(values), gyro, accel):
            rows.append((name, kind, allan_variance(values[name], type=type, freq=rate, taus=taus)))
        if not rows:
            raise ValueError("x has no data column")
        return rows, None if source is None else str(source), None if topic is None else str(topic)
    name = getattr(x, "name", None) if isinstance(x, pd.Series) else None
    av = allan_variance(x, type=type, freq=freq, taus=taus)
    return [(str(name) if name is not None else "x", single_kind, av)], None, None


def _interval(squared: float, edf: float, alpha: float) -> tuple[float, float]:
    """Chi-squared interval of a coefficient whose square has ``edf`` degrees of freedom."""
    if not math.isfinite(edf):
        return math.sqrt(squared), math.sqrt(squared)
    from scipy.stats import chi2

    low = squared * edf / chi2.ppf(1.0 - alpha / 2.0, edf)
    high = squared * edf / chi2.ppf(alpha / 2.0, edf)
    return math.sqrt(low), math.sqrt(high)


def term_rows(channel: str, kind: str | None, unit: str | None, av: AllanVariance, fit: TermFit,
              scales: Mapping[str, np.ndarray], alpha: float) -> list[dict[str, Any]]:
    """The table rows of one channel: one per IEEE term, SI and customary values, intervals, scales."""
    from avar.fit.slopes import format_scales

    model = np.sqrt(fit.model_av(av.levels))
    rows = []
    for term in TERMS:
        present = fit.present[term]
        row: dict[str, Any] = {
            "Channel": channel, "Sensor": kind or "", "Term": TERM_NAMES[kind][term], "Process": term,
            "Status": "present" if present else "absent",
            "Value": pd.NA, "Lower": pd.NA, "Upper": pd.NA, "Unit": unit_of(term, kind, unit),
            "Customary": pd.NA, "Customary lower": pd.NA, "Customary upper": pd.NA, "Customary unit": "",
            "Tau (s)": pd.NA, "Scales": "",
        }
        if kind in (GYRO, ACCEL):
            row["Customary unit"] = customary(term, 1.0, kind)[1]
        if present:
            value = fit.coefficient(term)
            lower, upper = _interval(fit.squared[term], fit.edf(term), alpha)
            si = [to_si(v, kind, unit) for v in (value, lower, upper)]
            row.update({"Value": si[0], "Lower": si[1], "Upper": si[2]})
            if kind in (GYRO, ACCEL):
                row.update({"Customary": customary(term, si[0], kind)[0],
                            "Customary lower": customary(term, si[1], kind)[0],
                            "Customary upper": customary(term, si[2], kind)[0]})
            used = scales.get(term, np.zeros(0, dtype=np.int64))
            row["Scales"] = format_scales(np.asarray(used)) if len(used) else "-"
            if term == "FN":
                row["Tau (s)"] = float(av.levels[int(np.argmin(model))])
        rows.append(row)
    return rows


def noise_report(
    x: Any,
    gyro_units: str | None = None,
    accel_units: str | None = None,
    *,
    freq: float | None = None,
    gyro: Any = None,
    accel: Any = None,
    alpha: float = 0.05,
    type: str = "mo",
    taus: Any = "octave",
    name: str | None = None,
) -> NoiseReport:
    """IEEE 952 noise terms of every channel, with no scales to choose.

    Per channel: quantization Q, angle / velocity random walk N, bias
    instability B (with the tau where it is read), rate / acceleration random
    walk K and ramp R, from the joint weighted fit of::

        AV(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2

    to the Allan variance at every level (:func:`avar.fit.noise_fit.fit_noise_terms`;
    terms not significantly above zero are *absent*, never NaN), with
    chi-squared intervals (the squared coefficient with edf = 2 s^2 / Var s),
    in SI units (rad/s/sqrt(Hz), rad/s, rad/s^2/sqrt(Hz); m/s^2/sqrt(Hz), m/s^2,
    m/s^3/sqrt(Hz)) and customary ones (deg/sqrt(h), deg/h, deg/h/sqrt(h);
    m/s/sqrt(h), ug, m/s^2/sqrt(h)). The scales where each term dominates come
    from :func:`avar.fit.auto_scales.auto_scales`.

    Parameters
    ----------
    x : array_like, pandas.Series, pandas.DataFrame, AllanVariance, IMU, ImuAllanVariance or Recording
        A series, a table of channels, an IMU or its Allan variance, or a
        recording (any object with ``.columns``, a DataFrame or mapping of
        named columns, ``.freq`` in Hz and optionally ``.topic``, ``.source``).
    gyro_units : {"rad/s", "deg/s", "deg/h"}, optional
        Unit of the gyroscope data (default rad/s, or the IMU's own units).
        For a single series, giving it makes the series a gyroscope.
    accel_units : {"m/s^2", "g", "mg"}, optional
        Unit of the accelerometer data (default m/s^2); as ``gyro_units``.
    freq : float, optional
        Sampling rate (Hz) of a series or table (a recording carries its own).
    gyro, accel : str or list of str, optional
        Gyroscope / accelerometer columns of a table or recording (default:
        recognized by name: ``gyro*``, ``gx``, ``angular_velocity.*``, ``acc*``,
        ``ax``, ``linear_acceleration.*``; other columns are reported without a
        sensor type, in data units).
    alpha : float
        1 - confidence level of the intervals, in (0, 1).
    type, taus
        Estimator and tau grid, as for :func:`avar.avar`.
    name : str, optional
        Label of the report (default: the IMU or recording name).

    Returns
    -------
    NoiseReport
        ``.table`` (DataFrame), ``plot()``, ``to_kalibr(path)``.

    References
    ----------
    IEEE Std 952-1997, Annex C; IEEE Std 1554-2005.

    Examples
    --------
    >>> import avar
    >>> f = 100.0
    >>> model = avar.WN.from_continuous(2e-3, f) + avar.FN(b2=1e-6) + avar.RW.from_continuous(1.5e-4, f)
    >>> x = model.simulate(360_000, seed=3)  # one hour of a gyro in deg/s
    >>> report = avar.noise_report(x, gyro_units="deg/s", freq=f)
    >>> [round(report.value("x", p, customary=True), 2) for p in ("WN", "FN", "RW")]  # truth 0.12, 3.6, 32.4
    [0.12, 3.63, 32.53]
    >>> table = report.table.set_index("Process")
    >>> table.loc["QN", "Status"]
    'absent'
    """
    if gyro_units is not None and accel_units is not None and not _multi_channel(x):
        raise ValueError("a single series is one sensor: give gyro_units or accel_units, not both")
    units = {GYRO: None if gyro_units is None else check_unit(gyro_units, GYRO, "gyro_units"),
             ACCEL: None if accel_units is None else check_unit(accel_units, ACCEL, "accel_units")}
    single_kind = GYRO if gyro_units is not None else ACCEL if accel_units is not None else None
    alpha = check_real(alpha, "alpha")
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must be in (0, 1) (e.g. 0.05 for 95% intervals), got {alpha!r}")
    if name is not None and not isinstance(name, str):
        raise TypeError(f"name must be a string, got {name!r}")
    own_units = dict(getattr(x, "units", None) or {}) if isinstance(x, (IMU, ImuAllanVariance)) else {}
    channels, source, topic = _channels(x, freq, gyro, accel, taus, type, single_kind)
    rows, fits, scales, avs, kinds, data_units = [], {}, {}, {}, [], []
    for channel, kind, av in channels:
        if len(av) < 3:
            raise ValueError(f"channel {channel!r} has an Allan variance of {len(av)} level(s); "
                             "the noise report needs at least 3 (a longer record)")
        unit = None
        if kind is not None:
            given = units[kind] or own_units.get(kind)
            unit = check_unit(given, kind, "gyro_units" if kind == GYRO else "accel_units") if given \
                else DEFAULT_UNITS[kind]
        fit = fit_noise_terms(av.levels, av.allan, level_edf(av))
        selection = auto_scales(av, fit=fit)
        fits[channel], scales[channel], avs[channel] = fit, selection, av
        kinds.append(kind)
        data_units.append(unit)
        rows += term_rows(channel, kind, unit, av, fit, selection.scales, alpha)
    first = channels[0][2]
    return NoiseReport(
        name=name or source or (channels[0][0] if len(channels) == 1 else "IMU"),
        source=source, topic=topic, freq=first.freq, n=first.n,
        channels=tuple(c for c, _, _ in channels), sensor_types=tuple(kinds), units=tuple(data_units),
        avs=avs, fits=fits, scales=scales, terms=pd.DataFrame(rows), alpha=alpha,
    )


def _multi_channel(x: Any) -> bool:
    return isinstance(x, (IMU, ImuAllanVariance, pd.DataFrame)) or (hasattr(x, "columns") and hasattr(x, "freq"))
