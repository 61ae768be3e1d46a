"""The result of :func:`avar.noise_report`: :class:`NoiseReport`.

Holds numbers only: the Allan variance, the joint term fit and the automatic
scales of every channel, and the table of terms. ``plot()`` draws the report
figure (:mod:`avar.plotting.report`), ``to_kalibr(path)`` writes a Kalibr
``imu.yaml`` (:mod:`avar.fit.kalibr`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from avar._frozen import frozen_mapping
from avar.stability.results import format_frequency

__all__ = ["NoiseReport"]

#: Columns of :attr:`NoiseReport.table`.
TABLE_COLUMNS = ["Channel", "Sensor", "Term", "Process", "Status", "Value", "Lower", "Upper", "Unit",
                 "Customary", "Customary lower", "Customary upper", "Customary unit", "Tau (s)", "Scales"]
NUMERIC_COLUMNS = ["Value", "Lower", "Upper", "Customary", "Customary lower", "Customary upper", "Tau (s)"]


def _number(value: Any) -> str:
    return "absent" if value is pd.NA or value is None else f"{value:.4g}"


@dataclass(frozen=True, eq=False)
class NoiseReport:
    """IEEE 952 noise terms of every channel of a log; build it with :func:`avar.noise_report`.

    Attributes
    ----------
    name : str
        Label (file, IMU or channel name), used in titles.
    source, topic : str or None
        Where the data came from (a file, a bag and its ROS topic).
    freq : float
        Sampling rate (Hz).
    n : int
        Samples per channel.
    channels, sensor_types, units : tuple
        Channel names, ``"Gyroscope"``/``"Accelerometer"``/None, data units.
    avs : Mapping[str, AllanVariance]
        The Allan variance of every channel.
    fits : Mapping[str, TermFit]
        The joint term fit of every channel (squared coefficients in data units).
    scales : Mapping[str, AutoScales]
        The scales where each term dominates, per channel.
    alpha : float
        1 - confidence level of the intervals.
    """

    name: str
    source: str | None
    topic: str | None
    freq: float
    n: int
    channels: tuple[str, ...]
    sensor_types: tuple[str | None, ...]
    units: tuple[str | None, ...]
    avs: Mapping[str, Any]
    fits: Mapping[str, Any]
    scales: Mapping[str, Any]
    terms: pd.DataFrame
    alpha: float

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        for field in ("avs", "fits", "scales"):
            set_field(self, field, frozen_mapping(getattr(self, field)))
        terms = self.terms.reindex(columns=TABLE_COLUMNS).copy()
        for column in NUMERIC_COLUMNS:
            terms[column] = terms[column].astype("Float64")
        set_field(self, "terms", terms)

    @property
    def table(self) -> pd.DataFrame:
        """One row per channel and term: status, value, chi-squared interval, unit (SI when the
        sensor type is known), the same in customary units, the tau where the bias instability
        is read and the scales where the term dominates. Absent terms hold <NA>, never NaN."""
        return self.terms.copy()

    def summary(self) -> pd.DataFrame:
        """The same as :attr:`table`."""
        return self.table

    def value(self, channel: str, process: str, customary: bool = False) -> float | None:
        """One term of one channel (SI, or customary units), None when absent.

        >>> import avar
        >>> x = avar.WN(sigma2=1e-4).simulate(20_000, seed=1)
        >>> round(avar.noise_report(x, gyro_units="rad/s", freq=100.0).value("x", "WN"), 5)
        0.001
        """
        rows = self.terms[(self.terms["Channel"] == channel) & (self.terms["Process"] == process)]
        if rows.empty:
            raise KeyError(f"no term {process!r} of channel {channel!r}; channels {list(self.channels)}, "
                           "processes QN, WN, FN, RW, DR")
        value = rows.iloc[0]["Customary" if customary else "Value"]
        return None if value is pd.NA else float(value)

    def implied_av(self, channel: str, implied: str = "sum") -> np.ndarray:
        """Implied Allan variance of the fit at the channel's levels.

        ``"sum"``: the sum of the terms' Allan variances (independent processes:
        the variances add). ``"r"``: R ``avar`` 0.1.3's curve, the square of
        the sum of the terms' deviations (DESIGN defect 6), on request only.
        """
        fit, av = self.fits[channel], self.avs[channel]
        parts = fit.component_av(av.levels)
        if implied == "sum":
            return sum(parts.values(), np.zeros(len(av)))
        if implied == "r":
            return sum((np.sqrt(p) for p in parts.values()), np.zeros(len(av))) ** 2
        raise ValueError(f"implied must be 'sum' (sum of the processes' variances) or 'r' (R's curve), got {implied!r}")

    def kalibr(self, **overrides: Any) -> dict[str, Any]:
        """The Kalibr ``imu.yaml`` fields; see :func:`avar.fit.kalibr.kalibr_fields`."""
        from avar.fit.kalibr import kalibr_fields

        return kalibr_fields(self, **overrides)

    def to_kalibr(self, path: Any, force: bool = False, **overrides: Any) -> Any:
        """Write a Kalibr ``imu.yaml``; see :func:`avar.fit.kalibr.write_kalibr`."""
        from avar.fit.kalibr import write_kalibr

        return write_kalibr(self, path, force=force, **overrides)

    def plot(self, **kwargs: Any):
        """Allan deviation of every channel with the fitted terms; see :func:`avar.plotting.report.plot_report`."""
        from avar.plotting import plot_report

        return plot_report(self, **kwargs)

    def describe(self) -> str:
        where = f" ({self.topic})" if self.topic else ""
        return (f"Noise report of {self.name}{where}: {len(self.channels)} channel(s), N = {self.n}, "
                f"freq = {format_frequency(self.freq)}, {100 * (1 - self.alpha):g}% chi-squared intervals")

    def __str__(self) -> str:
        lines = [self.describe()]
        for channel, kind in zip(self.channels, self.sensor_types):
            lines.append(f"\n{channel}" + (f" ({kind.lower()})" if kind else ""))
            rows = self.terms[self.terms["Channel"] == channel]
            for _, row in rows.iterrows():
                if row["Status"] == "absent":
                    lines.append(f"  {row['Term']:<26} absent")
                    continue
                text = (f"  {row['Term']:<26} {_number(row['Value'])} {row['Unit']} "
                        f"[{_number(row['Lower'])}, {_number(row['Upper'])}]")
                if row["Customary unit"]:
                    text += f" = {_number(row['Customary'])} {row['Customary unit']}"
                if row["Tau (s)"] is not pd.NA:
                    text += f" at tau = {row['Tau (s)']:.4g} s"
                lines.append(text + f"  (scales {row['Scales']})")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"<NoiseReport {self.describe()}>"

    def _repr_html_(self) -> str:
        return f"<p>{self.describe()}</p>" + self.table.to_html(index=False)
