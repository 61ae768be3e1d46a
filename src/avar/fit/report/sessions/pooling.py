"""The pooled terms of several logs: their pooled Allan variance, fitted once.

The logs are replicates of one process. At every averaging factor m common to
all logs (the octaves up to the shortest log's largest level), the pooled Allan
variance weighs each log's estimate by its number of differences
d_i = N_i - 2m + 1 (maximal overlap; K_i - 1 for "to")::

    AV_pooled(m) = sum_i d_i AV_i(m) / sum_i d_i

which is the Allan variance of the logs put end to end without the differences
that would straddle two logs. The noise model is then selected and fitted once on
that curve (:func:`avar.fit.report.noise_report.noise_report` on an Allan
variance of N = sum N_i samples).

Why pool the Allan variance rather than average the per-log terms with
inverse-variance weights: each log selects its own model, so a term can be
``present`` in one log and only a ``bound`` in another, and a weighted mean of
estimates whose weights depend on the estimates themselves (the variance of a
log-scale term grows with it) is biased low; the pooled curve resolves the
terms jointly, on k times the data, with one model selection. The fit's
intervals take the pooled curve as one log of sum N_i samples: exact for the
white-noise levels, slightly narrow at the largest levels (k logs have k (N - 2m + 1)
differences there, one log of k N samples k N - 2m + 1).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from avar.fit.report.noise_report import noise_report
from avar.fit.report.noise_terms import ACCEL, GYRO
from avar.fit.report.result import NoiseReport
from avar.stability.allan.results import AllanVariance

__all__ = ["RATE_TOLERANCE", "common_channels", "pooled_allan", "pooled_report"]

#: Largest relative difference of the logs' rates (timestamps give 100.002 Hz and 99.998 Hz for one sensor).
RATE_TOLERANCE = 0.01


def common_channels(reports: Sequence[NoiseReport], names: Sequence[str]) -> tuple[str, ...]:
    """The channels of the first log, checked to be in every log with the same sensor type and unit."""
    first = reports[0]
    for name, report in zip(names[1:], reports[1:]):
        if set(report.channels) != set(first.channels):
            raise ValueError(f"logs: {name!r} has the channels {list(report.channels)}, {names[0]!r} "
                             f"{list(first.channels)}; several logs of one sensor have the same channels")
        for channel, kind, unit in zip(first.channels, first.sensor_types, first.units):
            at = report.channels.index(channel)
            if (report.sensor_types[at], report.units[at]) != (kind, unit):
                raise ValueError(f"logs: channel {channel!r} is {report.sensor_types[at]} in "
                                 f"{report.units[at]} in {name!r}, {kind} in {unit} in {names[0]!r}")
    rates = np.array([report.rate for report in reports])
    if rates.max() > rates.min() * (1.0 + RATE_TOLERANCE):
        raise ValueError(f"logs: the rates differ by more than {100 * RATE_TOLERANCE:g} % "
                         f"({dict(zip(names, rates.round(6).tolist()))} Hz); pool logs of one rate")
    types = {av.type for report in reports for av in report.avs.values()}
    if len(types) != 1:
        raise ValueError(f"logs: the Allan variances mix the estimator types {sorted(types)}")
    return first.channels


def common_factors(avs: Sequence[AllanVariance]) -> np.ndarray:
    """The averaging factors every Allan variance has, in increasing order."""
    factors = set(np.asarray(avs[0].averaging_factors).tolist())
    for av in avs[1:]:
        factors &= set(np.asarray(av.averaging_factors).tolist())
    return np.array(sorted(factors), dtype=np.int64)


def _at(av: AllanVariance, factors: np.ndarray, field: str) -> np.ndarray:
    index = {int(m): i for i, m in enumerate(av.averaging_factors)}
    return np.asarray(getattr(av, field))[[index[int(m)] for m in factors]]


def pooled_allan(avs: Sequence[AllanVariance], name: str | None = None) -> AllanVariance:
    """The pooled Allan variance of replicate logs (see the module): weights d_i, N = sum N_i.

    Examples
    --------
    >>> import avar
    >>> a = avar.avar(avar.WN(sigma2=1.0).simulate(4096, seed=1), freq=10.0)
    >>> b = avar.avar(avar.WN(sigma2=4.0).simulate(4096, seed=2), freq=10.0)
    >>> pooled = pooled_allan([a, b])
    >>> pooled.n, round(float(pooled.allan[0] / (a.allan[0] + b.allan[0]) * 2), 6)
    (8192, 1.0)
    """
    factors = common_factors(avs)
    if factors.size == 0:
        raise ValueError("pooled_allan: the Allan variances share no averaging factor")
    counts = np.array([_at(av, factors, "n_differences") for av in avs], dtype=np.float64)
    values = np.array([_at(av, factors, "allan") for av in avs], dtype=np.float64)
    total = counts.sum(axis=0)
    n = int(sum(av.n for av in avs))
    rate = float(np.average([av.freq for av in avs], weights=[av.n for av in avs]))
    return AllanVariance(
        levels=factors / rate, averaging_factors=factors, allan=(counts * values).sum(axis=0) / total,
        errors=1.0 / np.sqrt(2.0 * np.maximum(n / factors - 1.0, 1.0)), n_differences=total.astype(np.int64),
        type=avs[0].type, freq=rate, n=n, name=name if name is not None else avs[0].name)


def pooled_report(reports: Sequence[NoiseReport], names: Sequence[str], confidence: float,
                  label: str | None = None) -> NoiseReport:
    """The noise report of the pooled Allan variance of every channel (see the module)."""
    channels = common_channels(reports, names)
    first = reports[0]
    avs, fits, terms, curves, warnings = {}, {}, [], [], []
    for channel, kind, unit in zip(channels, first.sensor_types, first.units):
        av = pooled_allan([report.avs[channel] for report in reports], name=channel)
        units = {"gyro_units": unit} if kind == GYRO else {"accel_units": unit} if kind == ACCEL else {}
        one = noise_report(av, confidence=confidence, **units)
        avs[channel], fits[channel] = one.avs[channel], one.fits[channel]
        terms.append(one.terms)
        curves.append(one.curves)
        warnings += list(one.warnings)
    pooled_av = next(iter(avs.values()))
    return NoiseReport(
        name=label or f"pooled ({len(reports)} logs)", source=None, topic=first.topic, rate=pooled_av.freq,
        n_samples=pooled_av.n, channels=channels, sensor_types=first.sensor_types, units=first.units, avs=avs,
        fits=fits, terms=pd.concat(terms, ignore_index=True), confidence=confidence,
        curves=pd.concat(curves, ignore_index=True), warnings=tuple(warnings))

