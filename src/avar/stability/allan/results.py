"""Result objects of the empirical Allan variance.

Result objects hold numbers; they never compute estimates. ``AllanVariance``
is one series' Allan variance, ``ImuAllanVariance`` the Allan variances of
the channels of an inertial measurement unit.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pandas loads with the first table
    import pandas as pd

from avar._escape import html_text, terminal
from avar._frozen import frozen_array
from avar._validation import check_freq, short_repr
from avar.stability.shared.confidence import format_confidence

TYPE_NAMES = {"mo": "maximal overlap", "to": "tau overlap"}
SUMMARY_COLUMNS = ["Time", "AVar", "ADev", "Lower CI", "Upper CI"]


def format_frequency(freq: float) -> str:
    """``250`` -> ``"250 Hz"``, ``0.5`` -> ``"0.5 Hz"``."""
    return f"{freq:g} Hz"


@dataclass(frozen=True, eq=False)
class AllanVariance:
    """The empirical Allan variance of one series, level by level.

    Build it with :func:`avar.avar`; the fields are read-only.

    Attributes
    ----------
    taus : ndarray
        (property) Averaging times tau = m / freq, in seconds (the unit of ``1 / freq``).
    levels : ndarray
        The same averaging times under R's name.
    averaging_factors : ndarray of int64
        Cluster sizes m (samples per average).
    allan : ndarray
        Allan variance at every level, in squared data units.
    errors : ndarray
        Relative standard error of the Allan deviation used by the R package
        ``avar``: 1 / sqrt(2 (N / m - 1)).
    n_differences : ndarray of int64
        How many squared differences of cluster means each level averaged.
    type : {"mo", "to"}
        Maximal overlap or tau overlap estimator.
    freq : float
        Sampling frequency in Hz (samples per unit of time).
    n_samples : int
        (property) Length of the series.
    n : int
        The same length under R's name.
    name : str or None
        Optional label (the channel name for IMU data).
    ci : {"r", "chi2"}
        Which confidence band ``lci``/``uci`` are: the R package's, or the
        chi-squared band of Greenhall's EDF (``avar.avar(..., ci="chi2")``).
    confidence : float or None
        Confidence level of the chi-squared band (None for ``ci="r"``).
    alpha : ndarray of int64 or None
        Identified power-law noise exponent per level (``ci="chi2"``).
    edf : ndarray or None
        Equivalent degrees of freedom per level (``ci="chi2"``).
    chi2_lci, chi2_uci : ndarray or None
        The chi-squared bounds of the Allan deviation (``ci="chi2"``).

    Notes
    -----
    ``adev`` = sqrt(allan). With ``ci="r"``, ``lci`` and ``uci`` derive from
    ``allan`` and ``errors`` as in the R package: adev (1 -/+ 2 errors); with
    ``ci="chi2"`` they are ``chi2_lci`` and ``chi2_uci``, positive at every level.
    """

    levels: np.ndarray
    averaging_factors: np.ndarray
    allan: np.ndarray
    errors: np.ndarray
    n_differences: np.ndarray
    type: str
    freq: float
    n: int
    name: str | None = None
    ci: str = "r"
    confidence: float | None = None
    alpha: np.ndarray | None = None
    edf: np.ndarray | None = None
    chi2_lci: np.ndarray | None = None
    chi2_uci: np.ndarray | None = None

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        for name in ("levels", "allan", "errors"):
            set_field(self, name, frozen_array(getattr(self, name)))
        for name in ("averaging_factors", "n_differences"):
            set_field(self, name, frozen_array(getattr(self, name), np.int64))
        sizes = {len(getattr(self, name)) for name in ("levels", "averaging_factors", "allan", "errors", "n_differences")}
        if len(sizes) != 1:
            raise ValueError("levels, averaging_factors, allan, errors and n_differences must have one length")
        if self.type not in TYPE_NAMES:
            raise ValueError(f"type must be one of {sorted(TYPE_NAMES)} ('mo' maximal overlap, 'to' tau overlap), "
                             f"got {short_repr(self.type)}")
        for name in ("allan", "errors"):
            values = getattr(self, name)
            if values.size and not (values.min() >= 0 and values.max() < np.inf):  # a nan makes min() nan
                bad = np.flatnonzero(~(values >= 0) | ~np.isfinite(values))
                raise ValueError(f"{name} must hold finite values >= 0 (a variance and its relative error), "
                                 f"got {values[bad[0]]!r} at level {bad[0]}")
        set_field(self, "freq", check_freq(self.freq))
        set_field(self, "n", int(self.n))
        self._check_band()

    def _check_band(self) -> None:
        """The chi-squared fields: all given, one per level, positive, with ci="chi2"; else none."""
        names = ("alpha", "edf", "chi2_lci", "chi2_uci")
        if self.ci == "r":
            if self.confidence is not None or any(getattr(self, name) is not None for name in names):
                raise ValueError("confidence, alpha, edf, chi2_lci and chi2_uci belong to ci='chi2' results")
            return
        if self.ci != "chi2":
            raise ValueError(f"ci must be 'r' (R's band) or 'chi2' (chi-squared band), got {short_repr(self.ci)}")
        if not isinstance(self.confidence, (float, int)) or not 0 < self.confidence < 1:
            raise ValueError(f"confidence must be in (0, 1) for ci='chi2', got {short_repr(self.confidence)}")
        for name in names:
            if getattr(self, name) is None:
                raise ValueError(f"a ci='chi2' result needs {name}")
            object.__setattr__(self, name, frozen_array(getattr(self, name), np.int64 if name == "alpha" else np.float64))
            if len(getattr(self, name)) != len(self.levels):
                raise ValueError(f"{name} must have one value per level")
        if not (np.all(self.edf > 0) and np.all(self.chi2_lci >= 0) and np.all(self.chi2_uci >= self.chi2_lci)):
            raise ValueError("edf must be > 0 and 0 <= chi2_lci <= chi2_uci at every level")

    @property
    def taus(self) -> np.ndarray:
        """Averaging times tau (s) of the levels (R's name: ``levels``)."""
        return self.levels

    @property
    def n_samples(self) -> int:
        """Length of the series (R's name: ``n``)."""
        return self.n

    @property
    def adev(self) -> np.ndarray:
        """Allan deviation sqrt(allan), in data units."""
        return np.sqrt(self.allan)

    @property
    def lci(self) -> np.ndarray:
        """Lower confidence bound of the Allan deviation: adev (1 - 2 errors), or ``chi2_lci``."""
        return self.chi2_lci if self.ci == "chi2" else self.adev * (1.0 - 2.0 * self.errors)

    @property
    def uci(self) -> np.ndarray:
        """Upper confidence bound of the Allan deviation: adev (1 + 2 errors), or ``chi2_uci``."""
        return self.chi2_uci if self.ci == "chi2" else self.adev * (1.0 + 2.0 * self.errors)

    def __len__(self) -> int:
        return len(self.levels)

    def summary(self) -> pd.DataFrame:
        """The table of R's ``summary.avar``: one row per level.

        Columns ``Time`` (tau, s), ``AVar``, ``ADev``, ``Lower CI``, ``Upper CI``;
        the index ``Scale`` numbers the levels from 1, as the scale selections
        of :func:`avar.avlr` do. The CI columns bound the Allan *deviation*
        (R's adev (1 -/+ 2 errors)); the lower one is negative where
        errors > 1/2, i.e. at scales m > N/3. A ``ci="chi2"`` result has the
        chi-squared bounds there instead, and two more columns: ``Alpha``
        (identified noise) and ``EDF``.
        """
        import pandas as pd

        columns = {"Time": self.levels, "AVar": self.allan, "ADev": self.adev,
                   "Lower CI": self.lci, "Upper CI": self.uci}
        if self.ci == "chi2":
            columns.update({"Alpha": self.alpha, "EDF": self.edf})
        return pd.DataFrame(columns, columns=list(columns), index=pd.RangeIndex(1, len(self) + 1, name="Scale"))

    def describe(self) -> str:
        """One line: estimator, length, rate and number of levels."""
        label = f"{terminal(self.name)}: " if self.name else ""  # a name from data: shown, never obeyed
        return (
            f"{label}Allan variance ({TYPE_NAMES.get(self.type, self.type)}, type {self.type!r}), "
            f"N = {self.n}, freq = {format_frequency(self.freq)}, {len(self)} levels"
            + (f", chi-squared {format_confidence(self.confidence)} band" if self.ci == "chi2" else "")
        )

    def __str__(self) -> str:
        import pandas as pd

        table = pd.DataFrame(
            {"Time": self.levels, "m": self.averaging_factors, "AVar": self.allan, "ADev": self.adev}
        )
        return self.describe() + "\n" + table.to_string(index=False, float_format=lambda v: f"{v:.6g}")

    def __repr__(self) -> str:
        return f"<AllanVariance {self.describe()}>"

    def _repr_html_(self) -> str:
        return f"<p>{html_text(self.describe())}</p>" + self.summary().to_html(index=False)

    def plot(self, **kwargs: Any):
        """Log-log plot of the Allan variance; see :func:`avar.plotting.plot_avar`."""
        from avar.plotting import plot_avar

        return plot_avar(self, **kwargs)


@dataclass(frozen=True, eq=False)
class ImuAllanVariance:
    """Allan variances of every channel of an inertial measurement unit.

    Attributes
    ----------
    sensor : str
        Sensor name.
    freq : float
        Sampling frequency in Hz.
    n : int
        Samples per channel (also ``n_samples``).
    taus : ndarray
        (property) Averaging times tau (s) of the levels, shared by the channels.
    channels : Mapping[str, AllanVariance]
        One Allan variance per channel, in channel order.
    sensor_types : tuple of str
        ``"Gyroscope"`` or ``"Accelerometer"`` for every channel.
    axes : tuple of str
        Axis label of every channel (``"X"``, ``"Y"``, ``"Z"``, ...).
    """

    sensor: str
    freq: float
    n: int
    channels: Mapping[str, AllanVariance]
    sensor_types: tuple[str, ...]
    axes: tuple[str, ...]
    units: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        set_field(self, "channels", MappingProxyType(dict(self.channels)))
        set_field(self, "sensor_types", tuple(self.sensor_types))
        set_field(self, "axes", tuple(self.axes))
        set_field(self, "units", MappingProxyType(dict(self.units)))
        set_field(self, "freq", float(self.freq))
        set_field(self, "n", int(self.n))
        if not len(self.channels) == len(self.sensor_types) == len(self.axes):
            raise ValueError("channels, sensor_types and axes must have one entry per channel")

    @property
    def taus(self) -> np.ndarray:
        """Averaging times tau (s) of the levels: the channels' common grid (the longest channel's when
        their lengths differ; each channel's own is ``channels[name].taus``)."""
        return max((av.levels for av in self.channels.values()), key=len, default=np.zeros(0))

    @property
    def n_samples(self) -> int:
        """Samples per channel (R's name: ``n``)."""
        return self.n

    @property
    def type(self) -> str:
        """Estimator type shared by the channels ("mo" or "to")."""
        types = {av.type for av in self.channels.values()}
        return types.pop() if len(types) == 1 else "mixed"

    def channels_of(self, sensor_type: str) -> dict[str, AllanVariance]:
        """The channels of one sensor type, in order."""
        return {
            name: av
            for (name, av), kind in zip(self.channels.items(), self.sensor_types)
            if kind == sensor_type
        }

    @property
    def present_types(self) -> tuple[str, ...]:
        """Sensor types present, in order of first appearance."""
        return tuple(dict.fromkeys(self.sensor_types))

    def __getitem__(self, channel: str) -> AllanVariance:
        return self.channels[channel]

    def __len__(self) -> int:
        return len(self.channels)

    def summary(self) -> pd.DataFrame:
        """All channels' summary tables stacked, indexed by (channel, 1-based scale)."""
        import pandas as pd

        frames = {name: av.summary() for name, av in self.channels.items()}
        return pd.concat(frames, names=["Channel", "Scale"])

    def describe(self) -> str:
        return (
            f"{terminal(self.sensor)} @ {format_frequency(self.freq)}, N = {self.n}, "
            f"{len(self)} channels ({', '.join(map(terminal, self.channels))})"
        )

    def __str__(self) -> str:
        lines = [f"IMU Allan variance: {self.describe()}"]
        for (name, av), kind, axis in zip(self.channels.items(), self.sensor_types, self.axes):
            lines.append(f"  {terminal(name):<10} {kind:<14} axis {terminal(axis)}: {len(av)} levels, tau {av.levels[0]:g} .. {av.levels[-1]:g} s")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"<ImuAllanVariance {self.describe()}>"

    def _repr_html_(self) -> str:
        return f"<p>IMU Allan variance: {html_text(self.describe())}</p>" + self.summary().to_html()

    def plot(self, **kwargs: Any):
        """Grid of log-log Allan deviation plots; see :func:`avar.plotting.plot_imu_avar`."""
        from avar.plotting import plot_imu_avar

        return plot_imu_avar(self, **kwargs)
