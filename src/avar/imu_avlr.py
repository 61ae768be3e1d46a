"""Allan variance linear regression of IMU data: :func:`imu_avlr`.

One latent model per sensor type (gyroscopes, accelerometers), fitted
jointly over the axes of that type as R ``avar`` 0.1.3 does in
``avlr.imu_avar``: every process's scale selection is applied to each axis
and the fixed-slope log-log regression of :func:`avar.avlr.fit_slopes` pools
all the selected (axis, scale) pairs::

    theta = exp(mean over axes k and selected scales j of (log AD_k(tau_j) - b log tau_j)) / c

(slope b and coefficient c of each process in :mod:`avar.avlr`). With
``per_axis=True`` every axis gets its own fit instead, identical to
:func:`avar.avlr` on that channel.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np
import pandas as pd

from avar.avlr import (
    PROCESSES,
    check_scale_selections,
    fit_slopes,
    format_scales,
    implied_allan_deviation,
    parameter_label,
    per_sample_model,
)
from avar.models import NoiseModel
from avar.results import AllanVariance, ImuAllanVariance, frozen_array, frozen_frame, frozen_series

__all__ = ["ImuAvlrResult", "imu_avlr"]

GYROSCOPE = "Gyroscope"
ACCELEROMETER = "Accelerometer"
#: Argument suffix of each sensor type (``wn_gyro``, ``wn_acc``).
SUFFIXES = {GYROSCOPE: "_gyro", ACCELEROMETER: "_acc"}
#: Heading of each sensor type's table (R ``print.imu_avlr``).
HEADINGS = {GYROSCOPE: "Estimates for gyroscopes:", ACCELEROMETER: "Estimates for accelerometers:"}


def _frozen_mapping(values: Mapping[str, Any]) -> Mapping[str, Any]:
    return MappingProxyType(dict(values))


@dataclass(frozen=True, eq=False)
class ImuAvlrResult:
    """AVLR fits of an IMU: one model per sensor type (or per axis).

    Build it with :func:`imu_avlr` (or ``avar.avlr(imu_av, wn_gyro=...)``).

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
        units (WN sigma, QN Q, RW gamma, DR omega; see :mod:`avar.avlr`).
    scales_used : Mapping[str, Mapping[str, ndarray]]
        Per sensor type, the 1-based scales each process was fitted on.
    models : Mapping[str, NoiseModel]
        Per channel, the fitted per-sample model at the IMU's rate (all
        channels of a sensor type share one model in the joint fit).
    implied_ad : Mapping[str, ndarray]
        Per channel, the sum of the processes' implied Allan deviations at
        the channel's levels (as R draws it).
    implied_ad_decomp : Mapping[str, Mapping[str, ndarray]]
        Per channel, the implied Allan deviation of every process.

    Examples
    --------
    >>> from avar import datasets
    >>> fit = imu_avlr(datasets.load("navchip_av"), wn_gyro=range(1, 8), wn_acc=range(1, 8))
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

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        frozen = {k: frozen_frame(v) if isinstance(v, pd.DataFrame) else frozen_series(v) for k, v in self.estimates.items()}
        set_field(self, "estimates", _frozen_mapping(frozen))
        set_field(
            self,
            "scales_used",
            _frozen_mapping({k: _frozen_mapping({p: frozen_array(s, np.int64) for p, s in v.items()})
                             for k, v in self.scales_used.items()}),
        )
        set_field(self, "models", _frozen_mapping(self.models))
        set_field(self, "implied_ad", _frozen_mapping({k: frozen_array(v) for k, v in self.implied_ad.items()}))
        set_field(
            self,
            "implied_ad_decomp",
            _frozen_mapping({k: _frozen_mapping({p: frozen_array(a) for p, a in v.items()})
                             for k, v in self.implied_ad_decomp.items()}),
        )

    @property
    def sensor_types(self) -> tuple[str, ...]:
        """The sensor types fitted, in order of appearance."""
        return tuple(self.estimates)

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
        return f"<p>{self.describe()}</p>" + self.summary().to_html()

    def plot(self, **kwargs: Any):
        """Grid of empirical and implied Allan variances; see :func:`avar.plotting.plot_imu_avlr`."""
        from avar.plotting import plot_imu_avlr

        return plot_imu_avlr(self, **kwargs)


def _check_input(imu_av: Any) -> ImuAllanVariance:
    from avar.imu import IMU

    if isinstance(imu_av, IMU):
        from avar.estimate import avar

        imu_av = avar(imu_av)
    if not isinstance(imu_av, ImuAllanVariance):
        raise TypeError(
            f"imu_av must be an ImuAllanVariance (avar.avar(imu) or avar.datasets.load(...)) or an IMU, "
            f"got {type(imu_av).__name__}"
        )
    short = {name: len(av) for name, av in imu_av.channels.items() if len(av) < 2}
    if short:
        raise ValueError(f"channels {short} have fewer than 2 levels; AVLR needs at least 2 levels")
    return imu_av


def _implied(estimates: Mapping[str, float], av: AllanVariance) -> dict[str, np.ndarray]:
    return {p: implied_allan_deviation(p, v, av.levels) for p, v in estimates.items()}


def imu_avlr(
    imu_av: Any,
    qn_gyro: Any = None,
    wn_gyro: Any = None,
    rw_gyro: Any = None,
    dr_gyro: Any = None,
    qn_acc: Any = None,
    wn_acc: Any = None,
    rw_acc: Any = None,
    dr_acc: Any = None,
    per_axis: bool = False,
) -> ImuAvlrResult:
    """Allan variance linear regression of every sensor type of an IMU.

    For each sensor type present, the selected processes are fitted on the
    selected scales of all its axes at once (R ``avlr.imu_avar``): with AD_k
    the Allan deviation of axis k, each parameter is::

        WN  sigma = exp(mean_{k,j}(log AD_k(tau_j) + log(tau_j) / 2))
        QN  Q     = exp(mean_{k,j}(log AD_k(tau_j) + log tau_j)) / sqrt(3)
        RW  gamma = sqrt(3) exp(mean_{k,j}(log AD_k(tau_j) - log(tau_j) / 2))
        DR  omega = sqrt(2) exp(mean_{k,j}(log AD_k(tau_j) - log tau_j))

    the geometric mean of the single-axis estimates, in tau units.

    Parameters
    ----------
    imu_av : ImuAllanVariance or IMU
        The IMU Allan variance (an IMU's is computed with the defaults of
        :func:`avar.avar`).
    qn_gyro, wn_gyro, rw_gyro, dr_gyro : int, range or sequence of int, optional
        1-based scales on which to fit each gyroscope process.
    qn_acc, wn_acc, rw_acc, dr_acc : int, range or sequence of int, optional
        The same for the accelerometers.
    per_axis : bool
        Fit every axis separately (beyond R): the estimates of a sensor type
        are then a table axis x process, each row equal to :func:`avar.avlr`
        of that channel.

    Returns
    -------
    ImuAvlrResult

    Raises
    ------
    ValueError
        A sensor type is present but no process is selected for it; a
        selection is given for a sensor type the IMU lacks; a scale is out of
        range, repeated or not whole; an Allan deviation on a selected scale
        is zero.
    TypeError
        ``imu_av`` is not an IMU Allan variance.

    Examples
    --------
    >>> from avar import datasets
    >>> fit = imu_avlr(datasets.load("navchip_av"), wn_gyro=range(6, 9), rw_gyro=range(10, 14),
    ...                wn_acc=range(1, 7), rw_acc=range(14, 17))
    >>> fit.estimates["Gyroscope"]
    WN    0.000059
    RW    0.000031
    dtype: float64
    >>> fit.implied_ad["Accel. Z"].shape
    (20,)
    """
    imu_av = _check_input(imu_av)
    if not isinstance(per_axis, (bool, np.bool_)):
        raise TypeError(f"per_axis must be True or False, got {per_axis!r}")
    requested = {
        GYROSCOPE: {"QN": qn_gyro, "WN": wn_gyro, "RW": rw_gyro, "DR": dr_gyro},
        ACCELEROMETER: {"QN": qn_acc, "WN": wn_acc, "RW": rw_acc, "DR": dr_acc},
    }
    present = imu_av.present_types
    unknown = [kind for kind in present if kind not in requested]
    if unknown:
        raise ValueError(
            f"unknown sensor type(s) {unknown}; the IMU AVLR fits {GYROSCOPE} and {ACCELEROMETER} channels"
        )
    for kind, selections in requested.items():
        given = [p.lower() + SUFFIXES[kind] for p in PROCESSES if selections[p] is not None]
        if kind not in present and given:
            raise ValueError(f"{', '.join(given)} given but the IMU has no {kind.lower()} channels")
        if kind in present and not given:
            names = ", ".join(p.lower() + SUFFIXES[kind] for p in PROCESSES)
            raise ValueError(
                f"the IMU has {kind.lower()} channels but no process is selected for them; give one of {names}"
            )

    estimates, scales_used, models, implied, decomposition = {}, {}, {}, {}, {}
    for kind in present:
        channels = imu_av.channels_of(kind)
        n_levels = min(len(av) for av in channels.values())
        selections = check_scale_selections(requested[kind], n_levels, SUFFIXES[kind])
        scales_used[kind] = selections
        if per_axis:
            rows = {}
            for name, av in channels.items():
                fitted = fit_slopes(av.levels, av.adev, selections)
                rows[imu_av.axes[list(imu_av.channels).index(name)]] = fitted
                models[name] = per_sample_model(fitted, imu_av.freq)
                decomposition[name] = _implied(fitted, av)
            estimates[kind] = pd.DataFrame.from_dict(rows, orient="index", dtype=np.float64)
            estimates[kind].columns.name = "Process"
        else:
            fitted = fit_slopes(
                [av.levels for av in channels.values()], [av.adev for av in channels.values()], selections
            )
            estimates[kind] = pd.Series(fitted, dtype=np.float64)
            model = per_sample_model(fitted, imu_av.freq)
            for name, av in channels.items():
                models[name] = model
                decomposition[name] = _implied(fitted, av)
        for name in channels:
            implied[name] = np.sum(list(decomposition[name].values()), axis=0)
    return ImuAvlrResult(
        imu_av=imu_av,
        per_axis=bool(per_axis),
        estimates=estimates,
        scales_used=scales_used,
        models={name: models[name] for name in imu_av.channels},
        implied_ad={name: implied[name] for name in imu_av.channels},
        implied_ad_decomp={name: decomposition[name] for name in imu_av.channels},
    )
