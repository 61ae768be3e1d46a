"""The result of :func:`avar.noise_report`: :class:`NoiseReport`.

Holds numbers only: the Allan variance and the selected model of every
channel, the table of terms, the curves (empirical deviation, band, implied
deviation) and the warnings. ``plot()`` draws the report
figure (:mod:`avar.plotting.report`), ``to_kalibr(path)`` writes a Kalibr
``imu.yaml`` and ``export(name, path)`` each estimator's own file (:mod:`avar.fit.report.exports`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from avar._escape import html_text, terminal
from avar._frozen import frozen_mapping
from avar._vocabulary import deprecated_significance
from avar.stability.allan.results import format_frequency

__all__ = ["NoiseReport"]

#: Columns of :attr:`NoiseReport.table`.
TABLE_COLUMNS = ["Channel", "Sensor", "Term", "Process", "Status", "Value", "Lower", "Upper", "Unit",
                 "Customary", "Customary lower", "Customary upper", "Customary unit", "Tau (s)", "Group", "Note"]
NUMERIC_COLUMNS = ["Value", "Lower", "Upper", "Customary", "Customary lower", "Customary upper", "Tau (s)"]


def _number(value: Any) -> str:
    return "none" if value is pd.NA or value is None else f"{value:.4g}"


def _line(row: pd.Series, bound: str) -> str:
    """One row of the printed summary."""
    if row["Status"] == "warning":
        return f"  warning: {terminal(row['Note'])}"
    if row["Status"] == "absent":
        return f"  {row['Term']:<34} absent"
    if row["Status"] == "bound":
        text = f"  {row['Term']:<34} < {_number(row['Upper'])} {row['Unit']} ({bound}, not resolved)"
        if row["Customary unit"]:
            text += f" = < {_number(row['Customary upper'])} {row['Customary unit']}"
        return text
    text = (f"  {row['Term']:<34} {_number(row['Value'])} {row['Unit']} "
            f"[{_number(row['Lower'])}, {_number(row['Upper'])}]")
    if row["Customary unit"]:
        text += f" = {_number(row['Customary'])} {row['Customary unit']}"
    if row["Tau (s)"] is not pd.NA and row["Process"] == "MIN":
        text += f" at tau = {row['Tau (s)']:.4g} s"
    return text


@dataclass(frozen=True, eq=False)
class NoiseReport:
    """IEEE 952 noise terms of every channel of a log; build it with :func:`avar.noise_report`.

    Attributes
    ----------
    name : str
        Label (file, IMU or channel name), used in titles.
    source, topic : str or None
        Where the data came from (a file, a bag and its ROS topic).
    rate : float
        Sampling rate (Hz); ``freq`` is the same value.
    n_samples : int
        Samples per channel; ``n`` is the same value.
    channels, sensor_types, units : tuple
        Channel names, ``"Gyroscope"``/``"Accelerometer"``/None, data units.
    avs : Mapping[str, AllanVariance]
        The Allan variance of every channel.
    fits : Mapping[str, SensorFit]
        The selected model of every channel (per-sample variances in data units).
    terms : DataFrame
        The table (see :attr:`table`).
    confidence : float
        Confidence level of the intervals and of the band (0.95 by default).
    curves : DataFrame
        Per channel and level: ``Channel, Tau (s), ADEV, Lower, Upper, Implied ADEV, Fits, Unit``
        (deviations in data units; ``Fits``: the implied deviation is inside the band or within 10 %).
    warnings : tuple of str
        Every warning of the report (fit, units, data), one line each.
    """

    name: str
    source: str | None
    topic: str | None
    rate: float
    n_samples: int
    channels: tuple[str, ...]
    sensor_types: tuple[str | None, ...]
    units: tuple[str | None, ...]
    avs: Mapping[str, Any]
    fits: Mapping[str, Any]
    terms: pd.DataFrame
    confidence: float
    curves: pd.DataFrame
    warnings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        set_field(self, "warnings", tuple(self.warnings))
        set_field(self, "curves", self.curves.copy())
        for field in ("avs", "fits"):
            set_field(self, field, frozen_mapping(getattr(self, field)))
        terms = self.terms.reindex(columns=TABLE_COLUMNS).copy()
        for column in NUMERIC_COLUMNS:
            terms[column] = terms[column].astype("Float64")
        set_field(self, "terms", terms)

    @property
    def freq(self) -> float:
        """The sampling rate in Hz (:attr:`rate`)."""
        return self.rate

    @property
    def n(self) -> int:
        """Samples per channel (:attr:`n_samples`)."""
        return self.n_samples

    @property
    def alpha(self) -> float:
        """Deprecated (removed in 0.3.0): 1 - :attr:`confidence`."""
        return deprecated_significance(self.confidence)

    @property
    def table(self) -> pd.DataFrame:
        """One row per channel and term: status (``present``, ``bound``, ``absent``, ``measured`` for
        the Allan-deviation minimum, ``warning``), value, interval (a bound: 0 to its upper bound),
        unit (SI when the sensor type is known), the same in customary units, a tau (the minimum's,
        a Gauss-Markov correlation time, a sinusoid's period), the group (``IEEE 952``, or ``sensor
        filtering`` for a term of the sensor's own filtering or vibration; :func:`avar.fit.report.rows.group_of`)
        and a note. Missing values are <NA>."""
        return self.terms.copy()

    def summary(self) -> pd.DataFrame:
        """The same as :attr:`table`."""
        return self.table

    def value(self, channel: str, process: str, customary: bool = False) -> float | None:
        """One term of one channel (SI, or customary units), None when absent or only bounded.

        ``process`` is a row's ``Process``: QN, WN, FN, RW, DR, AR1_1, AR1_1.T, SIN_1, SIN_1.f, or MIN
        (the Allan-deviation minimum).

        >>> import avar
        >>> x = avar.WN(sigma2=1e-4).simulate(20_000, seed=1)
        >>> round(avar.noise_report(x, gyro_units="rad/s", rate=100.0).value("x", "WN"), 5)
        0.001
        """
        rows = self.terms[(self.terms["Channel"] == channel) & (self.terms["Process"] == process)]
        if rows.empty:
            known = sorted(set(self.terms.loc[self.terms["Channel"] == channel, "Process"]) - {"WARNING"})
            raise KeyError(f"no term {process!r} of channel {channel!r}; channels {list(self.channels)}, "
                           f"processes {known}")
        value = rows.iloc[0]["Customary" if customary else "Value"]
        return None if value is pd.NA else float(value)

    def implied_av(self, channel: str, implied: str = "sum") -> np.ndarray:
        """Implied Allan variance of the fit at the channel's levels.

        ``"sum"``: the sum of the terms' Allan variances (independent processes:
        the variances add). ``"r"``: R ``avar`` 0.1.3's curve, the square of
        the sum of the terms' deviations (DESIGN defect 6), on request only.
        """
        fit, av = self.fits[channel], self.avs[channel]
        parts = [c.av(av.averaging_factors) for c in fit.components]
        if implied == "sum":
            return sum(parts, np.zeros(len(av)))
        if implied == "r":
            return sum((np.sqrt(p) for p in parts), np.zeros(len(av))) ** 2
        raise ValueError(f"implied must be 'sum' (sum of the processes' variances) or 'r' (R's curve), got {implied!r}")

    def kalibr(self, **overrides: Any) -> dict[str, Any]:
        """The Kalibr ``imu.yaml`` fields; see :func:`avar.fit.report.exports.kalibr.kalibr_fields`."""
        from avar.fit.report.exports.kalibr import kalibr_fields

        return kalibr_fields(self, **overrides)

    def kalibr_text(self, axis: str = "max", inflate: float = 1.0, **overrides: Any) -> str:
        """The Kalibr ``imu.yaml`` text with its comments; see :func:`avar.fit.report.exports.kalibr.kalibr_text`."""
        from avar.fit.report.exports.kalibr import kalibr_text

        return kalibr_text(self, axis=axis, inflate=inflate, **overrides)

    def to_kalibr(self, path: Any, force: bool = False, **overrides: Any) -> Any:
        """Write a Kalibr ``imu.yaml``; see :func:`avar.fit.report.exports.kalibr.write_kalibr`."""
        from avar.fit.report.exports.kalibr import write_kalibr

        return write_kalibr(self, path, force=force, **overrides)

    def export(self, name: str, path: Any = None, axis: str = "max", inflate: float = 1.0, force: bool = False) -> str:
        """An estimator's IMU file (``kalibr``, ``openvins``, ``vins``, ``orbslam3``, ``basalt``, ``matlab``):
        its text, written to ``path`` when given; see :func:`avar.fit.report.exports.registry.export`."""
        from avar.fit.report.exports.registry import export

        return export(self, name, path, axis=axis, inflate=inflate, force=force)

    def plot(self, **kwargs: Any):
        """Allan deviation of every channel with the fitted terms; see :func:`avar.plotting.report.plot_report`."""
        from avar.plotting import plot_report

        return plot_report(self, **kwargs)

    def describe(self) -> str:
        where = f" ({terminal(self.topic)})" if self.topic else ""  # names from data: shown, never obeyed
        return (f"Noise report of {terminal(self.name)}{where}: {len(self.channels)} channel(s), N = {self.n_samples}, "
                f"freq = {format_frequency(self.rate)}, {100 * self.confidence:g}% chi-squared intervals")

    def __str__(self) -> str:
        from avar.fit.report.rows import SENSOR_FILTERING, bound_words

        lines = [self.describe()]
        for channel, kind in zip(self.channels, self.sensor_types):
            lines.append(f"\n{terminal(channel)}" + (f" ({kind.lower()})" if kind else ""))
            rows = self.terms[self.terms["Channel"] == channel]
            filtering = rows["Group"] == SENSOR_FILTERING
            warned = rows["Status"] == "warning"
            for group, part in ((None, rows[~filtering & ~warned]), (SENSOR_FILTERING, rows[filtering]),
                                (None, rows[warned])):
                if group is not None and len(part):
                    lines.append(f"  {group} (the sensor's own filtering or vibration, apart from IEEE 952 terms):")
                indent = "  " if group is not None else ""
                lines += [indent + _line(row, bound_words(self.confidence)) for _, row in part.iterrows()]
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"<NoiseReport {self.describe()}>"

    def _repr_html_(self) -> str:
        return f"<p>{html_text(self.describe())}</p>" + self.table.to_html(index=False)  # to_html escapes
