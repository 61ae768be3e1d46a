"""What every noise process is: :class:`NoiseModel`, :class:`Process` and their sums, :class:`CompositeModel`.

A process's class is the one description of a noise term for every estimator
(:mod:`avar.fit`): its ``name``, its parameters (the dataclass fields), its
simulation and theoretical Allan variance, and its view as a *term* of a fitted
model (:class:`Process`): the per-sample variance its Allan variance is linear in,
the shape it is not linear in, the Allan variance per unit of that variance and,
for IEEE Std 952's power laws, the Allan deviation's slope and continuous-time
coefficient. The processes themselves are in :mod:`avar.models.processes`,
:mod:`~avar.models.flicker` and :mod:`~avar.models.sinusoid`.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass, fields
from typing import Any, ClassVar

import numpy as np

from avar._validation import check_count, check_seed, check_whole_numbers, short_repr

__all__ = ["NoiseModel", "Process", "CompositeModel", "format_parameter", "process_classes"]


def format_parameter(value: float) -> str:
    """Shortest exact text of a float, without a trailing ``.0``: 1.0 -> ``1``."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


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
        >>> from avar.models import RW, WN
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
        >>> from avar.models import DR, WN
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
        >>> from avar.models import RW
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
        >>> from avar.models import DR
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
    """One latent process; see :mod:`avar.models.processes` for the definitions.

    As a term of a noise model, every process is described by its class: its
    Allan variance is linear in one per-sample variance, its :attr:`scale` (the
    field ``scale_field``; DR's omega squared), at a fixed :attr:`shape` (the
    field ``shape_field``: AR1's phi, SIN's f; None for the power laws), so that
    AV(m) = scale * ``unit_av(m, shape)``. The five power laws of IEEE Std 952
    (QN, WN, FN, RW, DR) have, in continuous time, an Allan deviation
    AD(tau) = c theta tau^b: ``slope`` b, ``ad_coefficient`` c, the coefficient
    theta (``coefficient_label``; ``coefficient(scale, freq)`` from the scale at
    ``freq`` Hz, the inverse of ``from_continuous``) and ``ieee_av(tau)`` =
    (c tau^b)^2, the Allan variance per unit theta^2.
    """

    name: ClassVar[str] = ""
    #: The field the Allan variance is linear in (DR's omega enters squared).
    scale_field: ClassVar[str] = ""
    #: The field the Allan variance is not linear in (AR1's phi, SIN's f); None for the power laws.
    shape_field: ClassVar[str | None] = None
    #: Log-log slope b of the Allan deviation, AD(tau) = c theta tau^b (the power laws; else None).
    slope: ClassVar[float | None] = None
    #: Coefficient c of AD(tau) = c theta tau^b (the power laws; else None).
    ad_coefficient: ClassVar[float | None] = None
    #: Symbol and unit of theta, u the data unit and s seconds (the power laws; else None).
    coefficient_label: ClassVar[str | None] = None

    @property
    def components(self) -> tuple[Process, ...]:  # type: ignore[override]
        return (self,)

    @property
    def parameters(self) -> dict[str, float]:
        """Parameter names and values, in definition order."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @property
    def scale(self) -> float:
        """The per-sample variance the Allan variance is linear in (the field ``scale_field``)."""
        return getattr(self, self.scale_field)

    @property
    def shape(self) -> float | None:
        """The parameter the Allan variance is not linear in (the field ``shape_field``), or None."""
        return None if self.shape_field is None else getattr(self, self.shape_field)

    @staticmethod
    def unit_av(m: np.ndarray, shape: float | None = None) -> np.ndarray:  # pragma: no cover
        """Allan variance per unit :attr:`scale` at averaging factors ``m`` (unchecked, for fits)."""
        raise NotImplementedError

    @staticmethod
    def ieee_av(tau: np.ndarray) -> np.ndarray:  # pragma: no cover
        """IEEE 952's Allan variance per unit squared coefficient at ``tau`` seconds: (c tau^b)^2."""
        raise NotImplementedError("only the power laws (QN, WN, FN, RW, DR) have an IEEE 952 coefficient")

    @classmethod
    def coefficient(cls, scale: float, freq: float) -> float:  # pragma: no cover
        """The continuous-time coefficient theta of a per-sample ``scale`` at ``freq`` Hz."""
        raise NotImplementedError("only the power laws (QN, WN, FN, RW, DR) have an IEEE 952 coefficient")

    def __repr__(self) -> str:
        inner = ", ".join(f"{key}={format_parameter(v)}" for key, v in self.parameters.items())
        return f"{self.name}({inner})"

    def _fill(self, out: np.ndarray, rng: np.random.Generator) -> None:  # pragma: no cover
        raise NotImplementedError

    def _av(self, m: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError


def process_classes() -> dict[str, type[Process]]:
    """Every named :class:`Process` subclass defined so far, by upper-case name.

    >>> import avar.models
    >>> {"AR1", "DR", "FN", "QN", "RW", "SIN", "WN"} <= set(process_classes())
    True
    """
    found, pending = {}, list(Process.__subclasses__())
    while pending:
        cls = pending.pop()
        pending.extend(cls.__subclasses__())
        if cls.name:
            found[cls.name.upper()] = cls
    return found


@dataclass(frozen=True)
class CompositeModel(NoiseModel):
    """A sum of processes, built with ``+``: ``WN(sigma2=1) + RW(gamma2=1e-06)``.

    Sums are flat (``(a + b) + c`` has three components) and ordered: two
    composites are equal when they have equal components in the same order.

    Examples
    --------
    >>> from avar.models import RW, WN
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
