"""Time steps of a recording: its rate, jitter and gaps, from time stamps or a time index.

One concept for every reader: a step longer than :data:`GAP_FACTOR` median steps is a gap;
the rate is 1 / the least-squares step between gaps (robust to stamps rounded to the
millisecond); the jitter is the rms of the other steps about it. Used by the time columns
of text logs (:mod:`avar.io.timecols`), clock logs (:mod:`avar.io.clocks`) and pandas time
indexes (:func:`rate_from_index`, for :func:`avar._validation.as_series`).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

#: A time step longer than this many median steps is a gap.
GAP_FACTOR = 1.5


class StepAnalysis(NamedTuple):
    """What :func:`analyze_steps` finds in the time steps of a recording."""

    #: Sampling rate (Hz): 1 / the least-squares step between gaps.
    rate: float
    #: The median step (s).
    median_step: float
    #: Root mean square of the steps (outside gaps) about 1 / ``rate`` (s).
    jitter: float
    #: 0-based positions ``i`` of the gap steps (between samples ``i`` and ``i + 1``).
    gaps: np.ndarray


def analyze_steps(steps: np.ndarray) -> StepAnalysis:
    """Rate, median step, jitter and gaps of the time steps (s) of a recording.

    The median step locates the gaps: steps longer than ``GAP_FACTOR`` median steps. The
    step is then the least-squares slope of time against sample number, pooled over the
    stretches between gaps: the rounding of stamps (a 300 Hz log stamped to the
    millisecond steps 3, 3, 4 ms) biases the median step (333 Hz) and barely moves the
    slope. The rate is 1 / that step; the jitter is the root mean square of the
    deviations of the steps (outside gaps) from it (s).

    Returns
    -------
    StepAnalysis
        ``rate`` (Hz), ``median_step`` (s), ``jitter`` (s, rms) and ``gaps`` (0-based
        positions ``i`` of the gap steps, between samples ``i`` and ``i + 1``).

    Raises
    ------
    ValueError
        A step that is not > 0 (the message gives its position), or no step at all.

    >>> steps = analyze_steps(np.diff(np.round(np.arange(3000) / 0.3)) / 1000)
    >>> round(steps.rate, 2), steps.median_step, round(steps.jitter * 1e3, 3), steps.gaps.size
    (300.0, 0.003, 0.471, 0)
    """
    steps = np.asarray(steps, dtype=np.float64)
    if steps.size == 0:
        raise ValueError("a time axis needs at least two samples")
    bad = ~(steps > 0)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"time does not increase strictly: sample {i + 2} is at {steps[i]:+.6g} s from sample {i + 1}"
            f"{f' ({int(bad.sum())} such steps)' if bad.sum() > 1 else ''}; sort the samples or drop duplicate times"
        )
    median = float(np.median(steps))
    is_gap = steps > GAP_FACTOR * median
    times = np.concatenate([[0.0], np.cumsum(steps)])
    segment = np.concatenate([[0], np.cumsum(is_gap)])
    counts = np.bincount(segment).astype(np.float64)
    number = np.arange(times.size, dtype=np.float64)
    d_number = number - (np.bincount(segment, number) / counts)[segment]
    d_time = times - (np.bincount(segment, times) / counts)[segment]
    spread = float(d_number @ d_number)
    step = float(d_number @ d_time) / spread if spread > 0 else float(steps[~is_gap].mean())
    regular = steps[~is_gap]
    jitter = float(np.sqrt(np.mean((regular - step) ** 2)))
    return StepAnalysis(1.0 / step, median, jitter, np.flatnonzero(is_gap))


def describe_gaps(gaps: np.ndarray, steps: np.ndarray, median: float, seconds_at) -> str:
    """'3 gap(s) (steps > 1.5 x the median step 5 ms); the first after sample 1200 (t = 6 s), 0.5 s long'.

    ``seconds_at(i)`` gives the time (s from the first sample) of 0-based sample ``i``.
    """
    first = int(gaps[0])
    return (
        f"{gaps.size} gap(s) (time steps > {GAP_FACTOR:g} x the median step {median:.6g} s); the first is between "
        f"samples {first + 1} and {first + 2} (row {first + 2} at t = {seconds_at(first + 1):.6g} s), "
        f"a step of {float(steps[first]):.6g} s"
    )


def _rate_from_seconds(seconds: np.ndarray, what: str) -> float:
    steps = np.diff(seconds)
    try:
        found = analyze_steps(steps)
    except ValueError as error:
        raise ValueError(f"{what} has a time index where {error}") from None
    if found.gaps.size:
        origin = seconds[0]
        message = describe_gaps(found.gaps, steps, found.median_step, lambda i: seconds[i] - origin)
        raise ValueError(f"{what} has a time index with {message}; fill or cut them, or pass the sampling rate explicitly")
    return found.rate


def rate_from_index(index: Any, what: str) -> float | None:
    """Sampling rate (Hz) of a time index: regular Datetime/Timedelta, Period, or float seconds.

    A float index holds times in seconds: its rate is 1 / the mean step (see
    :func:`analyze_steps`; timestamp rounding and jitter are accepted, gaps are not).
    A PeriodIndex gives the rate of its periods. Returns None for other indexes (a
    RangeIndex or integer index numbers samples, it does not time them); raises
    ValueError for an irregular Datetime/Timedelta index or a float index with gaps.
    """
    import pandas as pd  # an index is a pandas object: pandas is loaded already
    if isinstance(index, pd.PeriodIndex) and len(index) >= 2:
        index = index.to_timestamp()
    if index.dtype.kind == "f" and len(index) >= 2:
        return _rate_from_seconds(index.to_numpy(dtype=np.float64), what)
    if not isinstance(index, (pd.DatetimeIndex, pd.TimedeltaIndex)) or len(index) < 2:
        return None
    steps = np.diff((index.tz_convert(None) if getattr(index, "tz", None) else index).to_numpy())  # own unit
    unit, count = np.datetime_data(steps.dtype)
    steps = steps.astype(np.int64)
    if np.any(steps <= 0):
        raise ValueError(f"{what} has a time index that does not increase strictly; sort it or drop duplicate times")
    if np.any(steps != steps[0]):
        raise ValueError(f"{what} has an irregular time index (steps from {steps.min() * count} to "
                         f"{steps.max() * count} {unit}); resample it to a regular grid or pass the sampling rate explicitly")
    return 1.0 / (float(steps[0]) * (np.timedelta64(count, unit) / np.timedelta64(1, "s")))
