"""The terms a sensor's noise model may hold, in the report's order, and the fit's likelihood.

The terms are the process classes of :mod:`avar.models` (their Allan variance per
unit variance is the class's ``unit_av``; :mod:`avar.fit.terms`): IEEE 952's
power laws by slope, then the Gauss-Markov and sinusoidal terms. The deviance and
the levels' weights of :mod:`avar.fit.report.sensor_fit` are here too.
"""

from __future__ import annotations

import numpy as np

from avar.fit.terms import POWER_LAWS, SHAPED

__all__ = ["KINDS", "LINEAR", "DISCREPANCY", "deviance", "weight_edf"]

#: Terms in report order: IEEE 952's five (QN, WN, FN, RW, DR), then Gauss-Markov and sinusoidal terms.
KINDS = tuple(cls.name for cls in POWER_LAWS + SHAPED)
#: The terms without a shape, linear in their one parameter.
LINEAR = tuple(cls.name for cls in POWER_LAWS)
#: Relative model discrepancy of the Allan variance (0.5 % in variance, 0.25 % in deviation): the
#: smallest that keeps real logs' shortest taus from dictating their fits, and that keeps the
#: intervals of simulated sensors calibrated (benchmarks/noise_report_real.py).
DISCREPANCY = 0.005


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
