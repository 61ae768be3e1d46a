"""A noise model as the fits see it: terms, each a process class with a variance scale and a shape.

Every estimator of :mod:`avar.fit` describes a term by its process class
(:mod:`avar.models`: name, parameters, Allan variance per unit variance, IEEE
952 slope and coefficient; :class:`~avar.models.base.Process`). What a fit adds
is only the values: a :class:`Component` is a class (by name), the per-sample
variance ``scale`` the Allan variance is linear in, and the ``shape`` it is not
(AR1's phi, SIN's f). :func:`components_of` turns any model description (a sum of
processes, processes, components) into components, so the estimators share one.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from avar.models import AR1, DR, FN, QN, RW, SIN, WN, NoiseModel, Process
from avar.models.base import process_classes

__all__ = ["POWER_LAWS", "SHAPED", "Component", "basis", "components_of", "process_class"]

#: IEEE Std 952's power laws, by the slope of their Allan deviation: QN, WN, FN, RW, DR.
POWER_LAWS = tuple(sorted((WN, QN, FN, RW, DR), key=lambda cls: cls.slope))
#: The terms with a shape: Gauss-Markov (AR1, phi) and sinusoid (SIN, f).
SHAPED = (AR1, SIN)


def process_class(kind: str) -> type[Process]:
    """The process class of a term's name (``"WN"`` -> :class:`~avar.models.WN`).

    >>> process_class("FN").slope
    0.0
    """
    found = process_classes().get(kind.upper()) if isinstance(kind, str) else None
    if found is None or found.name != kind:
        raise ValueError(f"unknown term {kind!r}; terms are {sorted(process_classes())}")
    return found


def basis(kind: str, shape: float | None, m: np.ndarray) -> np.ndarray:
    """Allan variance per unit per-sample variance of one term at factors ``m`` (the class's ``unit_av``).

    >>> basis("WN", None, np.array([1, 2, 4])).tolist()
    [1.0, 0.5, 0.25]
    """
    return process_class(kind).unit_av(np.asarray(m, dtype=np.float64), shape)


@dataclass(frozen=True)
class Component:
    """One term of a fitted model: its process's name ``kind``, per-sample variance ``scale`` and ``shape``
    (phi, f or None); the Allan variance is ``scale`` times the class's ``unit_av`` at ``shape``."""

    kind: str
    scale: float
    shape: float | None = None

    def __post_init__(self) -> None:
        process_class(self.kind)

    @property
    def process(self) -> type[Process]:
        """The process class of the term."""
        return process_class(self.kind)

    def av(self, m: np.ndarray) -> np.ndarray:
        """Its Allan variance at factors ``m``."""
        return self.scale * basis(self.kind, self.shape, m)


def components_of(model: Any) -> tuple[Component, ...]:
    """The components of a model: a :class:`~avar.models.NoiseModel`, or processes and components.

    >>> from avar.models import AR1, DR, WN
    >>> components_of(WN(sigma2=2.0) + AR1(phi=0.9, sigma2=1.0) + DR(omega=3.0))
    (Component(kind='WN', scale=2.0, shape=None), Component(kind='AR1', scale=1.0, shape=0.9),
     Component(kind='DR', scale=9.0, shape=None))
    """
    items: Iterable[Any] = model.components if isinstance(model, NoiseModel) else model
    out = []
    for item in items:
        if isinstance(item, Component):
            out.append(item)
        elif isinstance(item, Process):
            out.append(Component(item.name, item.scale, item.shape))
        else:
            raise TypeError(f"a model is processes or components, got {item!r}")
    return tuple(out)
