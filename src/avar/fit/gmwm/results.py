"""Result objects of :func:`avar.gmwm`: :class:`GmwmResult` and :class:`ImuGmwmResult`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from avar._frozen import frozen_array, frozen_frame, frozen_mapping, frozen_series
from avar._vocabulary import deprecated_significance
from avar.fit.gmwm.model import continuous_parameters
from avar.models import NoiseModel
from avar.stability.allan.results import AllanVariance, ImuAllanVariance

__all__ = ["GmwmResult", "ImuGmwmResult"]


@dataclass(frozen=True, eq=False)
class GmwmResult:
    """A joint (GMWM) fit of a sum of processes to an Allan variance.

    Build it with :func:`avar.gmwm`; the fields are read-only.

    Attributes
    ----------
    estimates : pandas.Series
        Per-sample parameters (``"WN.sigma2"``, ``"AR1_1.phi"``, ...), the
        parametrization of :mod:`avar.models.processes`.
    model : NoiseModel
        The fitted per-sample model, ready to ``simulate``.
    av : AllanVariance
        The empirical Allan variance that was fitted.
    implied_av : ndarray
        The model's Allan variance at ``av``'s averaging factors.
    decomposition : Mapping[str, ndarray]
        Each process's Allan variance at those factors (``"WN"``, ``"AR1_1"``).
    objective : float
        The minimized (nu_hat - nu)' W (nu_hat - nu) (a chi-square-like value
        with about L - p degrees of freedom for the default weights).
    weights : str
        ``"diagonal"``, ``"full"``, ``"efficient"`` or ``"identity"``.
    ci : pandas.DataFrame or None
        With ``ci=True``: ``Estimate``, ``SE``, ``Lower``, ``Upper`` per parameter.
    confidence, replicates : float, int or None
        Confidence level of ``ci`` and bootstrap replicates (with ``ci=True``).
    converged : bool
        Whether the optimizer reported convergence.
    taus : ndarray
        (property) Averaging times tau (s) of the levels of ``av``.
    """

    estimates: pd.Series
    model: NoiseModel
    av: AllanVariance
    implied_av: np.ndarray
    decomposition: Mapping[str, np.ndarray]
    objective: float
    weights: str
    ci: pd.DataFrame | None = None
    confidence: float | None = None
    replicates: int | None = None
    converged: bool = True

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        set_field(self, "estimates", frozen_series(self.estimates))
        set_field(self, "implied_av", frozen_array(self.implied_av))
        set_field(self, "decomposition", frozen_mapping({k: frozen_array(v) for k, v in self.decomposition.items()}))
        if self.ci is not None:
            set_field(self, "ci", frozen_frame(self.ci))

    @property
    def implied_ad(self) -> np.ndarray:
        """Implied Allan deviation sqrt(implied_av)."""
        return np.sqrt(self.implied_av)

    @property
    def taus(self) -> np.ndarray:
        """Averaging times tau (s) of the fitted Allan variance's levels."""
        return self.av.taus

    @property
    def alpha(self) -> float | None:
        """Deprecated (removed in 0.3.0): 1 - :attr:`confidence`."""
        return deprecated_significance(self.confidence)

    @property
    def continuous(self) -> pd.Series:
        """Continuous-time parameters at the data's rate (see :func:`~avar.fit.gmwm.model.continuous_parameters`).

        WN sigma [u s^1/2], QN Q [u s], RW gamma [u s^-1/2], DR omega [u s^-1],
        AR1 correlation time T [s] and stationary deviation sigma_s [u].
        """
        values = {}
        for label, process in zip(self.decomposition, self.model.components):
            for key, value in continuous_parameters(process, self.av.freq).items():
                values[f"{label}.{key}"] = value
        return pd.Series(values, dtype=np.float64)

    def summary(self) -> pd.DataFrame:
        """One row per per-sample parameter: ``Estimate`` (and ``SE``, ``Lower``, ``Upper`` with ``ci=True``)."""
        if self.ci is not None:
            return self.ci.copy()
        return pd.DataFrame({"Estimate": self.estimates.to_numpy()},
                            index=pd.Index(self.estimates.index, name="Parameter"))

    def describe(self) -> str:
        """Text of :meth:`__str__`."""
        head = (f"GMWM fit of {self.model!r}\n"
                f"{len(self.av)} scales, N = {self.av.n}, freq = {self.av.freq:g} Hz, weights = {self.weights}, "
                f"objective = {self.objective:.4g}")
        if self.ci is not None:
            head += f", {100 * self.confidence:g}% bootstrap intervals (B = {self.replicates})"
        return f"{head}\n{self.summary().to_string()}\nContinuous time:\n{self.continuous.to_string()}"

    def __str__(self) -> str:
        return self.describe()

    def __repr__(self) -> str:
        return f"<GmwmResult {self.model!r}, objective {self.objective:.4g}>"

    def plot(self, **kwargs: Any):
        """Empirical AD with band, implied AD and each process; see :func:`avar.plotting.plot_gmwm`."""
        from avar.plotting import plot_gmwm

        return plot_gmwm(self, **kwargs)


@dataclass(frozen=True, eq=False)
class ImuGmwmResult:
    """GMWM fits of every channel of an IMU (``avar.gmwm(imu, model_gyro=..., model_acc=...)``).

    Attributes
    ----------
    imu_av : ImuAllanVariance
        The Allan variances that were fitted.
    fits : Mapping[str, GmwmResult]
        One fit per channel, in channel order.
    taus : ndarray
        (property) Averaging times tau (s) of the IMU's levels (``imu_av.taus``).
    """

    imu_av: ImuAllanVariance
    fits: Mapping[str, GmwmResult]

    def __post_init__(self) -> None:
        object.__setattr__(self, "fits", frozen_mapping(dict(self.fits)))

    def __getitem__(self, channel: str) -> GmwmResult:
        return self.fits[channel]

    @property
    def taus(self) -> np.ndarray:
        """Averaging times tau (s) of the IMU's levels (see :attr:`avar.ImuAllanVariance.taus`)."""
        return self.imu_av.taus

    def summary(self) -> pd.DataFrame:
        """The channels' summaries stacked, indexed by (channel, parameter)."""
        return pd.concat({name: fit.summary() for name, fit in self.fits.items()}, names=["Channel", "Parameter"])

    def __str__(self) -> str:
        return f"GMWM fits of IMU {self.imu_av.sensor!r}\n{self.summary().to_string()}"

    def __repr__(self) -> str:
        return f"<ImuGmwmResult of {len(self.fits)} channels>"

    def plot(self, **kwargs: Any):
        """One panel per channel; see :func:`avar.plotting.plot_imu_gmwm`."""
        from avar.plotting import plot_imu_gmwm

        return plot_imu_gmwm(self, **kwargs)
