"""Result objects of AVLR fits: :class:`AvlrResult` (one series) and
:class:`ImuAvlrResult` (one model per IMU sensor type, or per axis).

Result objects hold numbers; they never compute estimates.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from avar._escape import html_text
from avar._frozen import frozen_array, frozen_frame, frozen_mapping, frozen_series
from avar._vocabulary import deprecated_significance
from avar.fit.slopes import format_scales, parameter_label
from avar.imu import ACCELEROMETER, GYROSCOPE
from avar.models import NoiseModel
from avar.stability.allan.results import AllanVariance, ImuAllanVariance, format_frequency

__all__ = ["AvlrResult", "ImuAvlrResult"]

@dataclass(frozen=True, eq=False)
class AvlrResult:
    """An AVLR fit: estimates, implied Allan deviations and fitted model.

    Build it with :func:`avlr`; the fields are read-only.

    Attributes
    ----------
    estimates : pandas.Series
        WN sigma, QN Q, RW gamma, DR omega of the fitted processes (index in
        that order), in tau units (see :mod:`avar.fit.slopes`).
    scales_used : Mapping[str, ndarray]
        1-based scale numbers each process was fitted on.
    av : AllanVariance
        The Allan variance that was fitted.
    implied_ad : ndarray
        Sum of the processes' implied Allan deviations at every level (as R;
        its square is R's implied AV, DESIGN defect 6).
    implied_av : ndarray
        (property) The implied Allan variance of the model: the sum of the
        processes' variances, what the plots draw by default.
    implied_ad_decomp : Mapping[str, ndarray]
        Implied Allan deviation of every process at every level.
    model : NoiseModel
        The fitted model in per-sample parameters at the data's rate ``av.freq`` (see
        :func:`per_sample_model`), ready to ``simulate``.
    ci : pandas.DataFrame or None
        With ``avlr(..., ci=True)``: index = process, columns ``Estimate``
        (bias-corrected 2 theta - mean(theta*)), ``SD``, ``Lower``, ``Upper``.
    confidence, replicates : float or None, int or None
        Confidence level and number of bootstrap replicates of ``ci``.
    taus : ndarray
        (property) Averaging times tau (s) of the levels of ``av``.
    """

    estimates: pd.Series
    scales_used: Mapping[str, np.ndarray]
    av: AllanVariance
    implied_ad: np.ndarray
    implied_ad_decomp: Mapping[str, np.ndarray]
    model: NoiseModel
    ci: pd.DataFrame | None = None
    confidence: float | None = None
    replicates: int | None = None

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        set_field(self, "estimates", frozen_series(self.estimates))
        set_field(self, "implied_ad", frozen_array(self.implied_ad))
        for name in ("scales_used", "implied_ad_decomp"):
            dtype = np.int64 if name == "scales_used" else np.float64
            set_field(self, name, frozen_mapping({k: frozen_array(v, dtype) for k, v in getattr(self, name).items()}))
        if self.ci is not None:
            set_field(self, "ci", frozen_frame(self.ci))

    @property
    def implied_av(self) -> np.ndarray:
        """Sum of the processes' implied Allan variances at every level (independent processes add)."""
        return np.sum([d**2 for d in self.implied_ad_decomp.values()], axis=0)

    @property
    def taus(self) -> np.ndarray:
        """Averaging times tau (s) of the fitted Allan variance's levels."""
        return self.av.taus

    @property
    def alpha(self) -> float | None:
        """Deprecated (removed in 0.3.0): 1 - :attr:`confidence`."""
        return deprecated_significance(self.confidence)

    def summary(self) -> pd.DataFrame:
        """The estimate table, one row per process.

        Columns ``Parameter`` (symbol and unit), ``Value`` (the fit) and,
        when bootstrap intervals were computed, ``Bias-corrected``, ``SD``,
        ``Lower``, ``Upper``.
        """
        table = pd.DataFrame({"Parameter": [parameter_label(p) for p in self.estimates.index], "Value": self.estimates})
        if self.ci is not None:
            table = table.join(self.ci.rename(columns={"Estimate": "Bias-corrected"}))
        table.index.name = "Process"
        return table

    def describe(self) -> str:
        """Fitted processes and their scales, one line."""
        parts = [
            f"{p} on scales {format_scales(s)} (tau {self.av.levels[s[0] - 1]:g} .. {self.av.levels[s[-1] - 1]:g} s)"
            for p, s in self.scales_used.items()
        ]
        return "AVLR fit: " + "; ".join(parts)

    def __str__(self) -> str:
        table = self.summary()
        lines = [self.describe(), "of the " + self.av.describe()]
        if self.ci is not None:
            lines.append(
                f"Bootstrap (B = {self.replicates}): bias-corrected estimates, SD and "
                f"{100 * self.confidence:g}% normal intervals"
            )
        lines.append(table.to_string(float_format=lambda v: f"{v:.6g}"))
        lines.append(f"Per-sample model at {format_frequency(self.av.freq)}: {self.model!r}")
        return "\n".join(lines)

    def __repr__(self) -> str:
        values = ", ".join(f"{p}={v:.6g}" for p, v in self.estimates.items())
        return f"<AvlrResult {values}{' with CI' if self.ci is not None else ''}>"

    def _repr_html_(self) -> str:
        return f"<p>{html_text(self.describe())}<br>{html_text(self.av.describe())}</p>" + self.summary().to_html()

    def plot(self, **kwargs: Any):
        """Empirical and implied Allan deviation; see :func:`avar.plotting.plot_avlr`."""
        from avar.plotting import plot_avlr

        return plot_avlr(self, **kwargs)


#: Argument suffix of each sensor type (``wn_gyro``, ``wn_acc``).
SUFFIXES = {GYROSCOPE: "_gyro", ACCELEROMETER: "_acc"}
#: Heading of each sensor type's table (R ``print.imu_avlr``).
HEADINGS = {GYROSCOPE: "Estimates for gyroscopes:", ACCELEROMETER: "Estimates for accelerometers:"}


@dataclass(frozen=True, eq=False)
class ImuAvlrResult:
    """AVLR fits of an IMU: one model per sensor type (or per axis).

    Build it with ``avar.avlr(imu_av, wn_gyro=...)``.

    Attributes
    ----------
    imu_av : ImuAllanVariance
        The Allan variances that were fitted.
    per_axis : bool
        False: one model per sensor type, pooled over its axes (R's fit).
        True: one model per channel.
    estimates : Mapping[str, pandas.Series or pandas.DataFrame]
        Per sensor type present. Joint fit: a Series indexed by process
        (order WN, QN, RW, DR). Per axis: a DataFrame, one row per axis
        (index = axis label), one column per process. Parameters are in tau
        units (WN sigma, QN Q, RW gamma, DR omega; see :mod:`avar.fit.slopes`).
    scales_used : Mapping[str, Mapping[str, ndarray]]
        Per sensor type, the 1-based scales each process was fitted on.
    models : Mapping[str, NoiseModel]
        Per channel, the fitted per-sample model at the IMU's rate (all
        channels of a sensor type share one model in the joint fit).
    implied_ad : Mapping[str, ndarray]
        Per channel, the sum of the processes' implied Allan deviations at
        the channel's levels (as R draws it).
    implied_av : Mapping[str, ndarray]
        (property) Per channel, the sum of the processes' implied Allan
        variances, what the plots draw by default.
    implied_ad_decomp : Mapping[str, Mapping[str, ndarray]]
        Per channel, the implied Allan deviation of every process.
    ci : Mapping[str, pandas.DataFrame] or None
        With ``ci=True``: per sensor type, the bootstrap table (columns
        ``Estimate`` (bias-corrected), ``SD``, ``Lower``, ``Upper``; index
        process, or (axis, process) per axis).
    confidence, replicates : float or None, int or None
        Confidence level and number of bootstrap replicates of ``ci``.
    taus : ndarray
        (property) Averaging times tau (s) of the IMU's levels (``imu_av.taus``).

    Examples
    --------
    >>> import avar
    >>> from avar.io import datasets
    >>> fit = avar.avlr(datasets.load("navchip_av"), wn_gyro=range(1, 8), wn_acc=range(1, 8))
    >>> table = fit.summary()
    >>> list(table.columns)
    ['Parameter', 'Value', 'Scales']
    >>> table["Value"].round(7).tolist()  # sigma of the gyroscopes, of the accelerometers
    [6.96e-05, 0.0005295]
    """

    imu_av: ImuAllanVariance
    per_axis: bool
    estimates: Mapping[str, pd.Series | pd.DataFrame]
    scales_used: Mapping[str, Mapping[str, np.ndarray]]
    models: Mapping[str, NoiseModel]
    implied_ad: Mapping[str, np.ndarray]
    implied_ad_decomp: Mapping[str, Mapping[str, np.ndarray]]
    ci: Mapping[str, pd.DataFrame] | None = None
    confidence: float | None = None
    replicates: int | None = None

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        if self.ci is not None:
            set_field(self, "ci", frozen_mapping({k: frozen_frame(v) for k, v in self.ci.items()}))
        frozen = {k: frozen_frame(v) if isinstance(v, pd.DataFrame) else frozen_series(v) for k, v in self.estimates.items()}
        set_field(self, "estimates", frozen_mapping(frozen))
        set_field(
            self,
            "scales_used",
            frozen_mapping({k: frozen_mapping({p: frozen_array(s, np.int64) for p, s in v.items()})
                             for k, v in self.scales_used.items()}),
        )
        set_field(self, "models", frozen_mapping(self.models))
        set_field(self, "implied_ad", frozen_mapping({k: frozen_array(v) for k, v in self.implied_ad.items()}))
        set_field(
            self,
            "implied_ad_decomp",
            frozen_mapping({k: frozen_mapping({p: frozen_array(a) for p, a in v.items()})
                             for k, v in self.implied_ad_decomp.items()}),
        )

    @property
    def implied_av(self) -> Mapping[str, np.ndarray]:
        """Per channel, the sum of the processes' implied Allan variances."""
        return frozen_mapping({name: np.sum([d**2 for d in parts.values()], axis=0)
                               for name, parts in self.implied_ad_decomp.items()})

    @property
    def sensor_types(self) -> tuple[str, ...]:
        """The sensor types fitted, in order of appearance."""
        return tuple(self.estimates)

    @property
    def taus(self) -> np.ndarray:
        """Averaging times tau (s) of the IMU's levels (see :attr:`avar.ImuAllanVariance.taus`)."""
        return self.imu_av.taus

    @property
    def alpha(self) -> float | None:
        """Deprecated (removed in 0.3.0): 1 - :attr:`confidence`."""
        return deprecated_significance(self.confidence)

    def summary(self) -> pd.DataFrame:
        """All estimates in one table indexed by (sensor type, process).

        Columns: ``Parameter`` (symbol and unit, with the sensor type's unit
        when the IMU has one), ``Value`` (joint fit) or one column per axis
        (per-axis fit), then ``Scales``, the 1-based scales of the process.
        """
        frames = {}
        for kind, estimates in self.estimates.items():
            table = pd.DataFrame({"Value": estimates}) if not self.per_axis else estimates.T.copy()
            table.columns = [str(c) for c in table.columns]
            unit = self.imu_av.units.get(kind)
            table.insert(0, "Parameter", [parameter_label(p, unit) for p in table.index])
            table["Scales"] = [format_scales(self.scales_used[kind][p]) for p in table.index]
            frames[kind] = table
        return pd.concat(frames, names=["Sensor type", "Process"])

    def describe(self) -> str:
        mode = "one model per axis" if self.per_axis else "one model per sensor type, pooled over its axes"
        return f"IMU AVLR fit ({mode}) of {self.imu_av.describe()}"

    def __str__(self) -> str:
        lines = [self.describe()]
        for kind, estimates in self.estimates.items():
            if self.per_axis:
                table = estimates.copy()
                table.index.name = "Axis"
            else:
                table = self.summary().loc[kind]
            heading = HEADINGS.get(kind, f"Estimates for {kind}:")
            lines += ["", f" {heading}", table.to_string(float_format=lambda v: f"{v:.6g}")]
            if self.ci is not None:
                lines += [f" Bootstrap (B = {self.replicates}): bias-corrected estimates, SD and "
                          f"{100 * self.confidence:g}% normal intervals",
                          self.ci[kind].to_string(float_format=lambda v: f"{v:.6g}")]
        return "\n".join(lines)

    def __repr__(self) -> str:
        parts = []
        for kind, estimates in self.estimates.items():
            if self.per_axis:
                parts.append(f"{kind}: {', '.join(estimates.columns)} x {len(estimates)} axes")
            else:
                parts.append(f"{kind}: " + ", ".join(f"{p}={v:.6g}" for p, v in estimates.items()))
        return f"<ImuAvlrResult {self.imu_av.sensor}; {'; '.join(parts)}>"

    def _repr_html_(self) -> str:
        return f"<p>{html_text(self.describe())}</p>" + self.summary().to_html()

    def plot(self, **kwargs: Any):
        """Grid of empirical and implied Allan variances; see :func:`avar.plotting.plot_imu_avlr`."""
        from avar.plotting import plot_imu_avlr

        return plot_imu_avlr(self, **kwargs)
