"""The terms of a sensor's noise model: their Allan variances per unit variance, and the fit's likelihood.

Per-sample parameters (:mod:`avar.models`), at averaging factors m: QN 3 / m^2,
WN 1 / m, FN flicker (exact sums up to m = 4096, then its expansion), RW
(2 m^2 + 1) / (6 m), DR m^2 / 2, AR1 Zhang's closed form, SIN a sinusoid of
frequency f cycles per sample. The deviance and the levels' weights of
:mod:`avar.fit.report.sensor_fit` are here too.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from avar.models.flicker import FLICKER_AV_FACTOR, av_fn
from avar.models.sinusoid import av_sin
from avar.models.theory import ar1_unit_av

__all__ = ["KINDS", "LINEAR", "DISCREPANCY", "Component", "basis", "deviance", "weight_edf", "flicker_unit_av"]

#: Terms in report order: IEEE 952's five, then Gauss-Markov and sinusoidal terms.
KINDS = ("QN", "WN", "FN", "RW", "DR", "AR1", "SIN")
LINEAR = ("QN", "WN", "FN", "RW", "DR")
#: Relative model discrepancy of the Allan variance (0.5 % in variance, 0.25 % in deviation): the
#: smallest that keeps real logs' shortest taus from dictating their fits, and that keeps the
#: intervals of simulated sensors calibrated (benchmarks/noise_report_real.py).
DISCREPANCY = 0.005


#: Largest factor at which the flicker AV is summed exactly; beyond, its expansion in 1 / m^2.
FLICKER_EXACT = 4096


@functools.lru_cache(maxsize=1)
def _flicker_head() -> tuple[np.ndarray, float]:
    exact = av_fn(1.0, np.arange(1, FLICKER_EXACT + 1))
    # AV(m) / (2 ln 2 / pi) - 1 = (c0 + (3/16) log2 m) / m^2 + O(log m / m^4): c0 from the last exact value
    c0 = (exact[-1] / FLICKER_AV_FACTOR - 1.0) * FLICKER_EXACT**2 - 0.1875 * math.log2(FLICKER_EXACT)
    return exact, c0


def flicker_unit_av(m: np.ndarray) -> np.ndarray:
    """Allan variance of unit flicker FN(b2=1) at factors m: exact up to 4096, then its expansion (1e-14).

    >>> bool(abs(flicker_unit_av(np.array([2.0**20]))[0] / av_fn(1.0, np.array([2**20]))[0] - 1) < 1e-13)
    True
    """
    m = np.asarray(m, dtype=np.float64)
    exact, c0 = _flicker_head()
    small = m <= FLICKER_EXACT
    out = np.empty(m.shape)
    out[small] = exact[m[small].astype(np.int64) - 1]
    big = m[~small]
    out[~small] = FLICKER_AV_FACTOR * (1.0 + (c0 + 0.1875 * np.log2(big)) / big**2)
    return out


def basis(kind: str, shape: float | None, m: np.ndarray) -> np.ndarray:
    """Allan variance per unit per-sample variance of one term at factors ``m``.

    >>> basis("WN", None, np.array([1, 2, 4])).tolist()
    [1.0, 0.5, 0.25]
    """
    m = np.asarray(m, dtype=np.float64)
    if kind == "QN":
        return 3.0 / m**2
    if kind == "WN":
        return 1.0 / m
    if kind == "FN":
        return flicker_unit_av(m)
    if kind == "RW":
        return (2.0 * m**2 + 1.0) / (6.0 * m)
    if kind == "DR":
        return m**2 / 2.0
    if kind == "AR1":
        return ar1_unit_av(m, shape)
    if kind == "SIN":
        return av_sin(m, 1.0, shape)
    raise ValueError(f"unknown term {kind!r}; terms are {KINDS}")


def weight_edf(edf: np.ndarray) -> np.ndarray:
    """Degrees of freedom the fit gives each level: 1 / (1 / edf + DISCREPANCY^2 / 2).

    A level's relative variance is 2 / edf from sampling, plus the square of
    the model's own discrepancy (no sum of processes describes a real sensor
    exactly): without that floor the shortest taus of a long log, known to
    0.1 % or better, would dictate the whole fit.

    >>> weight_edf(np.array([10.0, 1e6])).round(1).tolist()
    [10.0, 74074.1]
    """
    return 1.0 / (1.0 / np.asarray(edf, dtype=np.float64) + DISCREPANCY**2 / 2.0)


def deviance(nu_hat: np.ndarray, nu: np.ndarray, edf: np.ndarray) -> float:
    """Gamma deviance sum edf (r - 1 - log r), r = nu_hat / nu (0 for a perfect fit)."""
    ratio = nu_hat / np.maximum(nu, np.finfo(np.float64).tiny)
    return float(np.sum(edf * (ratio - 1.0 - np.log(ratio))))


@dataclass(frozen=True)
class Component:
    """One fitted term: its kind, per-sample variance ``scale`` and ``shape`` (phi, f or None)."""

    kind: str
    scale: float
    shape: float | None = None

    def av(self, m: np.ndarray) -> np.ndarray:
        """Its Allan variance at factors ``m``."""
        return self.scale * basis(self.kind, self.shape, m)
