"""Latent noise processes, their sums, simulation and theoretical Allan variance.

The processes are parametrized *per sample*, as in the R package ``simts``
(``WN``, ``QN``, ``RW``, ``DR``, ``AR1``), for a series x_1..x_n:

========================  =====================================================
``WN(sigma2)``            white noise, x_t i.i.d. N(0, sigma2)
``QN(q2)``                quantization noise, x_t = sqrt(q2) (u_{t+1} - u_t) with
                          u_t i.i.d. sqrt(12) U(0, 1) (so var x_t = 2 q2)
``RW(gamma2)``            random walk, x_t = sum_{i<=t} e_i, e_i i.i.d. N(0, gamma2)
``DR(omega)``             deterministic drift, x_t = omega t, t = 1..n
``AR1(phi, sigma2)``      x_t = phi x_{t-1} + e_t, e_t i.i.d. N(0, sigma2),
                          started from its stationary law N(0, sigma2 / (1 - phi^2))
========================  =====================================================

Processes add with ``+`` into a :class:`~avar.models.base.CompositeModel`; every model, single
or composite, can :meth:`~avar.models.base.NoiseModel.simulate` itself and gives its
:meth:`~avar.models.base.NoiseModel.theoretical_av` (the sum of the closed forms of
:mod:`avar.models.theory`) at averaging factors m. Because the parameters are per
sample, the sampling rate plays no part in simulation: a model fitted on an
Allan variance in seconds is converted to per-sample parameters first (see
:func:`avar.fit.slopes.per_sample_model`). Each class also describes the process
as a term of a fitted model (:class:`~avar.models.base.Process`): the variance
its Allan variance is linear in, that Allan variance per unit, and IEEE 952's
slope and continuous-time coefficient.

References
----------
S. Guerrier, R. Molinari, J. Balamuta et al., ``simts``: Time series analysis
tools, R package. N. F. Zhang, "Allan variance of time series models for
measurement data", Metrologia 45(5):549-561, 2008.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from avar import _kernels
from avar._validation import check_freq, check_real
from avar.models import theory
from avar.models.base import Process

__all__ = ["WN", "QN", "RW", "DR", "AR1"]


@dataclass(frozen=True, repr=False)
class WN(Process):
    """White noise: x_t i.i.d. N(0, sigma2); AV(m) = sigma2 / m.

    Examples
    --------
    >>> WN(sigma2=2).theoretical_av(4)
    0.5
    """

    sigma2: float
    name: ClassVar[str] = "WN"
    scale_field: ClassVar[str] = "sigma2"
    slope: ClassVar[float] = -0.5
    ad_coefficient: ClassVar[float] = 1.0
    coefficient_label: ClassVar[str] = "sigma [u s^1/2]"

    def __post_init__(self) -> None:
        object.__setattr__(self, "sigma2", check_real(self.sigma2, "sigma2", minimum=0.0))

    @classmethod
    def from_continuous(cls, sigma: float, freq: float) -> WN:
        """White noise of density ``sigma`` (u s^1/2 = u / sqrt(Hz)) sampled at ``freq`` Hz.

        AD(tau) = sigma / sqrt(tau) and, with tau = m / f, sigma^2 / tau =
        sigma2 / m give ``sigma2 = sigma^2 f``.

        >>> round(WN.from_continuous(0.1, 100.0).sigma2, 10)
        1.0
        """
        return cls(sigma2=check_real(sigma, "sigma") ** 2 * check_freq(freq))

    def _fill(self, out: np.ndarray, rng: np.random.Generator) -> None:
        rng.standard_normal(out=out)
        out *= np.sqrt(self.sigma2)

    def _av(self, m: np.ndarray) -> np.ndarray:
        return theory.av_wn(self.sigma2, m)

    @staticmethod
    def unit_av(m: np.ndarray, shape: float | None = None) -> np.ndarray:
        """1 / m."""
        return 1.0 / np.asarray(m, dtype=np.float64)

    @staticmethod
    def ieee_av(tau: np.ndarray) -> np.ndarray:
        """1 / tau: AD(tau) = N / sqrt(tau)."""
        return 1.0 / tau

    @classmethod
    def coefficient(cls, scale: float, freq: float) -> float:
        """N = sqrt(sigma2 / f), in u s^1/2 = u / sqrt(Hz)."""
        return math.sqrt(scale / freq)


@dataclass(frozen=True, repr=False)
class QN(Process):
    """Quantization noise: x_t = sqrt(q2) (u_{t+1} - u_t), u_t i.i.d. sqrt(12) U(0, 1).

    var x_t = 2 q2; AV(m) = 3 q2 / m^2.

    Examples
    --------
    >>> QN(q2=1).theoretical_av([1, 2])
    array([3.  , 0.75])
    """

    q2: float
    name: ClassVar[str] = "QN"
    scale_field: ClassVar[str] = "q2"
    slope: ClassVar[float] = -1.0
    ad_coefficient: ClassVar[float] = float(np.sqrt(3.0))
    coefficient_label: ClassVar[str] = "Q [u s]"

    def __post_init__(self) -> None:
        object.__setattr__(self, "q2", check_real(self.q2, "q2", minimum=0.0))

    @classmethod
    def from_continuous(cls, q: float, freq: float) -> QN:
        """Quantization noise of coefficient ``q`` (u s) sampled at ``freq`` Hz.

        AD(tau) = sqrt(3) q / tau and 3 q^2 / tau^2 = 3 q2 / m^2 give
        ``q2 = q^2 f^2``.

        >>> QN.from_continuous(0.01, 100.0)
        QN(q2=1)
        """
        return cls(q2=check_real(q, "q") ** 2 * check_freq(freq) ** 2)

    def _fill(self, out: np.ndarray, rng: np.random.Generator) -> None:
        uniform = rng.random((out.shape[0], out.shape[1] + 1))
        np.subtract(uniform[:, 1:], uniform[:, :-1], out=out)
        out *= np.sqrt(12.0 * self.q2)

    def _av(self, m: np.ndarray) -> np.ndarray:
        return theory.av_qn(self.q2, m)

    @staticmethod
    def unit_av(m: np.ndarray, shape: float | None = None) -> np.ndarray:
        """3 / m^2."""
        return 3.0 / np.asarray(m, dtype=np.float64) ** 2

    @staticmethod
    def ieee_av(tau: np.ndarray) -> np.ndarray:
        """3 / tau^2: AD(tau) = sqrt(3) Q / tau."""
        return 3.0 / tau**2

    @classmethod
    def coefficient(cls, scale: float, freq: float) -> float:
        """Q = sqrt(q2) / f, in u s."""
        return math.sqrt(scale) / freq


@dataclass(frozen=True, repr=False)
class RW(Process):
    """Random walk: x_t = e_1 + ... + e_t, e_i i.i.d. N(0, gamma2).

    AV(m) = (2 m^2 + 1) gamma2 / (6 m).

    Examples
    --------
    >>> RW(gamma2=3).theoretical_av(1)
    1.5
    """

    gamma2: float
    name: ClassVar[str] = "RW"
    scale_field: ClassVar[str] = "gamma2"
    slope: ClassVar[float] = 0.5
    ad_coefficient: ClassVar[float] = float(1.0 / np.sqrt(3.0))
    coefficient_label: ClassVar[str] = "gamma [u s^-1/2]"

    def __post_init__(self) -> None:
        object.__setattr__(self, "gamma2", check_real(self.gamma2, "gamma2", minimum=0.0))

    @classmethod
    def from_continuous(cls, gamma: float, freq: float) -> RW:
        """Random walk of coefficient ``gamma`` (u / s^1/2) sampled at ``freq`` Hz.

        AD(tau) = gamma sqrt(tau / 3) and gamma^2 tau / 3 = gamma2 m / 3 give
        ``gamma2 = gamma^2 / f``. The per-sample closed form
        (2 m^2 + 1) gamma2 / (6 m) exceeds gamma2 m / 3 by the factor
        1 + 1 / (2 m^2): 1.125 at m = 2, under 0.2% from m = 16.

        >>> RW.from_continuous(0.5, 100.0)
        RW(gamma2=0.0025)
        """
        return cls(gamma2=check_real(gamma, "gamma") ** 2 / check_freq(freq))

    def _fill(self, out: np.ndarray, rng: np.random.Generator) -> None:
        rng.standard_normal(out=out)
        np.cumsum(out, axis=1, out=out)
        out *= np.sqrt(self.gamma2)

    def _av(self, m: np.ndarray) -> np.ndarray:
        return theory.av_rw(self.gamma2, m)

    @staticmethod
    def unit_av(m: np.ndarray, shape: float | None = None) -> np.ndarray:
        """(2 m^2 + 1) / (6 m)."""
        m = np.asarray(m, dtype=np.float64)
        return (2.0 * m**2 + 1.0) / (6.0 * m)

    @staticmethod
    def ieee_av(tau: np.ndarray) -> np.ndarray:
        """tau / 3: AD(tau) = K sqrt(tau / 3)."""
        return tau / 3.0

    @classmethod
    def coefficient(cls, scale: float, freq: float) -> float:
        """K = sqrt(gamma2 f), in u / s^1/2."""
        return math.sqrt(scale * freq)


@dataclass(frozen=True, repr=False)
class DR(Process):
    """Deterministic drift: x_t = omega t for t = 1..n; AV(m) = m^2 omega^2 / 2.

    Examples
    --------
    >>> DR(omega=2).simulate(3)
    array([2., 4., 6.])
    """

    omega: float
    name: ClassVar[str] = "DR"
    scale_field: ClassVar[str] = "omega"
    slope: ClassVar[float] = 1.0
    ad_coefficient: ClassVar[float] = float(1.0 / np.sqrt(2.0))
    coefficient_label: ClassVar[str] = "omega [u s^-1]"

    def __post_init__(self) -> None:
        object.__setattr__(self, "omega", check_real(self.omega, "omega"))

    @classmethod
    def from_continuous(cls, omega: float, freq: float) -> DR:
        """Drift of ``omega`` units per second sampled at ``freq`` Hz: ``DR(omega / f)``.

        AD(tau) = omega tau / sqrt(2) and omega^2 tau^2 / 2 = m^2 delta^2 / 2
        give the per-sample slope delta = omega / f.

        >>> DR.from_continuous(2.0, 100.0)
        DR(omega=0.02)
        """
        return cls(omega=check_real(omega, "omega") / check_freq(freq))

    def _fill(self, out: np.ndarray, rng: np.random.Generator) -> None:
        out[:] = self.omega * np.arange(1, out.shape[1] + 1, dtype=np.float64)

    def _av(self, m: np.ndarray) -> np.ndarray:
        return theory.av_dr(self.omega, m)

    @property
    def scale(self) -> float:
        """omega^2: the Allan variance is m^2 omega^2 / 2."""
        return self.omega * self.omega

    @staticmethod
    def unit_av(m: np.ndarray, shape: float | None = None) -> np.ndarray:
        """m^2 / 2."""
        return np.asarray(m, dtype=np.float64) ** 2 / 2.0

    @staticmethod
    def ieee_av(tau: np.ndarray) -> np.ndarray:
        """tau^2 / 2: AD(tau) = R tau / sqrt(2)."""
        return tau**2 / 2.0

    @classmethod
    def coefficient(cls, scale: float, freq: float) -> float:
        """R = sqrt(omega^2) f, the slope's size per second, in u / s."""
        return math.sqrt(scale) * freq


@dataclass(frozen=True, repr=False)
class AR1(Process):
    """First-order autoregression x_t = phi x_{t-1} + e_t, e_t i.i.d. N(0, sigma2).

    Stationary (``|phi| < 1``): x_1 is drawn from N(0, sigma2 / (1 - phi^2)) and
    the recursion x_t = phi x_{t-1} + e_t runs in a compiled kernel. The theoretical AV
    is Zhang's (2008) closed form, :func:`avar.models.theory.av_ar1`.

    Examples
    --------
    >>> AR1(phi=0.0, sigma2=2).theoretical_av(4)
    0.5
    """

    phi: float
    sigma2: float
    name: ClassVar[str] = "AR1"
    scale_field: ClassVar[str] = "sigma2"
    shape_field: ClassVar[str] = "phi"

    def __post_init__(self) -> None:
        object.__setattr__(self, "phi", check_real(self.phi, "phi", bound=1.0))
        object.__setattr__(self, "sigma2", check_real(self.sigma2, "sigma2", minimum=0.0))

    def _fill(self, out: np.ndarray, rng: np.random.Generator) -> None:
        rng.standard_normal(out=out)
        out *= np.sqrt(self.sigma2)
        out[:, 0] /= np.sqrt(1.0 - self.phi**2)
        _kernels.ar1_recursion(out, self.phi)

    def _av(self, m: np.ndarray) -> np.ndarray:
        return theory.av_ar1(m, self.phi, self.sigma2)

    @staticmethod
    def unit_av(m: np.ndarray, shape: float | None = None) -> np.ndarray:
        """Zhang's form per unit sigma2 at phi = ``shape``, 1/2 < phi < 1 (:func:`avar.models.theory.ar1_unit_av`)."""
        return theory.ar1_unit_av(m, shape)


