"""A recording read from a log: named columns, their sampling rate and how it was found.

:class:`Recording` is what :func:`avar.read` returns for a table of series (an
:class:`avar.IMU` when gyroscope and accelerometer columns are named). Like the IMU it
holds data and computes nothing; it sits beside :mod:`avar.imu` so that estimators can
accept it without knowing about files.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from avar._escape import terminal
from avar._frozen import frozen_mapping
from avar._vocabulary import check_rate, renamed


def _read_only(values: Any) -> np.ndarray:
    """The column itself when already read-only (the reader's own arrays), else a read-only copy."""
    array = np.asarray(values)
    if array.dtype.kind not in "iuf":
        raise TypeError(f"a column must be numeric, got dtype {array.dtype}")
    if array.flags.writeable:
        array = array.copy()
        array.flags.writeable = False
    return array


def _duration(seconds: float) -> str:
    """'0.33 ms', '2 us', '1.5 s' (the largest unit that keeps the number >= 0.1)."""
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9)):
        if abs(seconds) >= 0.1 * scale or unit == "ns":
            return f"{seconds / scale:.3g} {unit}"
    raise AssertionError  # pragma: no cover


@dataclass(frozen=True, eq=False, init=False)  # arrays: identity, as for any container of arrays
class Recording:
    """Named series sampled together, with their rate and where it came from.

    :func:`avar.read` builds it; ``Recording(columns, rate=..., rate_source=...)`` with the
    fields below builds one by hand.

    Attributes
    ----------
    columns : Mapping[str, ndarray]
        The data columns in file order, read-only 1-D arrays of one length: float64, or
        int64 for columns of integers (kept exact; :func:`avar.avar` centres them
        exactly). Time columns are never among them.
    rate : float
        Sampling rate (Hz): from the time column, given by the caller, or 1.0 when
        there is neither (then ``rate_source`` says so). ``freq`` is the same value.
    rate_source : str
        Where ``rate`` came from, e.g. ``"time column 'time'"``, ``"given"`` (the
        default) or ``"none (no time column): 1 Hz, sample numbers as time"``.
    time_column : str or None
        The column that timed the samples.
    jitter : float or None
        Root mean square of the time steps' deviations from the mean step (s).
    gap_rows : ndarray of int
        0-based samples that follow a gap (a time step longer than 1.5 median steps).
    gap_steps : ndarray of float
        The length of each of those steps (s).
    gaps_ignored : bool
        Whether the gaps were accepted and the samples treated as contiguous.
    source : str
        The file (and topic) the samples came from.

    Examples
    --------
    >>> import numpy as np
    >>> rec = Recording({"gx": np.arange(6.0)}, rate=100.0, rate_source="given")
    >>> rec.names, rec.n_samples, rec["gx"][:3]
    (('gx',), 6, array([0., 1., 2.]))
    >>> rec.rate_note()
    'at 100 Hz (given)'
    """

    columns: Mapping[str, np.ndarray]
    rate: float
    rate_source: str = "given"
    time_column: str | None = None
    jitter: float | None = None
    gap_rows: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    gap_steps: np.ndarray = field(default_factory=lambda: np.zeros(0))
    gaps_ignored: bool = False
    source: str = ""

    def __init__(self, columns: Mapping[str, Any], rate: float | None = None, rate_source: str = "given",
                 time_column: str | None = None, jitter: float | None = None, gap_rows: Any = (),
                 gap_steps: Any = (), gaps_ignored: bool = False, source: str = "", *,
                 freq: float | None = None) -> None:
        rate, rate_name = renamed("rate", rate, "freq", freq, deprecated=True)
        if rate is None:
            raise TypeError("a Recording needs its sampling rate: Recording(columns, rate=HZ)")
        values = {"columns": columns, "rate": check_rate(rate, rate_name), "rate_source": rate_source, "time_column": time_column,
                  "jitter": jitter, "gap_rows": gap_rows, "gap_steps": gap_steps, "gaps_ignored": gaps_ignored,
                  "source": source}
        for name, value in values.items():
            object.__setattr__(self, name, value)
        self.__post_init__()

    def __post_init__(self) -> None:
        if not isinstance(self.columns, Mapping) or not self.columns:
            raise ValueError("a Recording needs at least one column (a mapping of names to arrays)")
        columns = {str(name): _read_only(values) for name, values in self.columns.items()}
        lengths = {values.shape for values in columns.values()}
        if len(lengths) != 1 or len(next(iter(lengths))) != 1:
            raise ValueError(f"every column must be 1-D with the same length, got shapes {sorted(lengths)}")
        object.__setattr__(self, "columns", frozen_mapping(columns))
        for name in ("gap_rows", "gap_steps"):
            array = np.array(getattr(self, name), dtype=np.int64 if name == "gap_rows" else np.float64).reshape(-1)
            array.flags.writeable = False
            object.__setattr__(self, name, array)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.columns)

    @property
    def freq(self) -> float:
        """The sampling rate in Hz: :attr:`rate` under R's name."""
        return self.rate

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(next(iter(self.columns.values())).shape[0])

    @property
    def n(self) -> int:
        """Number of samples (the same as :attr:`n_samples`)."""
        return self.n_samples

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.columns[name]
        except KeyError:
            raise KeyError(f"no column {name!r}; the recording has {list(self.columns)}") from None

    def to_dataframe(self) -> pd.DataFrame:
        """The columns as a DataFrame indexed by time from the first sample (s, at ``rate``)."""
        index = pd.Index(np.arange(self.n) / self.rate, name="Time")
        return pd.DataFrame(dict(self.columns), index=index)

    def rate_note(self) -> str:
        """``'at 300 Hz from time column 'time' (jitter 0.33 ms rms)'``, and the gaps if any."""
        note = f"at {self.rate:.6g} Hz"
        note += f" from {self.rate_source}" if self.time_column is not None else f" ({self.rate_source})"
        if self.jitter is not None:
            note += f" (jitter {_duration(self.jitter)} rms)" if self.jitter >= 1e-9 else " (jitter < 1 ns rms)"
        if self.gap_rows.size:
            first = int(self.gap_rows[0])
            how = "ignored: samples treated as contiguous" if self.gaps_ignored else "found"
            note += (
                f"; {self.gap_rows.size} gap(s) {how}, the first before row {first + 1} "
                f"({_duration(float(self.gap_steps[0]))} long)"
            )
        return note

    def describe(self) -> str:
        where = f"{terminal(self.source)}: " if self.source else ""  # a path: shown, never obeyed
        return f"{where}{len(self.columns)} column(s) x {self.n} samples {self.rate_note()}"

    def __repr__(self) -> str:
        return f"<Recording {self.describe()}>"

    def __str__(self) -> str:
        return self.describe()
