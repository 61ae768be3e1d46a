"""What a clock log reader returns: :class:`ClockLog`, its :class:`Gaps`, and :class:`ClockLogError`.

A clock log is one series of time error (phase, s) or fractional frequency with its time
stamps. The rate is 1 / the median time step; a step longer than 1.5 median steps is a gap.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from avar._frozen import frozen_array, frozen_frame, frozen_mapping
from avar._time_steps import GAP_FACTOR

if TYPE_CHECKING:  # pandas loads with the reader
    import pandas as pd

#: How far (in median steps) a step may be from a whole number of steps and still sit on the grid.
GRID_TOLERANCE = 0.25


class ClockLogError(ValueError):
    """A clock log that cannot be read: the message names the file, the line and the field."""


class Gaps(NamedTuple):
    """The steps of a clock log's time stamps longer than 1.5 median steps.

    Attributes
    ----------
    count : int
        How many such steps.
    positions : ndarray of int
        0-based ``i`` of each: the gap lies between samples ``i`` and ``i + 1``.
    lengths : ndarray of float
        Each gap step's length (s).
    """

    count: int
    positions: np.ndarray
    lengths: np.ndarray


class StepsAndGaps(NamedTuple):
    """The median time step of a clock log and its :class:`Gaps` (:func:`find_gaps`)."""

    #: The median step (s).
    median_step: float
    gaps: Gaps


def find_gaps(times: np.ndarray) -> StepsAndGaps:
    """The median step (s) of increasing ``times`` (s) and the :class:`Gaps` among the steps
    (steps longer than :data:`avar._time_steps.GAP_FACTOR` median steps).

    >>> found = find_gaps(np.array([0.0, 64, 128, 256, 320]))
    >>> found.median_step, found.gaps.count, found.gaps.positions.tolist(), found.gaps.lengths.tolist()
    (64.0, 1, [2], [128.0])
    """
    steps = np.diff(times)
    median = float(np.median(steps))
    where = np.flatnonzero(steps > GAP_FACTOR * median)
    return StepsAndGaps(median, Gaps(int(where.size), frozen_array(where, np.int64), frozen_array(steps[where])))


def grid_positions(times: np.ndarray, step: float) -> np.ndarray | None:
    """The sample number of each stamp on a grid of ``step`` (s), counted step by step; None off the grid.

    Each step is rounded to a whole number of ``step`` on its own, so a clock whose stamps drift
    slowly against the nominal step stays on the grid.

    >>> grid_positions(np.array([0.0, 1.001, 1.999, 5.0]), 1.0).tolist()
    [0, 1, 2, 5]
    >>> grid_positions(np.array([0.0, 1.0, 1.5]), 1.0) is None
    True
    """
    ratios = np.diff(times) / step
    whole = np.round(ratios)
    if np.any(whole < 1) or np.any(np.abs(ratios - whole) > GRID_TOLERANCE):
        return None
    return np.concatenate([[0], np.cumsum(whole.astype(np.int64))])


@dataclass(frozen=True, eq=False)  # arrays: identity, as for any container of arrays
class ClockLog:
    """One clock series read from a log: time error (phase) or fractional frequency, with its stamps.

    :func:`avar.read_clock_log` builds it; ``avar.oadev(log.values, rate=log.rate,
    data_type=log.data_type)`` takes it as it is.

    Attributes
    ----------
    times : ndarray of float64
        Time stamps (s since the first stamp).
    values : ndarray of float64
        Time error (s) when ``data_type`` is ``"phase"``, fractional frequency (dimensionless)
        when it is ``"freq"``.
    data_type : str
        ``"phase"`` or ``"freq"``.
    column : str
        Which field was taken and why, e.g. ``"chrony tracking.log: Offset (s), the estimated
        local offset, positive when the clock is fast of UTC (the default)"``.
    rate : float
        Sampling rate (Hz): 1 / the median time step.
    gaps : Gaps
        The time steps longer than 1.5 median steps (count, positions, lengths in s).
    source : str
        The format, e.g. ``"chrony tracking.log"``, ``"ntpd peerstats"``, ``"RINEX clock 3.04"``.
    columns : pandas.DataFrame
        Every numeric field of the samples taken, in the file's units (the field names say
        which: ``Offset`` is s, ``Freq ppm`` ppm...), indexed by ``times``: for the user who
        wants another field (or pass ``column=`` to the reader).
    path : str
        The file read.
    start : pandas.Timestamp or None
        The first stamp as a date and time (UTC, or the file's time system) when the format
        gives one; None for monotonic stamps (linuxptp) and files without time tags.
    selected : str or None
        The source taken when the file holds several (an IP address, a satellite, a station, a
        linuxptp clock), and why.
    available : Mapping[str, int]
        Every source in the file and its number of samples (empty for one-source formats).
    skipped : Mapping[str, int]
        Lines left out and why (banners, other kinds of line, servo states...), counted.
    lines : ndarray of int64
        The file line (1-based) of each sample.

    Examples
    --------
    >>> import os, tempfile
    >>> import avar
    >>> path = os.path.join(tempfile.mkdtemp(), "phc2sys.log")
    >>> with open(path, "w") as f:
    ...     for k, offset in enumerate([-12, 7, 3, -5, 4, 1]):
    ...         if k != 2:  # a missed update: a gap
    ...             _ = f.write(f"phc2sys[{100 + k}.250]: CLOCK_REALTIME phc offset {offset} s2 freq -3456\\n")
    >>> log = avar.read_clock_log(path)
    >>> log.values.tolist(), log.times.tolist(), log.rate, log.gaps.count
    ([-1.2e-08, 7e-09, -5e-09, 4e-09, 1e-09], [0.0, 1.0, 3.0, 4.0, 5.0], 1.0, 1)
    >>> log.to_series().tolist()
    [-1.2e-08, 7e-09, nan, -5e-09, 4e-09, 1e-09]
    """

    times: np.ndarray
    values: np.ndarray
    data_type: str
    column: str
    rate: float
    gaps: Gaps
    source: str
    columns: pd.DataFrame
    path: str = ""
    start: Any = None
    selected: str | None = None
    available: Mapping[str, int] = field(default_factory=dict)
    skipped: Mapping[str, int] = field(default_factory=dict)
    lines: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    def __post_init__(self) -> None:
        if self.data_type not in ("phase", "freq"):
            raise ValueError(f"data_type must be 'phase' or 'freq', got {self.data_type!r}")
        times, values = frozen_array(self.times), frozen_array(self.values)
        if times.shape != values.shape:
            raise ValueError(f"times and values differ in length: {times.size} and {values.size}")
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "columns", frozen_frame(self.columns))
        lines = frozen_array(self.lines, np.int64)
        if lines.size not in (0, times.size):
            raise ValueError(f"lines holds {lines.size} line numbers for {times.size} samples")
        object.__setattr__(self, "lines", lines)
        object.__setattr__(self, "available", frozen_mapping(self.available))
        object.__setattr__(self, "skipped", frozen_mapping(self.skipped))

    def __len__(self) -> int:
        return int(self.values.size)

    @property
    def n(self) -> int:
        """Number of samples."""
        return len(self)

    def to_series(self) -> pd.Series:
        """The values as a pandas Series, on a regular time index where the stamps allow one.

        When every time step is close to a whole number of median steps (within a quarter
        step), the index is the regular grid ``k / rate`` (s) from the first stamp to the last,
        and the samples a gap leaves out are NaN (``avar.avar(series, nan_policy="omit")``
        skips them); otherwise the index is the stamps themselves. Either way the index is
        float seconds named ``"time (s)"``; ``series.attrs`` holds ``data_type``, ``rate``,
        ``source``, ``column`` and ``missing`` (the NaN count).

        Returns
        -------
        pandas.Series
            Phase (s) or fractional frequency, named by the field taken.
        """
        import pandas as pd

        step = 1.0 / self.rate
        positions = grid_positions(self.times, step) if self.n > 1 else np.zeros(self.n, dtype=np.int64)
        if positions is None:
            values, index, missing = self.values.copy(), self.times.copy(), 0
        else:
            values = np.full(int(positions[-1]) + 1, np.nan)
            values[positions] = self.values
            index, missing = np.arange(values.size) * step, int(values.size - self.n)
        name = self.column.split(": ", 1)[-1].split(" (", 1)[0]
        series = pd.Series(values, index=pd.Index(index, name="time (s)"), name=name)
        series.attrs.update(data_type=self.data_type, rate=self.rate, source=self.source, column=self.column,
                            missing=missing)
        return series

    def describe(self) -> str:
        """A few lines on what was read: the field, the rate, the gaps, the sources, what was skipped."""
        what = "phase (s)" if self.data_type == "phase" else "fractional frequency"
        text = [f"{self.path}: {self.source}, {self.n} samples of {what}", f"  column: {self.column}",
                f"  rate: {self.rate:.6g} Hz (median step {1 / self.rate:.6g} s)"]
        if self.gaps.count:
            first = int(self.gaps.positions[0])
            line = f" (line {int(self.lines[first])})" if self.lines.size == self.n else ""
            text.append(f"  gaps: {self.gaps.count} step(s) > {GAP_FACTOR:g} median steps; the first after sample "
                        f"{first + 1}{line}, {float(self.gaps.lengths[0]):.6g} s long")
        if self.selected is not None:
            text.append(f"  source: {self.selected}")
        if self.skipped:
            text.append("  skipped: " + "; ".join(f"{count} {why}" for why, count in self.skipped.items()))
        return "\n".join(text)

    def __str__(self) -> str:
        return self.describe()
