"""Logs simulated from a fitted noise model: :func:`simulate_log`, the report's terms played back.

Every term of every channel of a noise report, as its table gives it (continuous-time
coefficients in SI units for gyroscopes and accelerometers, data units otherwise), is
turned back into the per-sample process of :mod:`avar.models` at the simulated rate f
(Hz) and simulated with that process's own simulator:

=====================  ================================  =========================================
Process (table)        coefficient                       per-sample process
=====================  ================================  =========================================
``QN``                 quantization Q (u s)              ``QN.from_continuous(Q, f)``: q2 = Q^2 f^2
``WN``                 random walk N (u / sqrt(Hz))      ``WN.from_continuous(N, f)``: sigma2 = N^2 f
``FN``                 bias instability B (u)            ``FN(b2=B^2)`` (flicker is scale-free)
``RW``                 rate random walk K (u s^-1/2)     ``RW.from_continuous(K, f)``: gamma2 = K^2 / f
``DR``                 ramp R (u / s)                    ``DR.from_continuous(R, f)``: omega = R / f
``AR1_k``, ``.T``      Gauss-Markov sigma (u), T (s)      ``AR1(phi, sigma^2 (1 - phi^2))``, phi = exp(-1 / (f T))
``SIN_k``, ``.f``      sinusoid amplitude (u), f0 (Hz)    ``SIN.from_continuous(amplitude, f0, f)``
=====================  ================================  =========================================

Only ``present`` terms are simulated (a ``bound`` term was not resolved by the data,
an ``absent`` one was rejected); the Allan-deviation minimum and the warnings are not
terms. A Kalibr ``imu.yaml`` gives N and K per sensor type (``*_noise_density``,
``*_random_walk``), applied to every axis. The log's columns are named so that
:func:`avar.noise_report` and ``avar report`` recognize them with no options: ``gx gy gz``
for gyroscopes (rad/s), ``ax ay az`` for accelerometers (m/s^2), a channel of no sensor
type under its own name (in its data unit).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from avar._validation import check_count, check_seed, short_repr
from avar._vocabulary import check_rate
from avar.fit.report.noise_terms import ACCEL, GYRO, SI_UNITS
from avar.models import AR1, DR, FN, QN, RW, SIN, WN, CompositeModel, Process
from avar.recording import Recording

__all__ = ["simulate_log", "simulated", "ChannelTerms", "Term", "ModelSource", "channel_terms", "parse_duration",
           "simulate_channels", "SimulatedLog"]

#: Seconds per unit of a duration's text (``"2h"``, ``"90 min"``, ``"7200 s"``).
DURATION_UNITS = {"s": 1.0, "sec": 1.0, "min": 60.0, "m": 60.0, "h": 3600.0, "hr": 3600.0, "d": 86400.0}
#: The per-sample process of each IEEE term from its continuous-time coefficient at ``rate`` Hz.
IEEE = {"QN": QN.from_continuous, "WN": WN.from_continuous, "FN": FN.from_continuous,
        "RW": RW.from_continuous, "DR": DR.from_continuous}
#: Column names per sensor type for up to three axes (beyond: ``gyro_4``, ``accel_4`` ...).
AXES = {GYRO: ("gx", "gy", "gz"), ACCEL: ("ax", "ay", "az")}
PREFIX = {GYRO: "gyro", ACCEL: "accel"}
#: Kalibr's keys: (sensor type, term).
KALIBR_KEYS = {(GYRO, "WN"): "gyroscope_noise_density", (GYRO, "RW"): "gyroscope_random_walk",
               (ACCEL, "WN"): "accelerometer_noise_density", (ACCEL, "RW"): "accelerometer_random_walk"}
_SHAPED = re.compile(r"^(AR1|SIN)_(\d+)$")


class Term(NamedTuple):
    """One continuous-time term: ``process`` (QN, WN, FN, RW, DR, AR1, SIN), its ``value`` (the coefficient,
    Gauss-Markov sigma or sinusoid amplitude) and ``shape`` (correlation time in s, frequency in Hz, or None)."""

    process: str
    value: float
    shape: float | None = None

    def process_at(self, rate: float) -> Process:
        """The per-sample process of :mod:`avar.models` at ``rate`` Hz."""
        if self.process in IEEE:
            return IEEE[self.process](self.value, rate)
        if self.process == "AR1":
            phi = math.exp(-1.0 / (rate * self.shape))
            return AR1(phi=phi, sigma2=self.value**2 * (1.0 - phi * phi))
        if not self.shape < rate / 2.0:
            raise ValueError(f"a sinusoid of {self.shape:g} Hz cannot be sampled at {rate:g} Hz (above Nyquist); "
                             "simulate at a rate above twice its frequency")
        return SIN.from_continuous(self.value, self.shape, rate)


class ChannelTerms(NamedTuple):
    """The terms of one channel: its name in the source, its column in the log, its sensor type and terms."""

    channel: str
    column: str
    sensor: str | None
    terms: tuple[Term, ...]

    def model(self, rate: float) -> CompositeModel:
        """The sum of the per-sample processes at ``rate`` Hz."""
        return CompositeModel(tuple(term.process_at(rate) for term in self.terms))


class ModelSource(NamedTuple):
    """What :func:`channel_terms` read: the channels' terms, and the rate (Hz) and duration (s) the source
    gives (None when it holds none)."""

    channels: list[ChannelTerms]
    rate: float | None
    duration: float | None


class SimulatedLog(NamedTuple):
    """What :func:`simulate_channels` made: the channels' terms and the recording."""

    channels: tuple[ChannelTerms, ...]
    recording: Recording


def parse_duration(value: Any, name: str = "duration") -> float:
    """A duration in seconds from a number of seconds or a text with a unit (s, min, h, d).

    >>> parse_duration(90), parse_duration("2h"), parse_duration("1.5 min"), parse_duration("7200 s")
    (90.0, 7200.0, 90.0, 7200.0)
    """
    if isinstance(value, str):
        match = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][-+]?\d+)?)\s*([a-zA-Z]*)\s*", value)
        unit = match[2].lower() if match else ""
        if not match or (unit and unit not in DURATION_UNITS):
            raise ValueError(f"{name} must be seconds or a number with a unit ({', '.join(DURATION_UNITS)}), "
                             f"e.g. 7200 or 2h; got {short_repr(value)}")
        seconds = float(match[1]) * DURATION_UNITS.get(unit, 1.0)
    elif isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, (bool, np.bool_)):
        seconds = float(value)
    else:
        raise TypeError(f"{name} must be seconds (a number) or a text such as '2h', got {short_repr(value)}")
    if not (math.isfinite(seconds) and seconds > 0):
        raise ValueError(f"{name} must be a finite duration > 0, got {short_repr(value)}")
    return seconds


def _columns(channels: list[tuple[str, str | None]]) -> list[str]:
    """Log column names: gx gy gz / ax ay az per sensor type, a channel of no type under its own name."""
    counts = {kind: sum(k == kind for _, k in channels) for kind in AXES}
    seen = {kind: 0 for kind in AXES}
    names = []
    for channel, kind in channels:
        if kind in AXES:
            axis = seen[kind]
            seen[kind] += 1
            names.append(AXES[kind][axis] if counts[kind] <= 3 else f"{PREFIX[kind]}_{axis + 1}")
        else:
            names.append(str(channel))
    taken = [n for n in names if names.count(n) > 1]
    if taken:
        raise ValueError(f"terms: two channels would both be the column {taken[0]!r}; rename one")
    return names


def _undefuse(text: Any) -> str:
    """A text cell as written, without the quote a CSV writer puts before a formula-like start (``'-x``)."""
    text = "" if text is None or (isinstance(text, float) and math.isnan(text)) else str(text)
    return text[1:] if text[:1] == "'" and text[1:2] in ("=", "+", "-", "@", "\t", "\r") else text


def _table_terms(table: pd.DataFrame, where: str) -> list[ChannelTerms]:
    """The present terms of every channel of a report's table (see the module docstring)."""
    needed = {"Channel", "Sensor", "Process", "Status", "Value", "Unit"}
    missing = sorted(needed - set(table.columns))
    if missing:
        raise ValueError(f"{where}: not a noise report's terms table: no column(s) {missing} "
                         "(write one with `avar report LOG --output terms.csv`)")
    order: dict[str, str | None] = {}
    found: dict[str, dict[str, float]] = {}
    for row in table.to_dict("records"):
        channel, sensor = _undefuse(row["Channel"]), _undefuse(row["Sensor"]) or None
        if sensor not in (None, GYRO, ACCEL):
            raise ValueError(f"{where}: channel {channel!r} has the sensor type {sensor!r}; "
                             f"expected {GYRO!r}, {ACCEL!r} or none")
        order.setdefault(channel, sensor)
        if _undefuse(row["Status"]) != "present":
            continue
        process, value = _undefuse(row["Process"]), pd.to_numeric(row["Value"], errors="coerce")
        if process in ("MIN", "WARNING") or not (process in IEEE or _SHAPED.match(process.split(".")[0])):
            continue
        if not (math.isfinite(value) and value >= 0):
            raise ValueError(f"{where}: channel {channel!r}, term {process}: the value {row['Value']!r} "
                             "is not a number >= 0")
        unit = _undefuse(row["Unit"])
        if process in IEEE and sensor is not None and unit != SI_UNITS[sensor][process]:
            raise ValueError(f"{where}: channel {channel!r}, term {process} is in {unit!r}; a {sensor.lower()}'s "
                             f"terms are read in SI units ({SI_UNITS[sensor][process]})")
        if process in found.get(channel, {}):
            raise ValueError(f"{where}: channel {channel!r} has two {process} terms; give the table of one report "
                             "(a table of several logs' reports holds a channel per log)")
        found.setdefault(channel, {})[process] = float(value)
    channels = []
    for channel, column in zip(order, _columns(list(order.items()))):
        values = found.get(channel, {})
        terms = [Term(p, values[p]) for p in IEEE if values.get(p, 0.0) > 0]
        for process in sorted(p for p in values if _SHAPED.match(p)):
            kind = _SHAPED.match(process)[1]
            shape = values.get(f"{process}.T" if kind == "AR1" else f"{process}.f")
            if shape is None or not shape > 0:
                raise ValueError(f"{where}: channel {channel!r}, term {process} has no "
                                 f"{'correlation time' if kind == 'AR1' else 'frequency'} row ({process}."
                                 f"{'T' if kind == 'AR1' else 'f'}) > 0")
            if values[process] > 0:
                terms.append(Term(kind, values[process], shape))
        if not terms:
            raise ValueError(f"{where}: channel {channel!r} has no present term to simulate")
        channels.append(ChannelTerms(channel, column, order[channel], tuple(terms)))
    if not channels:
        raise ValueError(f"{where}: the table has no channel")
    return channels


def _yaml_number(value: Any) -> float | None:
    """A YAML number, or the text of one (PyYAML reads ``6e-4``, without a dot, as a string); else None."""
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return None
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def _kalibr_fields(fields: Mapping[str, Any], where: str) -> Mapping[str, Any]:
    """The mapping that holds the densities: the file's, or the one IMU's of a nested file (``imu0: {...}``)."""
    if any(key in fields for key in KALIBR_KEYS.values()):
        return fields
    nested = [v for v in fields.values() if isinstance(v, Mapping) and any(k in v for k in KALIBR_KEYS.values())]
    if len(nested) != 1:
        found = "several IMUs" if nested else "none"
        raise ValueError(f"{where}: one IMU's Kalibr densities ({', '.join(KALIBR_KEYS.values())}) expected, "
                         f"found {found}")
    return nested[0]


def _kalibr_terms(fields: Mapping[str, Any], where: str) -> list[ChannelTerms]:
    """Three axes per sensor type of a Kalibr yaml, each with its N (and K, when > 0)."""
    channels = []
    for kind in (GYRO, ACCEL):
        values = {}
        for process in ("WN", "RW"):
            key = KALIBR_KEYS[kind, process]
            if key in fields:
                value = _yaml_number(fields[key])
                if value is None or not (math.isfinite(value) and value >= 0):
                    raise ValueError(f"{where}: {key} must be a number >= 0, got {short_repr(fields[key])}")
                values[process] = value
        if not values:
            continue
        if not values.get("WN", 0.0) > 0:
            raise ValueError(f"{where}: {KALIBR_KEYS[kind, 'WN']} is missing or zero; a Kalibr IMU model needs it")
        terms = tuple(Term(p, v) for p, v in values.items() if v > 0)
        channels += [ChannelTerms(column, column, kind, terms) for column in AXES[kind]]
    return channels


def channel_terms(terms: Any) -> ModelSource:
    """The channels' terms of any accepted source, with the rate (Hz) and duration (s) it gives (or None).

    ``terms`` is a :class:`~avar.fit.report.result.NoiseReport`, its ``table`` (a DataFrame), or the path
    of a terms CSV (``avar report --output``) or of a Kalibr ``imu.yaml`` (``.yaml``/``.yml``).
    """
    if all(hasattr(terms, name) for name in ("table", "rate", "n_samples", "channels")):  # a NoiseReport
        return ModelSource(_table_terms(terms.table, "report"), float(terms.rate), terms.n_samples / float(terms.rate))
    if isinstance(terms, pd.DataFrame):
        return ModelSource(_table_terms(terms, "terms"), None, None)
    if isinstance(terms, (str, Path)):
        path = Path(terms)
        try:
            if path.suffix.lower() in (".yaml", ".yml"):
                import yaml

                fields = yaml.safe_load(path.read_text(encoding="utf-8"))
                if not isinstance(fields, Mapping):
                    raise ValueError(f"{path}: not a Kalibr imu.yaml (a mapping of keys to values)")
                fields = _kalibr_fields(fields, str(path))
                return ModelSource(_kalibr_terms(fields, str(path)), _yaml_number(fields.get("update_rate")), None)
            return ModelSource(_table_terms(pd.read_csv(path, keep_default_na=False, na_values=[""]), str(path)),
                               None, None)
        except (OSError, UnicodeDecodeError) as error:
            raise OSError(f"{path}: cannot read the terms ({error})") from None
    raise TypeError(f"terms must be a NoiseReport, its table (DataFrame) or the path of a terms CSV or Kalibr "
                    f"imu.yaml, got {type(terms).__name__}")


def simulate_channels(channels: list[ChannelTerms], n_samples: int, rate: float, seed: Any = None,
                      source: str = "") -> SimulatedLog:
    """Simulate ``n_samples`` of every channel at ``rate`` Hz (one random stream, channel after channel)."""
    rng = np.random.default_rng(check_seed(seed))
    columns = {c.column: c.model(rate).simulate(n_samples, seed=rng) for c in channels}
    return SimulatedLog(tuple(channels), Recording(columns, rate=rate, rate_source="given", source=source))


def simulate_log(terms: Any, duration: Any = None, rate: float | None = None, seed: Any = None) -> Recording:
    """A log simulated from a fitted noise model: every present term of every channel (see the module docstring).

    Parameters
    ----------
    terms : NoiseReport, DataFrame, str or Path
        A noise report (:func:`avar.noise_report`), its ``table``, the terms CSV that
        ``avar report LOG --output terms.csv`` writes, or a Kalibr ``imu.yaml`` (N and K per sensor
        type, on three axes each).
    duration : float or str, optional
        Length of the log in seconds, or a text with a unit: ``"2h"``, ``"90 min"``, ``"600 s"``
        (default: a report's own length; required for a CSV or yaml).
    rate : float, optional
        Sampling rate (Hz) (default: a report's rate, a yaml's ``update_rate``; required for a CSV).
    seed : None, int or numpy.random.Generator
        Random seed, for a reproducible log.

    Returns
    -------
    Recording
        Columns ``gx gy gz`` (rad/s) and ``ax ay az`` (m/s^2) per sensor type, channels of no type
        under their own names; ``n_samples = round(duration * rate)``.

    Examples
    --------
    >>> import avar
    >>> x = (avar.WN.from_continuous(1e-3, 100.0) + avar.RW.from_continuous(1e-5, 100.0)).simulate(360_000, seed=1)
    >>> report = avar.noise_report(x, gyro_units="rad/s", rate=100.0)
    >>> log = avar.simulate_log(report, duration="1h", seed=2)
    >>> log.names, log.n_samples, log.rate
    (('gx',), 360000, 100.0)
    >>> again = avar.noise_report(log)
    >>> round(again.value("gx", "WN") / report.value("x", "WN"), 2)
    1.0
    """
    return simulated(terms, duration, rate, seed).recording


def simulated(terms: Any, duration: Any = None, rate: float | None = None, seed: Any = None) -> SimulatedLog:
    """:func:`simulate_log` with the channels' terms beside the recording."""
    source = channel_terms(terms)
    channels, own_rate, own_duration = source.channels, source.rate, source.duration
    if rate is None and own_rate is None:
        raise ValueError("rate: give the sampling rate (Hz) to simulate at; a terms table does not hold one, "
                         "nor a Kalibr yaml without update_rate")
    rate = check_rate(own_rate if rate is None else rate)
    if duration is None and own_duration is None:
        raise ValueError("duration: give the length to simulate (seconds, or e.g. '2h'); a terms table or "
                         "Kalibr yaml does not hold one")
    seconds = own_duration if duration is None else parse_duration(duration)
    n_samples = check_count(int(round(seconds * rate)), "duration * rate", minimum=2)
    where = f"simulated from {terms}" if isinstance(terms, (str, Path)) else "simulated"
    return simulate_channels(channels, n_samples, rate, seed, where)
