"""Stable32's Check before any statistic: outliers, phase and frequency jumps, and their correction.

A clock record often holds a few bad points: a spike in the phase (a missed or false count),
a phase step (a cable swapped, a counter reset) or a frequency step (a synthesizer retuned,
a change of reference). Each raises the short-tau deviations and can flip the identified
noise type, silently. :func:`check` finds them in the fractional frequency y (phase data
are differenced first, y_i = (x_{i+1} - x_i) rate), reports each with its sample index,
time and size, and :meth:`CheckReport.corrected` returns the data with them removed.

* **Outliers** (Stable32's Check): y_i with |y_i - median(y)| > ``factor`` MAD, where
  MAD = median(|y - median(y)|) / 0.6745 (the standard deviation of Gaussian data).
* In phase data an outlier of y is a **phase spike** when two adjacent outliers have
  opposite signs and sizes within a factor of 2 (the phase went away and came back: one bad
  phase point), and a **phase jump** when it stands alone (the phase stepped and stayed).
  In frequency data every outlier is a frequency spike.
* **Frequency jumps**: steps of the mean of y, found where the difference of the means of the
  ``window`` values after and before a point exceeds ``factor`` times its standard error
  (MAD sqrt(2 / window)), taken at the local maximum of that difference.

Corrections: a phase spike is replaced by the mean of its neighbours, a phase jump is removed
from every later phase point, a frequency spike becomes the median of y (or NaN with
``outliers="nan"``), a frequency jump is removed from every later frequency value (for phase
data: the ramp it put into the phase). Nothing is changed silently: the report lists every
change.

References
----------
W. J. Riley, Handbook of Frequency Stability Analysis, NIST SP 1065 (2008), section 5
(data preprocessing); Stable32 User Manual, "Check".
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from avar._validation import check_freq, short_repr
from avar.stability.shared.inputs import finite_vector

__all__ = ["CheckReport", "Event", "check"]

#: MAD / 0.6745 is the standard deviation of Gaussian data.
MAD_SCALE = 0.6745


@dataclass(frozen=True)
class Event:
    """One bad point or step found in the data.

    Attributes
    ----------
    kind : {"phase spike", "phase jump", "frequency spike", "frequency jump"}
    index : int
        Sample index in the data as given (phase: the phase point that is bad, or the first
        one after the jump; frequency: the frequency value).
    time : float
        ``index / rate`` (s).
    size : float
        Phase spike/jump: the phase excursion or step (s); frequency spike: y_i - median(y);
        frequency jump: the step of the mean of y (dimensionless).
    """

    kind: str
    index: int
    time: float
    size: float


@dataclass(frozen=True, eq=False)
class CheckReport:
    """What :func:`check` found, and the data it came from.

    Attributes
    ----------
    events : tuple of Event
        Every spike and jump, in order of index.
    data_type : {"phase", "freq"}
    rate : float
    threshold : float
        ``factor`` MAD of y (dimensionless): the outlier threshold used.
    mad : float
        The MAD of y (scaled to a standard deviation).
    """

    events: tuple[Event, ...]
    data_type: str
    rate: float
    threshold: float
    mad: float
    data: np.ndarray = field(repr=False)
    outliers_to: str = "fill"

    def kinds(self, kind: str) -> tuple[Event, ...]:
        """The events of one kind."""
        return tuple(e for e in self.events if e.kind == kind)

    def corrected(self) -> np.ndarray:
        """The data with every event removed (see the module docstring); a new array."""
        x = np.array(self.data, dtype=np.float64)
        if self.data_type == "phase":
            for event in self.events:
                if event.kind == "phase spike":
                    i = event.index
                    x[i] = 0.5 * (x[i - 1] + x[i + 1]) if 0 < i < x.size - 1 else np.nan
                elif event.kind == "phase jump":
                    x[event.index:] -= event.size
                elif event.kind == "frequency jump":
                    ramp = (np.arange(x.size - event.index, dtype=np.float64) + 1.0) / self.rate
                    x[event.index:] -= event.size * ramp
            return x
        median = float(np.median(self.data))
        for event in self.events:
            if event.kind == "frequency spike":
                x[event.index] = np.nan if self.outliers_to == "nan" else median
            elif event.kind == "frequency jump":
                x[event.index:] -= event.size
        return x

    def summary(self):
        """A table: Kind, Index, Time (s), Size."""
        import pandas as pd

        return pd.DataFrame([(e.kind, e.index, e.time, e.size) for e in self.events],
                            columns=["Kind", "Index", "Time (s)", "Size"])

    def __str__(self) -> str:
        if not self.events:
            return f"check: no outliers or jumps ({len(self.data)} {self.data_type} points, threshold {self.threshold:.3g})"
        lines = [f"check: {len(self.events)} event(s) in {len(self.data)} {self.data_type} points "
                 f"(threshold {self.threshold:.3g} in fractional frequency):"]
        unit = {"phase spike": "s", "phase jump": "s", "frequency spike": "", "frequency jump": ""}
        for e in self.events:
            lines.append(f"  {e.kind} at index {e.index} (t = {e.time:g} s), size {e.size:.4g}{' ' + unit[e.kind] if unit[e.kind] else ''}")
        return "\n".join(lines)


def _outliers(y: np.ndarray, factor: float) -> tuple[np.ndarray, float, float]:
    median = float(np.median(y))
    mad = float(np.median(np.abs(y - median))) / MAD_SCALE
    if mad == 0.0:
        mad = float(np.std(y)) or 1.0
    return np.flatnonzero(np.abs(y - median) > factor * mad), median, mad


def _frequency_jumps(y: np.ndarray, bad: np.ndarray, window: int, factor: float, mad: float) -> list[int]:
    """Indices k where the mean of y[k:k+w] departs from the mean of y[k-w:k] beyond ``factor``
    standard errors, at the local maximum of the departure; outliers are left out of the means."""
    clean = y.astype(np.float64).copy()
    clean[bad] = np.nan
    valid = ~np.isnan(clean)
    filled = np.where(valid, clean, 0.0)
    s = np.concatenate(([0.0], np.cumsum(filled)))
    c = np.concatenate(([0], np.cumsum(valid)))
    k = np.arange(window, y.size - window + 1)
    n_after, n_before = c[k + window] - c[k], c[k] - c[k - window]
    ok = (n_after > window // 2) & (n_before > window // 2)
    diff = np.zeros(k.size)
    diff[ok] = (s[k + window] - s[k])[ok] / n_after[ok] - (s[k] - s[k - window])[ok] / n_before[ok]
    limit = factor * mad * np.sqrt(2.0 / window)
    found = []
    over = np.abs(diff) > limit
    i = 0
    while i < k.size:
        if over[i]:
            j = i
            while j < k.size and over[j]:
                j += 1
            found.append(int(k[i + int(np.argmax(np.abs(diff[i:j])))]))
            i = j
        else:
            i += 1
    return found


def check(data: Any, data_type: str = "freq", rate: float = 1.0, factor: float = 5.0, window: int | None = None,
          outliers: str = "fill") -> CheckReport:
    """Find outliers, phase spikes and jumps, and frequency jumps (Stable32's Check); see the module.

    Parameters
    ----------
    data : array_like
        Phase (s) or fractional frequency, 1-D, finite.
    data_type : {"freq", "phase"}
    rate : float
        Sampling rate in Hz (for the events' times and the ramp of a frequency jump in phase data).
    factor : float
        Threshold in MADs (Stable32's default 5), > 0.
    window : int, optional
        Values averaged on each side of a frequency jump (default max(16, N // 50)); None or >= 4.
    outliers : {"fill", "nan"}
        How :meth:`CheckReport.corrected` replaces a frequency spike: the median of y, or NaN
        (a gap for ``nan_policy="omit"``).

    Returns
    -------
    CheckReport

    Examples
    --------
    >>> import numpy as np, avar
    >>> x = np.cumsum(np.random.default_rng(1).standard_normal(10_000)) * 1e-12   # phase, s
    >>> x[4000:] += 1e-9          # a 1 ns phase step
    >>> x[7000] += 5e-9           # a 5 ns phase spike
    >>> report = avar.check(x, data_type="phase")
    >>> [(e.kind, e.index, round(e.size * 1e9, 2)) for e in report.events]
    [('phase jump', 4000, 1.0), ('phase spike', 7000, 5.0)]
    """
    rate = check_freq(rate, "rate")
    if not isinstance(data_type, str) or data_type not in ("freq", "phase"):
        raise ValueError(f"data_type must be 'freq' or 'phase', got {short_repr(data_type)}")
    if isinstance(factor, bool) or not isinstance(factor, (int, float, np.integer, np.floating)) or not factor > 0:
        raise ValueError(f"factor must be a number of MADs > 0 (Stable32: 5), got {short_repr(factor)}")
    if outliers not in ("fill", "nan"):
        raise ValueError(f"outliers must be 'fill' (the median) or 'nan' (a gap), got {short_repr(outliers)}")
    values = finite_vector(data, "data", 10 if data_type == "phase" else 9)
    y = np.diff(values) * rate if data_type == "phase" else values
    if window is None:
        window = max(16, y.size // 50)
    if isinstance(window, bool) or not isinstance(window, (int, np.integer)) or not 4 <= window <= y.size // 2:
        raise ValueError(f"window must be a whole number of values in 4 .. {y.size // 2}, got {short_repr(window)}")
    bad, median, mad = _outliers(y, float(factor))
    events: list[Event] = []
    used: set[int] = set()
    for i in bad.tolist():
        if i in used:
            continue
        if data_type == "phase":
            j = i + 1
            pair = (j in set(bad.tolist()) and np.sign(y[i] - median) != np.sign(y[j] - median)
                    and 0.5 <= abs(y[j] - median) / abs(y[i] - median) <= 2.0)
            if pair:  # x[j] (between y_i and y_j) went away and came back
                size = 0.5 * ((y[i] - median) - (y[j] - median)) / rate
                events.append(Event("phase spike", j, j / rate, float(size)))
                used.update((i, j))
            else:  # the phase stepped between x[i] and x[i + 1]
                events.append(Event("phase jump", i + 1, (i + 1) / rate, float((y[i] - median) / rate)))
                used.add(i)
        else:
            events.append(Event("frequency spike", i, i / rate, float(y[i] - median)))
    for k in _frequency_jumps(y, bad, int(window), float(factor), mad):
        w = int(window)
        after, before = y[k:k + w], y[k - w:k]
        keep_a, keep_b = ~np.isin(np.arange(k, k + w), bad), ~np.isin(np.arange(k - w, k), bad)
        step = float(np.mean(after[keep_a]) - np.mean(before[keep_b]))
        index = k + 1 if data_type == "phase" else k  # the phase point where the ramp starts
        events.append(Event("frequency jump", index, index / rate, step))
    events.sort(key=lambda e: e.index)
    return CheckReport(tuple(events), data_type, rate, float(factor) * mad, mad, values, outliers)
