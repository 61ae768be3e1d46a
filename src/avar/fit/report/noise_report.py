"""The IMU noise report: :func:`noise_report`, from a log to ARW, bias instability and RRW.

One call, no scales to pick: for every channel, the maximal-overlap Allan
variance on octaves from m = 1, its chi-squared band (Greenhall's EDF at the
fitted noise type), the noise model chosen by the data among sums of QN,
WN, FN, RW, DR, up to two Gauss-Markov and two sinusoid terms
(:mod:`avar.fit.report.sensor_fit`), the terms in SI and customary units with
intervals (:mod:`avar.fit.report.rows`), the Allan-deviation minimum, and
checks of the fit, the units and the data (:mod:`avar.fit.report.checks`).
The result is a :class:`~avar.fit.report.result.NoiseReport`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from avar._validation import as_series
from avar._vocabulary import CONFIDENCE_95, check_rate, renamed, resolve_confidence
from avar.fit.gmwm import octave_factors
from avar.fit.report.checks import data_warnings, fit_check, unit_warnings
from avar.fit.report.noise_terms import ACCEL, GYRO, check_unit
from avar.fit.report.result import NoiseReport
from avar.fit.report.rows import channel_rows, minimum_row
from avar.fit.report.sensor_fit import SensorFit, fit_sensor_model
from avar.fit.report.uncertainty import non_overlapping_fit, with_level_covariance
from avar.imu import IMU
from avar.recording import Recording
from avar.stability.allan.estimator import avar as allan_variance
from avar.stability.allan.results import AllanVariance, ImuAllanVariance

__all__ = ["noise_report", "infer_sensor_type", "fit_channel", "FittedChannel"]

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


def _grid(taus: Any, n: int, rate: float) -> Any:
    return octave_factors(n) / rate if isinstance(taus, str) and taus == "octave" else taus


def _estimator(robust: bool, type: str) -> Any:
    """The Allan variance of one series: the plain estimator, or the robust one (``type="mo"`` only)."""
    # the rate goes by position: ``freq`` in avar() (R's name), ``rate`` in the estimators that take it
    if not robust:
        return lambda values, rate, taus: allan_variance(values, type, rate, taus=taus)
    if type != "mo":
        raise ValueError(f"robust=True estimates the maximal-overlap Allan variance; type must be 'mo', got {type!r}")
    from avar.stability.robust.estimator import robust_allan_variance

    return lambda values, rate, taus: robust_allan_variance(values, 1.0 if rate is None else rate, taus=taus)


def _has_columns(x: Any) -> bool:
    """A table of named columns with a rate: a Recording, or an object like one (``.columns``, ``.rate`` or ``.freq``)."""
    return isinstance(x, Recording) or (hasattr(x, "columns") and (hasattr(x, "rate") or hasattr(x, "freq")))


def _channels(x: Any, rate: Any, gyro: Any, accel: Any, taus: Any, type: str, single_kind: str | None,
              robust: bool = False, rate_name: str = "rate") -> tuple:
    """([(name, sensor type, AllanVariance, values or None)], source, topic) from any accepted input."""
    estimate = _estimator(robust, type)
    if isinstance(x, IMU):
        rows = []
        for name, kind in zip(x.channels, x.sensor_types):
            values = np.asarray(x[name], dtype=np.float64)
            av = estimate(values, x.rate, _grid(taus, x.n_samples, x.rate))
            rows.append((name, kind, av, values))
        return rows, None, None
    if robust and isinstance(x, (ImuAllanVariance, AllanVariance)):
        raise ValueError("robust=True needs the samples: give the series, table, IMU or recording, not an Allan variance")
    if isinstance(x, ImuAllanVariance):
        rows = [(name, kind, av, None) for (name, av), kind in zip(x.channels.items(), x.sensor_types)]
        return rows, None, None
    if isinstance(x, AllanVariance):
        return [(x.name or "x", single_kind, x, None)], None, None
    if isinstance(x, pd.DataFrame) or _has_columns(x):
        if isinstance(x, pd.DataFrame):
            values = {str(c): x[c] for c in x.columns}
            source, topic = None, None
        else:
            values = _columns_of(x)
            if rate is None:
                rate = x.rate if hasattr(x, "rate") else x.freq
            source, topic = getattr(x, "source", None) or None, getattr(x, "topic", None)
        if rate is not None:
            rate = check_rate(rate, rate_name)
        rows = []
        for name, kind in _selected(list(values), gyro, accel):
            series = np.asarray(values[name], dtype=np.float64)
            grid = _grid(taus, series.size, 1.0 if rate is None else float(rate))
            rows.append((name, kind, estimate(values[name], rate, grid), series))
        if not rows:
            raise ValueError("x has no data column")
        return rows, None if source is None else str(source), None if topic is None else str(topic)
    name = getattr(x, "name", None) if isinstance(x, pd.Series) else None
    series, rate = as_series(x, rate, rate_name=rate_name)
    series = np.asarray(series, dtype=np.float64)
    av = estimate(series, rate, _grid(taus, series.size, rate))  # the rate given, else of a time index, else 1 Hz
    return [(str(name) if name is not None else "x", single_kind, av, series)], None, None


class FittedChannel(NamedTuple):
    """The selected model of one channel and the band of its Allan deviation (``lower``, ``upper``)."""

    fit: SensorFit
    lower: np.ndarray
    upper: np.ndarray


def fit_channel(av: AllanVariance, significance: float) -> FittedChannel:
    """The selected model of one Allan variance and its band of confidence 1 - significance (lower, upper deviation).

    The fit weighs the levels by their degrees of freedom (N - 2m + 1) / m;
    the band uses Greenhall's EDF of the overlapping Allan variance at the
    noise type of the fitted model's local slope (the power-law noise exponent
    alpha = -1 - d log AV / d log tau, rounded into -2..2). The long-tau terms (random walk, a long
    Gauss-Markov term, flicker) are chosen on the levels' exact likelihood for the record's length
    (:mod:`avar.fit.report.long_tau`). When the selected model misses a level, the selection is made
    again with the fit check (``check`` of :func:`~avar.fit.report.sensor_fit.fit_sensor_model`): a larger
    long-tau model that fits more levels where a likelihood-ratio test supports it, and below 90 % of the
    levels the terms the data demand. The parameters'
    covariance is the sandwich around the exact covariance of the
    maximal-overlap levels under the selected model
    (:func:`~avar.fit.report.uncertainty.with_level_covariance`); for a
    non-overlapping ("to") estimate, that correlation with Greenhall's variances
    (:func:`~avar.fit.report.uncertainty.non_overlapping_fit`).
    """
    factors = np.asarray(av.averaging_factors, dtype=np.int64)
    counts = np.maximum(av.n - 2 * factors + 1, 1)
    nu_hat, adev = np.asarray(av.allan, dtype=np.float64), np.asarray(av.adev, dtype=np.float64)
    fit = fit_sensor_model(factors, nu_hat, counts / factors, n_samples=av.n)
    lower, upper, edf = _band(av, fit.implied(factors), significance)

    def share(implied: np.ndarray) -> float:
        return float(np.mean(fit_check("", av.levels, adev, lower, upper, np.sqrt(implied)).fits))

    if share(fit.implied(factors)) < 1.0:
        fit = fit_sensor_model(factors, nu_hat, counts / factors, check=share, n_samples=av.n)
        lower, upper, edf = _band(av, fit.implied(factors), significance)
    if av.type != "mo":  # the exact covariance is the maximal-overlap estimator's
        return FittedChannel(non_overlapping_fit(fit, av.n, 2.0 * fit.implied(factors) ** 2 / edf), lower, upper)
    return FittedChannel(with_level_covariance(fit, av.n), lower, upper)


def _band(av: AllanVariance, implied: np.ndarray, significance: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lower and upper chi-squared bounds (confidence 1 - significance) of the deviation and Greenhall's EDF, at
    the model's noise types (power-law alpha: AV slope mu gives -1 - mu, and 2 (white PM) below -1.5), for the
    estimator's overlap."""
    from avar.stability.uncertainty.edf import chi2_bounds, greenhall_edf

    factors = np.asarray(av.averaging_factors, dtype=np.int64)
    slope = np.gradient(np.log(implied), np.log(factors)) if factors.size > 1 else np.zeros(1)
    noise = np.where(slope < -1.5, 2, np.clip(np.rint(-1.0 - slope), -2, 1)).astype(np.int64)
    edf = greenhall_edf(noise, 2, factors, av.n + 1, overlapping=av.type == "mo", modified=False)
    lower, upper = chi2_bounds(np.sqrt(av.allan), edf, 1.0 - significance)
    return np.asarray(lower), np.asarray(upper), np.asarray(edf)


def noise_report(
    x: Any,
    gyro_units: str | None = None,
    accel_units: str | None = None,
    *,
    rate: float | None = None,
    gyro: Any = None,
    accel: Any = None,
    confidence: float = CONFIDENCE_95,
    type: str = "mo",
    taus: Any = "octave",
    name: str | None = None,
    source: str | None = None,
    topic: str | None = None,
    from_bag: bool = False,
    robust: bool = False,
    freq: float | None = None,
    alpha: float | None = None,
) -> NoiseReport:
    """Noise terms of every channel of a real sensor's log, with no scales to choose.

    Per channel: the maximal-overlap Allan variance at m = 1, 2, 4, ...; the
    noise model chosen by the data among sums of quantization QN, white noise
    WN, flicker FN, random walk RW, ramp DR, up to two first-order
    Gauss-Markov and two sinusoid terms, fitted jointly at every level by
    maximum likelihood and selected by a penalized deviance
    (:func:`avar.fit.report.sensor_fit.fit_sensor_model`); then, in SI and customary
    units with intervals of the given ``confidence``:

    * quantization Q, angle / velocity random walk N, bias instability B
      (IEEE 952: the flicker plateau of the Allan deviation is 0.664 B),
      rate / acceleration random walk K, ramp R, each ``present``,
      ``bound`` (N, B, K left out by the selection: the upper end of their interval,
      worded ``one-sided 97.5 % upper bound`` at confidence 0.95,
      :func:`avar.fit.report.rows.bound_words`) or ``absent``::

          AV(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2 + ...

    * Gauss-Markov sigma and correlation time, sinusoid amplitude and frequency; those
      of the sensor's own filtering or vibration (a deviation peaking within 16 sample
      periods) in the ``Group`` "sensor filtering", the rest "IEEE 952"
      (:func:`avar.fit.report.rows.group_of`);
    * the **Allan-deviation minimum** and its tau (the "in-run bias stability"
      of datasheets), also in deg/h or ug.

    The implied deviation is checked against the empirical band at every
    level; a channel where it fits fewer than 90 % of the levels, wrong-looking
    units, clipped, stuck, spiky, moving or short data each add a warning
    (:attr:`NoiseReport.warnings`).

    Parameters
    ----------
    x : array_like, pandas.Series, pandas.DataFrame, AllanVariance, IMU, ImuAllanVariance or Recording
        A series, a table of channels, an :class:`~avar.IMU` or its Allan variance, or
        a :class:`~avar.Recording` (what :func:`avar.read` returns: named columns, their
        rate and the file they came from).
    gyro_units : str, optional
        Unit of the gyroscope data: ``"rad/s"`` (default, or the IMU's own units),
        ``"deg/s"`` (``"dps"``), ``"deg/h"``; any spelling of :data:`avar.fit.report.noise_terms.UNIT_SPELLINGS`.
        For a single series, giving it makes the series a gyroscope.
    accel_units : str, optional
        Unit of the accelerometer data: ``"m/s^2"`` (default), ``"g"``, ``"mg"``; as ``gyro_units``.
    rate : float, optional
        Sampling rate (Hz) of a series or table; default: a time index's, else 1 Hz. A
        recording or IMU carries its own (``rate`` overrides a recording's).
    gyro, accel : str or list of str, optional
        Gyroscope / accelerometer columns of a table or recording (default:
        recognized by name: ``gyro*``, ``gx``, ``angular_velocity.*``, ``acc*``,
        ``ax``, ``linear_acceleration.*``; other columns are reported without a
        sensor type, in data units).
    confidence : float
        Confidence level of the intervals and of the band, in (0, 1); default 0.95.
    type, taus
        Estimator and tau grid, as for :func:`avar.avar` (``"octave"``: m = 1, 2, 4, ...).
    name : str, optional
        Label of the report (default: the IMU, recording or file name).
    source : str, optional
        The file the data came from (default: a recording's); a Kalibr yaml never overwrites it.
    topic : str, optional
        The ROS topic of the data, written as Kalibr's ``rostopic`` (default: none, ``/imu0`` in the yaml).
    from_bag : bool
        The data came from a ROS bag (SI units by definition): a non-SI unit is warned about.
    robust : bool
        Estimate the Allan variance robustly (:func:`avar.stability.robust.estimator.robust_allan_variance`):
        a log with a few per cent of spikes gives the terms of the clean process.

    Returns
    -------
    NoiseReport
        ``.table`` (DataFrame), ``.curves``, ``.warnings``, ``plot()``, ``to_kalibr(path)``.

    References
    ----------
    IEEE Std 952-1997, Annex C; IEEE Std 1554-2005. C. A. Greenhall, W. J. Riley,
    "Uncertainty of stability variances based on finite differences", 2003.

    Examples
    --------
    >>> import avar
    >>> f = 100.0
    >>> model = avar.WN.from_continuous(2e-3, f) + avar.FN(b2=1e-6) + avar.RW.from_continuous(1.5e-4, f)
    >>> x = model.simulate(360_000, seed=3)  # one hour of a gyro in deg/s
    >>> report = avar.noise_report(x, gyro_units="deg/s", rate=f)
    >>> truth = {"WN": 0.12, "FN": 3.6, "RW": 32.4}   # deg/sqrt(h), deg/h, deg/h/sqrt(h)
    >>> [round(report.value("x", p, customary=True) / truth[p], 1) for p in truth]   # estimate / truth
    [1.0, 1.0, 1.0]
    >>> report.table.set_index("Process").loc[["QN", "DR"], "Status"].tolist()
    ['absent', 'absent']
    """
    if gyro_units is not None and accel_units is not None and not _multi_channel(x):
        raise ValueError("a single series is one sensor: give gyro_units or accel_units, not both")
    units = {GYRO: None if gyro_units is None else check_unit(gyro_units, GYRO, "gyro_units"),
             ACCEL: None if accel_units is None else check_unit(accel_units, ACCEL, "accel_units")}
    single_kind = GYRO if gyro_units is not None else ACCEL if accel_units is not None else None
    rate, rate_name = renamed("rate", rate, "freq", freq, deprecated=True)
    confidence, significance = resolve_confidence(confidence, alpha)
    for label, value in (("name", name), ("source", source), ("topic", topic)):
        if value is not None and not isinstance(value, str):
            raise TypeError(f"{label} must be a string, got {value!r}")
    own_units = dict(getattr(x, "units", None) or {}) if isinstance(x, (IMU, ImuAllanVariance)) else {}
    if not isinstance(robust, (bool, np.bool_)):
        raise TypeError(f"robust must be True or False, got {robust!r}")
    channels, own_source, own_topic = _channels(x, rate, gyro, accel, taus, type, single_kind, bool(robust), rate_name)
    source = source if source is not None else own_source
    topic = topic if topic is not None else own_topic
    label = name or (x.name if isinstance(x, IMU) else x.sensor if isinstance(x, ImuAllanVariance) else None)
    rows, fits, avs, kinds, data_units, warnings, curves = [], {}, {}, [], [], [], []
    for channel, kind, av, values in channels:
        if len(av) < 3:
            raise ValueError(f"channel {channel!r} has an Allan variance of {len(av)} level(s); "
                             "the noise report needs at least 3 (a longer record)")
        if not np.all(np.isfinite(av.allan) & (av.allan > 0)):
            raise ValueError(f"channel {channel!r}: the Allan variance is zero or not finite at some level "
                             "(a constant or exactly linear channel has no noise to fit)")
        unit = None
        if kind is not None:
            given = units[kind] or own_units.get(kind)
            unit = check_unit(given, kind, "gyro_units" if kind == GYRO else "accel_units") if given \
                else DEFAULT_UNITS[kind]
        fit, lower, upper = fit_channel(av, significance)
        implied = np.sqrt(fit.implied(av.averaging_factors))
        fits_level, departure = fit_check(channel, av.levels, av.adev, lower, upper, implied)
        fits[channel], avs[channel] = fit, av
        kinds.append(kind)
        data_units.append(unit)
        rows += channel_rows(channel, kind, unit, fit, av.freq, significance)
        rows.append(minimum_row(channel, kind, unit, av.levels, av.adev, lower, upper,
                                duration=av.n_samples / av.freq))
        notes = [departure] if departure else []
        if values is not None:
            notes += data_warnings(channel, kind, values, av.freq, len(av), robust=bool(robust))
        if kind is not None:
            white = [c.scale for c in fit.components if c.kind == "WN"]
            density = float(np.sqrt(white[0] / av.freq)) if white else None
            notes += unit_warnings(channel, kind, unit, values if values is not None else np.zeros(0),
                                   density, from_bag)
        for note in notes:
            rows.append({"Channel": channel, "Sensor": kind or "", "Term": "Warning", "Process": "WARNING",
                         "Status": "warning", "Group": "", "Note": note})
        warnings += notes
        curves.append(pd.DataFrame({"Channel": channel, "Tau (s)": av.levels, "ADEV": av.adev, "Lower": lower,
                                    "Upper": upper, "Implied ADEV": implied, "Fits": fits_level,
                                    "Unit": unit or ""}))
    first = channels[0][2]
    return NoiseReport(
        name=label or source or (channels[0][0] if len(channels) == 1 else "IMU"),
        source=source, topic=topic, rate=first.freq, n_samples=first.n,
        channels=tuple(c[0] for c in channels), sensor_types=tuple(kinds), units=tuple(data_units),
        avs=avs, fits=fits, terms=pd.DataFrame(rows), confidence=confidence,
        curves=pd.concat(curves, ignore_index=True), warnings=tuple(warnings),
    )


def _multi_channel(x: Any) -> bool:
    return isinstance(x, (IMU, ImuAllanVariance, pd.DataFrame)) or _has_columns(x)
