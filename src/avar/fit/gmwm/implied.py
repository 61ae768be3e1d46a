"""The model Allan variance nu(theta) of :func:`avar.gmwm` and its Jacobian.

The Allan variance of a sum is the sum of its processes' closed forms
A_k(m; theta_k) (``Process.theoretical_av``). Most parameters are scales:
A_k is homogeneous of some degree p in them (WN sigma2, QN q2, RW gamma2 and
AR1 sigma2: p = 1; DR omega: p = 2), so with the log transform
theta = exp(u), dA_k / du = p A_k exactly, at no extra cost. The degree is
found once per model by doubling the parameter (it must be the same ratio at
every scale); then A_k = prod_i theta_i^p_i B_k(shape), where the basis B_k
(the process with its homogeneous parameters at 1) depends only on the other
parameters (phi, or a scale that is not homogeneous) and is cached: WN, QN,
RW and DR are evaluated once per fit, an AR1 once per new phi. Shape
parameters get a forward difference of their own basis. A least-squares
iteration thus costs at most two closed-form evaluations per AR1, instead
of (number of parameters + 1) evaluations of the whole sum.
"""

from __future__ import annotations

import math

import numpy as np

from avar.fit.gmwm.model import ModelSpec

__all__ = ["ImpliedAllanVariance"]

#: Relative step of the forward differences in the unconstrained parameter.
STEP = 1e-7
#: Value of a shape parameter while the degrees of the others are found (inside its range).
REFERENCE = {"atanh": 0.5, "half-logit": 0.1}


class ImpliedAllanVariance:
    """nu(theta) and d nu / d u at fixed averaging factors, for unconstrained vectors u."""

    def __init__(self, spec: ModelSpec, factors: np.ndarray) -> None:
        self.spec = spec
        self.factors = np.asarray(factors, dtype=np.int64)
        sizes = [len(keys) for keys in spec.fields]
        self.blocks = [slice(a, a + s) for a, s in zip(np.cumsum([0] + sizes[:-1]), sizes)]
        self.powers = self._degrees()
        self._bases: dict[tuple, np.ndarray] = {}

    def _component(self, k: int, theta_block: np.ndarray) -> np.ndarray:
        cls, keys = self.spec.classes[k], self.spec.fields[k]
        process = cls(**{key: float(v) for key, v in zip(keys, theta_block)})
        return np.asarray(process.theoretical_av(self.factors), dtype=np.float64)

    def _degrees(self) -> list[float | None]:
        """Homogeneity degree of every log-transformed parameter (None: use differences)."""
        degrees: list[float | None] = []
        kinds = [t.kind for t in self.spec.transforms]
        for k, block in enumerate(self.blocks):
            reference = np.array([REFERENCE.get(kinds[i], 1.0) for i in range(block.start, block.stop)])
            base = self._component(k, reference)
            for j in range(block.stop - block.start):
                degree = None
                if kinds[block.start + j] == "log":
                    doubled = reference.copy()
                    doubled[j] = 2.0
                    ratio = self._component(k, doubled) / np.where(base > 0, base, np.nan)
                    logs = np.log2(ratio[np.isfinite(ratio) & (ratio > 0)])
                    if logs.size and np.ptp(logs) < 1e-9:
                        degree = float(np.mean(logs))
                degrees.append(degree)
        return degrees

    def _basis(self, k: int, free_block: np.ndarray) -> np.ndarray:
        """A_k with its homogeneous parameters at 1: depends on the shape parameters only (cached)."""
        block = self.blocks[k]
        shape = tuple(float(free_block[i - block.start]) for i in range(block.start, block.stop)
                      if self.powers[i] is None)
        key = (k, shape)
        found = self._bases.get(key)
        if found is None:
            theta = self.spec.theta_block(k, free_block)
            for i in range(block.start, block.stop):
                if self.powers[i] is not None:
                    theta[i - block.start] = 1.0
            found = self._component(k, theta)
            if len(self._bases) > 64:
                self._bases.clear()
            self._bases[key] = found
        return found

    def _scale(self, k: int, free_block: np.ndarray) -> float:
        """prod theta_i ** p_i over the homogeneous parameters (theta_i = exp(u_i))."""
        block = self.blocks[k]
        exponent = sum(self.powers[i] * min(max(float(free_block[i - block.start]), -300.0), 300.0)
                       for i in range(block.start, block.stop) if self.powers[i] is not None)
        return math.exp(min(max(exponent, -600.0), 600.0))

    def components(self, free: np.ndarray) -> list[np.ndarray]:
        """A_k(m; theta_k) of every process at the unconstrained vector ``free``."""
        free = np.asarray(free, dtype=np.float64)
        return [self._scale(k, free[b]) * self._basis(k, free[b]) for k, b in enumerate(self.blocks)]

    def value(self, free: np.ndarray) -> np.ndarray:
        """nu(theta(free)): the model's Allan variance at the factors."""
        return np.sum(self.components(free), axis=0)

    def jacobian(self, free: np.ndarray) -> np.ndarray:
        """d nu / d free, shape (scales, parameters)."""
        free = np.asarray(free, dtype=np.float64)
        out = np.empty((self.factors.size, free.size))
        for k, block in enumerate(self.blocks):
            local = free[block]
            scale = self._scale(k, local)
            part = scale * self._basis(k, local)
            for i in range(block.start, block.stop):
                if self.powers[i] is not None:
                    out[:, i] = self.powers[i] * part
                    continue
                step = STEP * max(1.0, abs(free[i]))
                moved = local.copy()
                moved[i - block.start] += step
                out[:, i] = (scale * self._basis(k, moved) - part) / step
        return out
