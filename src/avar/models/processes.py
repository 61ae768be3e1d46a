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

Processes add with ``+`` into a :class:`CompositeModel`; every model, single
or composite, can :meth:`~NoiseModel.simulate` itself and gives its
:meth:`~NoiseModel.theoretical_av` (the sum of the closed forms of
:mod:`avar.models.theory`) at averaging factors m. Because the parameters are per
sample, the sampling rate plays no part in simulation: a model fitted on an
Allan variance in seconds is converted to per-sample parameters first (see
:func:`avar.fit.slopes.per_sample_model`).

References
----------
S. Guerrier, R. Molinari, J. Balamuta et al., ``simts``: Time series analysis
tools, R package. N. F. Zhang, "Allan variance of time series models for
measurement data", Metrologia 45(5):549-561, 2008.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np

from avar import _kernels
from avar._validation import check_count, check_freq, check_real, check_seed, check_whole_numbers, short_repr
from avar.models import theory

__all__ = ["NoiseModel", "Process", "CompositeModel", "WN", "QN", "RW", "DR", "AR1"]


def format_parameter(value: float) -> str:
    """Shortest exact text of a float, without a trailing ``.0``: 1.0 -> ``1``."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


# --------------------------------------------------------------------------- models
class NoiseModel:
    """Behaviour shared by single processes and their sums.

    Subclasses give ``components`` (the processes, in order) and, for a
    single process, ``_fill``.
    """

    components: tuple[Process, ...]

    def __add__(self, other: Any) -> CompositeModel:
        if not isinstance(other, NoiseModel):
            return NotImplemented
        return CompositeModel(self.components + other.components)

    def __radd__(self, other: Any) -> NoiseModel:
        # ``sum(models)`` starts from 0
        if isinstance(other, numbers.Number) and other == 0:
            return self
        return NotImplemented

    @property
    def parameter_vector(self) -> np.ndarray:
        """All parameters in component order, float64 (``WN + RW`` -> [sigma2, gamma2])."""
        return np.array([value for process in self.components for value in process.parameters.values()])

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Labels of :attr:`parameter_vector`, ``"<process>.<parameter>"``."""
        return tuple(f"{p.name}.{key}" for p in self.components for key in p.parameters)

    def theoretical_av(self, m: Any) -> float | np.ndarray:
        """Theoretical Allan variance at averaging factors ``m``.

        The sum over the components of the closed forms of :mod:`avar.models.theory`
        (WN sigma2 / m; QN 3 q2 / m^2; RW (2 m^2 + 1) gamma2 / (6 m);
        DR m^2 omega^2 / 2; AR1 Zhang 2008), in squared data units.

        Parameters
        ----------
        m : int or array_like of int
            Averaging factors (cluster sizes in samples), whole numbers >= 1.

        Returns
        -------
        float or ndarray
            A float for a scalar ``m``, else a float64 array shaped like ``m``.

        Examples
        --------
        >>> (WN(sigma2=1) + RW(gamma2=0.5)).theoretical_av([1, 2])
        array([1.25 , 0.875])
        """
        factors = check_whole_numbers(m, "m")
        if np.any(factors < 1):
            raise ValueError(f"m must hold averaging factors >= 1, got {short_repr(m)}")
        factors = factors.reshape(np.shape(m))
        total = sum(np.asarray(p._av(factors), dtype=np.float64) for p in self.components)
        return float(total) if np.ndim(m) == 0 else total

    def simulate(self, n: int, seed: Any = None) -> np.ndarray:
        """Simulate ``n`` samples of the model (the sum of its components).

        Parameters
        ----------
        n : int
            Length of the series, >= 1.
        seed : None, int, array_like, numpy.random.SeedSequence or numpy.random.Generator
            Passed to :func:`numpy.random.default_rng`; the same seed gives the
            same series. A Generator is used (and advanced) as is.

        Returns
        -------
        ndarray of float64, shape (n,)

        Examples
        --------
        >>> x = (WN(sigma2=1) + DR(omega=0.5)).simulate(5, seed=1)
        >>> x.shape, bool(np.all(x == (WN(sigma2=1) + DR(omega=0.5)).simulate(5, seed=1)))
        ((5,), True)
        """
        return self.simulate_replicates(n, 1, seed)[0]

    def simulate_replicates(self, n: int, replicates: int, seed: Any = None) -> np.ndarray:
        """Simulate ``replicates`` independent series of length ``n`` at once.

        Returns a C-contiguous float64 array of shape (replicates, n), one
        series per row (pass ``.T`` to :func:`avar.stability.allan.columns.allan_variance_columns`).
        Row 0 of a single replicate equals :meth:`simulate` with the same seed.

        Examples
        --------
        >>> RW(gamma2=1).simulate_replicates(1000, 3, seed=0).shape
        (3, 1000)
        """
        n = check_count(n, "n")
        replicates = check_count(replicates, "replicates")
        out = np.empty((replicates, n))
        with np.errstate(over="ignore", invalid="ignore"):
            self.simulate_into(out, np.random.default_rng(check_seed(seed)))
        if not np.isfinite(out).all():  # e.g. DR(omega=1e306): omega t passes the float64 limit
            raise ValueError(f"the simulation of {self!r} overflows float64 within {n} samples; rescale the "
                             "model's parameters (e.g. other units) or simulate fewer samples")
        return out

    def simulate_into(self, out: np.ndarray, rng: np.random.Generator) -> None:
        """Overwrite ``out`` with independent series of the model, one per row.

        ``out`` is a C-contiguous float64 array of shape (replicates, n),
        reused across calls to avoid allocating (the bootstrap of
        the AVLR bootstrap (:mod:`avar.fit.bootstrap`) fills it chunk by chunk); ``rng`` is advanced.

        Examples
        --------
        >>> out = np.empty((2, 3))
        >>> DR(omega=1).simulate_into(out, np.random.default_rng(0))
        >>> out
        array([[1., 2., 3.],
               [1., 2., 3.]])
        """
        if not (isinstance(out, np.ndarray) and out.dtype == np.float64 and out.ndim == 2 and out.flags.c_contiguous):
            raise TypeError("out must be a C-contiguous float64 array of shape (replicates, n)")
        if not isinstance(rng, np.random.Generator):
            raise TypeError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
        first, *rest = self.components
        first._fill(out, rng)
        if rest:
            scratch = np.empty_like(out)
            for process in rest:
                process._fill(scratch, rng)
                out += scratch


@dataclass(frozen=True)
class Process(NoiseModel):
    """One latent process; see the module docstring for the definitions."""

    name: ClassVar[str] = ""

    @property
    def components(self) -> tuple[Process, ...]:  # type: ignore[override]
        return (self,)

    @property
    def parameters(self) -> dict[str, float]:
        """Parameter names and values, in definition order."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def __repr__(self) -> str:
        inner = ", ".join(f"{key}={format_parameter(v)}" for key, v in self.parameters.items())
        return f"{self.name}({inner})"

    def _fill(self, out: np.ndarray, rng: np.random.Generator) -> None:  # pragma: no cover
        raise NotImplementedError

    def _av(self, m: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError


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


@dataclass(frozen=True)
class CompositeModel(NoiseModel):
    """A sum of processes, built with ``+``: ``WN(sigma2=1) + RW(gamma2=1e-06)``.

    Sums are flat (``(a + b) + c`` has three components) and ordered: two
    composites are equal when they have equal components in the same order.

    Examples
    --------
    >>> model = WN(sigma2=1) + RW(gamma2=1e-06)
    >>> model
    WN(sigma2=1) + RW(gamma2=1e-06)
    >>> model.parameter_vector
    array([1.e+00, 1.e-06])
    >>> model == WN(sigma2=1.0) + RW(gamma2=1e-6)
    True
    """

    components: tuple[Process, ...]

    def __post_init__(self) -> None:
        components = tuple(self.components)
        if not components or not all(isinstance(p, Process) for p in components):
            raise TypeError("a CompositeModel needs one or more processes (WN, QN, RW, DR, AR1, FN)")
        object.__setattr__(self, "components", components)

    def __repr__(self) -> str:
        return " + ".join(repr(p) for p in self.components)

    def __len__(self) -> int:
        return len(self.components)
