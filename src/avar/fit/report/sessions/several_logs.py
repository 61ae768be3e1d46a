"""Several logs of one sensor: :func:`noise_reports`, a report per log, the pooled terms, and whether they agree.

The work is cut in two so that logs can run anywhere (``avar report --workers``):
:func:`log_session` turns one log into a :class:`LogSession` (its noise report and
its bias-versus-temperature slopes: small, picklable with :func:`pack_session`), and
:func:`combine_sessions` pools the sessions in one process
(:mod:`~avar.fit.report.sessions.pooling`), tests their agreement and measures the
spread between units (:mod:`~avar.fit.report.sessions.agreement`).
"""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from dataclasses import fields
from pathlib import PurePath
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from avar._vocabulary import CONFIDENCE_95
from avar.fit.report.noise_report import noise_report
from avar.fit.report.result import NoiseReport
from avar.fit.report.sessions.agreement import (
    SPREAD_COLUMNS,
    agreement_table,
    level_tests,
    name_disagreeing,
    term_spread,
)
from avar.fit.report.sessions.pooling import pooled_report
from avar.fit.report.sessions.result import IEEE, NoiseReports
from avar.fit.report.sessions.temperature import TemperatureFit, is_temperature_name, temperature_fit
from avar.imu import IMU
from avar.recording import Recording

__all__ = ["LogSession", "combine_sessions", "log_session", "noise_reports", "pack_session", "unpack_session"]

#: Default family-wise false-alarm rate of the test of agreement.
FALSE_ALARM = 0.05
TEMPERATURE_TABLE = ["Log", "Column", "Low (degC)", "High (degC)", "Channel", "Slope", "SE", "Unit", "Windows"]


class LogSession(NamedTuple):
    """One log's share of :func:`noise_reports`: its label, noise report and temperature fit (or None)."""

    name: str
    report: NoiseReport
    temperature: TemperatureFit | None


def _temperature_column(names: Sequence[str], temperature: Any) -> str | None:
    if temperature is None or temperature is False:
        return None
    if isinstance(temperature, str) and temperature != "auto":
        if temperature not in names:
            raise ValueError(f"temperature column {temperature!r} is not a column of the log; the columns are "
                             f"{list(names)}")
        return temperature
    if temperature != "auto":
        raise ValueError(f"temperature must be 'auto', a column name or None, got {temperature!r}")
    return next((name for name in names if is_temperature_name(name)), None)


def split_temperature(log: Any, temperature: Any = "auto") -> tuple[Any, str | None, np.ndarray | None]:
    """(the log without its temperature column, the column's name, its values): a recording or a table.

    ``temperature``: ``"auto"`` (a column named like ``temp``, ``temperature``, ``temp_c``, ``T``), a column
    name, or None (no temperature). Other logs (an IMU, a series) have no temperature column.
    """
    if isinstance(log, Recording) or isinstance(log, pd.DataFrame):
        names = [str(name) for name in (log.names if isinstance(log, Recording) else log.columns)]
        column = _temperature_column(names, temperature)
        if column is None:
            return log, None, None
        if len(names) == 1:
            raise ValueError(f"the log's only column {column!r} is the temperature; no sensor channel is left")
        if isinstance(log, pd.DataFrame):
            return log.drop(columns=[column]), column, log[column].to_numpy(dtype=np.float64)
        kept = {name: values for name, values in log.columns.items() if name != column}
        data = Recording(kept, rate=log.rate, rate_source=log.rate_source, time_column=log.time_column,
                         jitter=log.jitter, gap_rows=log.gap_rows, gap_steps=log.gap_steps,
                         gaps_ignored=log.gaps_ignored, source=log.source)
        return data, column, np.asarray(log.columns[column], dtype=np.float64)
    if isinstance(temperature, str) and temperature != "auto":
        raise ValueError(f"temperature column {temperature!r}: a {type(log).__name__} has no named columns "
                         "(give a recording or a table)")
    return log, None, None


def _samples(data: Any, channel: str) -> np.ndarray:
    if isinstance(data, Recording):
        return np.asarray(data.columns[channel], dtype=np.float64)
    if isinstance(data, IMU):
        return np.asarray(data[channel], dtype=np.float64)
    return np.asarray(data[channel], dtype=np.float64)


def log_session(log: Any, name: str, gyro_units: str | None = None, accel_units: str | None = None, *,
                temperature: Any = "auto", **options: Any) -> LogSession:
    """One log's noise report (:func:`avar.noise_report` with ``options``) and its temperature fit.

    The temperature column is taken out of the channels and gives the bias-versus-temperature
    slope of every channel (:func:`~avar.fit.report.sessions.temperature.temperature_fit`).
    """
    data, column, temps = split_temperature(log, temperature)
    report = noise_report(data, gyro_units, accel_units, name=name, **options)
    fit = None
    if column is not None:
        channels = {channel: _samples(data, channel) for channel in report.channels}
        fit = temperature_fit(channels, temps, column, dict(zip(report.channels, report.units)), log=name,
                              noise=_noise(report))
    return LogSession(name, report, fit)


def pack_session(session: LogSession) -> dict[str, Any]:
    """A session as plain picklable data (a report's mappings are read-only proxies, which do not pickle)."""
    report = {field.name: getattr(session.report, field.name) for field in fields(session.report)}
    report["avs"], report["fits"] = dict(report["avs"]), dict(report["fits"])
    return {"name": session.name, "report": report, "temperature": session.temperature}


def unpack_session(packed: Mapping[str, Any]) -> LogSession:
    """The session :func:`pack_session` was given, rebuilt."""
    return LogSession(packed["name"], NoiseReport(**packed["report"]), packed["temperature"])


def _label(log: Any, at: int) -> str:
    source = getattr(log, "source", None) if isinstance(log, Recording) else None
    if source:
        return PurePath(str(source)).name
    if isinstance(log, IMU) and log.name:
        return str(log.name)
    return f"log {at + 1}"


def _unique(labels: list[str]) -> list[str]:
    seen: dict[str, int] = {}
    out = []
    for label in labels:
        seen[label] = seen.get(label, 0) + 1
        out.append(label if labels.count(label) == 1 else f"{label} ({seen[label]})")
    return out


def _spread(sessions: Sequence[LogSession], pooled: NoiseReport) -> pd.DataFrame:
    rows = []
    for channel in pooled.channels:
        terms = pooled.table[pooled.table["Channel"] == channel].set_index("Process")
        for process in IEEE:
            values, errors = [], []
            for session in sessions:
                fit = session.report.fits[channel]
                table = session.report.table
                row = table[(table["Channel"] == channel) & (table["Process"] == process)]
                at = [k for k, c in enumerate(fit.components) if c.kind == process]
                if row.empty or row.iloc[0]["Status"] != "present" or not at:
                    continue
                scale, variance = fit.components[at[0]].scale, fit.scale_variance(at[0])
                if not (scale > 0 and variance > 0):
                    continue
                values.append(float(row.iloc[0]["Value"]))
                errors.append(0.5 * np.sqrt(variance) / scale)  # term ~ sqrt(scale): se of its log
            if len(values) >= 2:
                rows.append(term_spread(channel, process, str(terms.loc[process, "Term"]),
                                        str(terms.loc[process, "Unit"]), np.array(values), np.array(errors)))
    return pd.DataFrame(rows, columns=SPREAD_COLUMNS)


def _noise(*reports: NoiseReport) -> dict[str, dict[str, float]]:
    """Per channel, the largest white noise and random walk (per-sample variances) of the reports' fits."""
    noise: dict[str, dict[str, float]] = {}
    for report in reports:
        for channel, fit in report.fits.items():
            for c in fit.components:
                if c.kind in ("WN", "RW"):
                    own = noise.setdefault(channel, {})
                    own[c.kind] = max(own.get(c.kind, 0.0), float(c.scale))
    return noise


def combine_sessions(sessions: Sequence[LogSession], confidence: float = CONFIDENCE_95,
                     false_alarm: float = FALSE_ALARM) -> NoiseReports:
    """Pool the logs' sessions, test their agreement and measure their spread (see :func:`noise_reports`)."""
    if len(sessions) < 2:
        raise ValueError(f"several logs: got {len(sessions)} log(s); the pooled terms and the test need at least 2")
    if not 0 < false_alarm < 1:
        raise ValueError(f"false_alarm must be a probability in (0, 1), got {false_alarm!r}")
    names = [session.name for session in sessions]
    reports = [session.report for session in sessions]
    pooled = pooled_report(reports, names, confidence)
    tests = [level_tests(channel, [report.avs[channel] for report in reports], pooled.fits[channel].implied)
             for channel in pooled.channels]
    agreement = pd.concat([agreement_table(test) for test in tests], ignore_index=True)
    threshold = false_alarm / max(len(agreement), 1)
    disagreements = []
    for test, kind in zip(tests, pooled.sensor_types):
        disagreements += name_disagreeing(test, names, threshold, pooled.fits[test.channel], kind)
    noise = _noise(pooled, *reports)  # one sensor: its largest white noise and random walk in any fit
    temperature = [fit.with_noise(noise).slopes.assign(
                       Log=session.name, Column=fit.column, **{"Low (degC)": fit.low, "High (degC)": fit.high})
                   for session, fit in ((s, s.temperature) for s in sessions) if fit is not None]
    warnings = [d.describe() for d in disagreements]
    warnings += [s.temperature.warning for s in sessions if s.temperature is not None and s.temperature.warning]
    warnings += [f"{s.name}: {w}" for s in sessions for w in s.report.warnings]
    warnings += [f"pooled: {w}" for w in pooled.warnings]
    table = (pd.concat(temperature, ignore_index=True)[TEMPERATURE_TABLE] if temperature
             else pd.DataFrame(columns=TEMPERATURE_TABLE))
    return NoiseReports(tuple(names), tuple(reports), pooled, agreement, tuple(disagreements),
                        _spread(sessions, pooled), table, float(false_alarm), tuple(warnings))


def noise_reports(
    logs: Any,
    gyro_units: str | None = None,
    accel_units: str | None = None,
    *,
    names: Sequence[str] | None = None,
    confidence: float = CONFIDENCE_95,
    false_alarm: float = FALSE_ALARM,
    temperature: Any = "auto",
    progress: bool | None = None,
    **options: Any,
) -> NoiseReports:
    """Noise reports of several logs of one sensor, their pooled terms, and whether the logs agree.

    Every log gets its own :func:`avar.noise_report`; the terms are then pooled
    (the logs' Allan variances averaged level by level with weights N - 2m + 1 and
    fitted once: :mod:`avar.fit.report.sessions.pooling` says why rather than an
    inverse-variance mean of the per-log terms), the logs are tested for
    agreement (Bartlett's test of their Allan variances at every level of every
    channel, Greenhall's degrees of freedom, Bonferroni over all levels and
    channels: a family-wise false-alarm rate ``false_alarm``;
    :mod:`avar.fit.report.sessions.agreement`), each disagreeing log is named
    with its channel and term, and the spread of every term between logs is
    measured (max/min, between-log SD beyond sampling). A temperature column
    gives the bias-versus-temperature slope of every channel and a warning when
    the temperature drifts by more than 1 degC (:mod:`avar.fit.report.sessions.temperature`).

    Parameters
    ----------
    logs : sequence or mapping of logs
        Two or more logs, each anything :func:`avar.noise_report` accepts (a series, a table, an
        :class:`~avar.IMU`, a :class:`~avar.Recording`); a mapping names them.
    gyro_units, accel_units : str, optional
        Data units, as for :func:`avar.noise_report` (the same for every log).
    names : sequence of str, optional
        Labels of the logs (default: the mapping's keys, the files' names, ``log 1``, ``log 2``...).
    confidence : float
        Confidence level of the intervals, in (0, 1); default 0.95.
    false_alarm : float
        Probability that logs of one sensor are declared in disagreement (family-wise, over every
        level and channel), in (0, 1); default 0.05.
    temperature : "auto", str or None
        The temperature column (degC) of a recording or table: found by name (``temp``,
        ``temperature``, ``temp_c``, ``T``), named, or None for none. It is not a noise channel.
    progress : bool, optional
        A bar over the logs on stderr (default: when stderr is a terminal).
    **options
        Passed to :func:`avar.noise_report`: ``rate``, ``gyro``, ``accel``, ``type``, ``robust``...

    Returns
    -------
    NoiseReports
        ``.pooled``, ``.reports``, ``.agree``, ``.disagreements``, ``.spread``, ``.temperature``,
        ``summary()``, ``plot()``.

    References
    ----------
    M. S. Bartlett, "Properties of sufficiency and statistical tests", Proc. R. Soc. A 160, 1937.
    S. Guerrier, R. Molinari et al., multi-signal GMWM: H. Bakalli et al., "A two-step computationally
    efficient procedure for IMU classification and calibration", IEEE/ION PLANS 2018; A. Radi et al.,
    "A multisensor approach for the stochastic modelling of inertial sensors", 2019.
    R. DerSimonian, N. Laird, "Meta-analysis in clinical trials", Control. Clin. Trials 7, 1986.

    Examples
    --------
    >>> import avar
    >>> model = avar.WN(sigma2=1e-4) + avar.RW(gamma2=1e-10)
    >>> logs = [model.simulate(20_000, seed=s) for s in (1, 2, 3)]
    >>> several = avar.noise_reports(logs, gyro_units="rad/s", rate=100.0, progress=False)
    >>> several.agree, several.names
    (True, ('log 1', 'log 2', 'log 3'))
    >>> logs[2] = logs[2] * 2.0                       # one unit twice as noisy
    >>> several = avar.noise_reports(logs, gyro_units="rad/s", rate=100.0, progress=False)
    >>> several.disagreeing, several.disagreements[0].channel
    (('log 3',), 'x')
    """
    if isinstance(logs, Mapping):
        names = list(logs) if names is None else names
        logs = list(logs.values())
    logs = list(logs)
    labels = _unique([str(n) for n in names] if names is not None else [_label(log, i) for i, log in enumerate(logs)])
    if len(labels) != len(logs):
        raise ValueError(f"names: {len(labels)} name(s) for {len(logs)} log(s)")
    if len(logs) < 2:
        raise ValueError(f"logs: got {len(logs)} log(s); give at least 2 (one log: avar.noise_report)")
    show = sys.stderr.isatty() if progress is None else progress
    items: Any = zip(labels, logs)
    if show:
        from tqdm import tqdm

        items = tqdm(items, total=len(logs), desc="noise reports", unit="log", file=sys.stderr)
    sessions = [log_session(log, label, gyro_units, accel_units, temperature=temperature, confidence=confidence,
                            **options) for label, log in items]
    return combine_sessions(sessions, confidence, false_alarm)
