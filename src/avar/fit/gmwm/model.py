"""The model of :func:`avar.gmwm`: which processes, their free parameters and transforms.

A model to estimate is given without changing the process classes:

* a string of process names joined by ``+``: ``"WN + RW + AR1"``;
* a process class or a list of classes and instances: ``[avar.WN, avar.AR1]``;
* a process or a sum of processes with values (``WN(sigma2=1) + RW(gamma2=1e-6)``),
  whose values are the starting values of the optimizer.

Every :class:`~avar.models.Process` subclass with a ``name`` is accepted (the
flicker noise included once its module is imported): its parameters are its
dataclass fields, each mapped to the real line by a transform chosen by field
name (:data:`TRANSFORMS`): ``phi`` -> atanh (|phi| < 1), ``f`` -> logit(2 f)
(0 < f < 1/2), ``omega`` -> log |omega|
(the Allan variance sees omega^2 only, so its sign is not identifiable and
|omega| is reported), every other field -> log (a variance or scale > 0).
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from avar.fit.slopes import PROCESS_CLASSES
from avar.models import AR1, NoiseModel, Process
from avar.models.base import process_classes

__all__ = ["ModelSpec", "parse_model", "TRANSFORMS", "continuous_parameters"]

#: Clip of the unconstrained values: exp(+-300) stays finite, tanh(+-17) stays inside (-1, 1).
_LOG_CLIP, _TANH_CLIP = 300.0, 17.0


@dataclass(frozen=True)
class Transform:
    """A bijection between a constrained parameter and the real line."""

    kind: str

    def to_free(self, value: float) -> float:
        if self.kind == "atanh":
            return float(np.arctanh(np.clip(value, -1 + 1e-15, 1 - 1e-15)))
        if self.kind == "half-logit":
            share = float(np.clip(2.0 * value, 1e-15, 1 - 1e-15))
            return math.log(share / (1.0 - share))
        return float(np.log(abs(value)))

    def from_free(self, free: float) -> float:
        if self.kind == "atanh":
            return math.tanh(min(max(float(free), -_TANH_CLIP), _TANH_CLIP))
        if self.kind == "half-logit":
            return 0.5 / (1.0 + math.exp(-min(max(float(free), -_LOG_CLIP), _LOG_CLIP)))
        return math.exp(min(max(float(free), -_LOG_CLIP), _LOG_CLIP))


#: Transform of a parameter by field name; fields not listed are positive scales (log).
#: ``f`` (a sinusoid's frequency in cycles per sample) lies in (0, 1/2): a logistic of 2 f.
TRANSFORMS = {"phi": Transform("atanh"), "omega": Transform("log"), "f": Transform("half-logit")}
POSITIVE = Transform("log")


def transform_of(field_name: str) -> Transform:
    """The transform of a parameter field: ``phi`` atanh, anything else log."""
    return TRANSFORMS.get(field_name, POSITIVE)


@dataclass(frozen=True)
class ModelSpec:
    """Processes to fit, in order, with optional starting values.

    ``starts[k]`` is the process instance given by the user (its values start
    the optimizer) or None (starting values from the data).
    """

    classes: tuple[type[Process], ...]
    starts: tuple[Process | None, ...]

    @property
    def fields(self) -> tuple[tuple[str, ...], ...]:
        """Parameter names of every component."""
        return tuple(tuple(f.name for f in fields(cls)) for cls in self.classes)

    @property
    def size(self) -> int:
        """Number of parameters."""
        return sum(len(names) for names in self.fields)

    @property
    def labels(self) -> tuple[str, ...]:
        """``"WN.sigma2"``; a process that appears twice is numbered ``"AR1_1.phi"``, ``"AR1_2.phi"``."""
        names = [cls.name for cls in self.classes]
        seen: dict[str, int] = {}
        out = []
        for name, keys in zip(names, self.fields):
            seen[name] = seen.get(name, 0) + 1
            tag = f"{name}_{seen[name]}" if names.count(name) > 1 else name
            out.extend(f"{tag}.{key}" for key in keys)
        return tuple(out)

    @property
    def component_labels(self) -> tuple[str, ...]:
        """One label per component (``"WN"``, ``"AR1_1"``, ``"AR1_2"``)."""
        return tuple(dict.fromkeys(label.split(".")[0] for label in self.labels))

    @property
    def transforms(self) -> tuple[Transform, ...]:
        return tuple(transform_of(key) for keys in self.fields for key in keys)

    def model(self, theta: np.ndarray) -> NoiseModel:
        """The model with parameter vector ``theta`` (in :attr:`labels` order)."""
        processes, at = [], 0
        for cls, keys in zip(self.classes, self.fields):
            processes.append(cls(**{key: float(theta[at + i]) for i, key in enumerate(keys)}))
            at += len(keys)
        return sum(processes, start=0)

    def theta(self, free: np.ndarray) -> np.ndarray:
        """Constrained parameters of an unconstrained vector."""
        free = np.asarray(free, dtype=np.float64)
        return np.array([t.from_free(v) for t, v in zip(self.transforms, free)], dtype=np.float64)

    def theta_block(self, k: int, free: np.ndarray) -> np.ndarray:
        """Constrained parameters of component ``k`` from its unconstrained values."""
        keys = self.fields[k]
        return np.array([transform_of(key).from_free(v) for key, v in zip(keys, free)], dtype=np.float64)

    def free(self, theta: np.ndarray) -> np.ndarray:
        """Unconstrained vector of constrained parameters."""
        return np.array([t.to_free(v) for t, v in zip(self.transforms, theta)], dtype=np.float64)

    def canonical(self, theta: np.ndarray) -> np.ndarray:
        """Order repeated processes with a ``phi`` (AR1) by increasing phi, i.e. correlation time.

        A sum of two AR(1) is the same model whichever is called first; sorting
        makes the labels (and the bootstrap replicates) identifiable.
        """
        theta = np.array(theta, dtype=np.float64)
        offsets = np.cumsum([0] + [len(k) for k in self.fields])
        for cls in set(self.classes):
            keys = fields(cls)
            names = [f.name for f in keys]
            where = [k for k, c in enumerate(self.classes) if c is cls]
            if len(where) < 2 or "phi" not in names:
                continue
            blocks = [theta[offsets[k]:offsets[k + 1]].copy() for k in where]
            blocks.sort(key=lambda b: b[names.index("phi")])
            for k, block in zip(where, blocks):
                theta[offsets[k]:offsets[k + 1]] = block
        return theta


#: Processes a model may hold more than once (Gauss-Markov terms of different correlation times).
REPEATABLE = ("AR1", "GM")


def parse_model(model: Any) -> ModelSpec:
    """Validate the ``model`` argument of :func:`avar.gmwm` into a :class:`ModelSpec`.

    Examples
    --------
    >>> parse_model("WN + RW").labels
    ('WN.sigma2', 'RW.gamma2')
    >>> from avar.models import AR1, WN
    >>> parse_model([WN, AR1, AR1(phi=0.9, sigma2=1.0)]).labels
    ('WN.sigma2', 'AR1_1.phi', 'AR1_1.sigma2', 'AR1_2.phi', 'AR1_2.sigma2')
    """
    known = process_classes()
    accepted = f"a string such as 'WN + RW + AR1' (processes {sorted(known)}), a process class, a list of " \
               "classes or processes, or a process sum with starting values such as WN(sigma2=1) + RW(gamma2=1e-6)"
    if isinstance(model, str):
        items: Sequence[Any] = [part.strip() for part in re.split(r"\+", model)]
    elif isinstance(model, NoiseModel):
        items = model.components
    elif isinstance(model, type):
        items = [model]
    elif isinstance(model, (list, tuple)):
        items = model
    else:
        raise TypeError(f"model must be {accepted}; got {type(model).__name__}")
    if not items:
        raise ValueError(f"model is empty; give {accepted}")
    classes, starts = [], []
    for item in items:
        if isinstance(item, str):
            if item.upper() not in known:
                raise ValueError(f"model has an unknown process {item!r}; known processes: {sorted(known)}")
            classes.append(known[item.upper()])
            starts.append(None)
        elif isinstance(item, type) and issubclass(item, Process) and item.name:
            classes.append(item)
            starts.append(None)
        elif isinstance(item, Process):
            classes.append(type(item))
            starts.append(item)
        else:
            raise TypeError(f"model items must be process names, classes or instances; got {item!r}")
    for cls in dict.fromkeys(classes):
        count = classes.count(cls)
        if count > 1 and cls.name not in REPEATABLE:
            raise ValueError(f"model has {cls.name} {count} times: terms of one kind have the same Allan variance "
                             f"shape, so only their sum is estimable (any split fits equally); give {cls.name} once "
                             f"(only {' and '.join(REPEATABLE)} may repeat, with different correlation times)")
    return ModelSpec(tuple(classes), tuple(starts))


def continuous_parameters(process: Process, freq: float) -> dict[str, float]:
    """Continuous-time parameters of a per-sample process at rate ``freq`` (Hz).

    WN sigma = sqrt(sigma2 / f) [u s^1/2]; QN Q = sqrt(q2) / f [u s]; RW
    gamma = sqrt(gamma2 f) [u s^-1/2]; DR omega f [u s^-1] (the class's
    ``coefficient`` and ``coefficient_label``, for the processes of
    :data:`avar.fit.slopes.PROCESS_CLASSES`); AR1 (a first-order
    Gauss-Markov process) correlation time T = -1 / (f ln phi) [s] (for
    phi > 0) and stationary deviation sqrt(sigma2 / (1 - phi^2)) [u]. The
    inverses of the ``from_continuous`` constructors. Other processes: {}.

    >>> from avar.models import WN
    >>> continuous_parameters(WN(sigma2=4.0), 100.0)
    {'sigma [u s^1/2]': 0.2}
    """
    cls = type(process)
    if cls in PROCESS_CLASSES.values():
        return {cls.coefficient_label: float(cls.coefficient(process.scale, freq))}
    if isinstance(process, AR1):
        phi = process.phi
        corr = -1.0 / (freq * np.log(phi)) if 0.0 < phi < 1.0 else float("nan")
        return {"T [s]": float(corr), "sigma_s [u]": float(np.sqrt(process.sigma2 / (1.0 - phi**2)))}
    return {}
