"""The noise model of a clock from its time error: :func:`clock_report`.

The fractional frequency y (phase data are differenced, y_i = (x_{i+1} - x_i) rate) is
described by a sum of independent power-law processes: white PM (QN), white FM (WN), flicker FM
(FN) and random-walk FM (RW). Every non-empty sum of them is fitted jointly at all averaging
factors m = 1, 2, 4, ... by the generalized method of wavelet moments (:func:`avar.gmwm`), the
sums are ranked by an AIC-type penalized objective (:func:`avar.select_model`, 2 per parameter),
and the chosen one is refitted with a parametric bootstrap for its intervals. The processes'
per-sample parameters convert exactly to the power-law coefficients ``h_alpha`` and to the
diffusion coefficients q1, q2 of the two-state Kalman clock model
(:mod:`avar.fit.clock.coefficients`). The implied Allan deviation is checked against the
record's OADEV and its chi-squared band at every level.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from avar._validation import short_repr
from avar._vocabulary import check_confidence
from avar.fit.clock.coefficients import H_OF_PROCESS, h_coefficient, kalman_q

__all__ = ["ClockReport", "clock_report", "PROCESSES"]

#: The processes a clock's model is built from, with the noise each stands for.
PROCESSES = {"QN": "white PM", "WN": "white FM", "FN": "flicker FM", "RW": "random-walk FM"}
#: Share of levels whose implied deviation must lie in the chi-squared band of the record's OADEV.
FIT_SHARE = 0.9


@dataclass(frozen=True, eq=False)
class ClockReport:
    """A clock's power-law and Kalman-model coefficients with intervals, and the fit behind them.

    Attributes
    ----------
    coefficients : pandas.DataFrame
        One row per power law in the chosen model: ``Noise``, ``alpha``, ``h`` (S_y = h f**alpha,
        1/Hz at f = 1 Hz), ``Lower``, ``Upper`` (the ``confidence`` interval), ``Process``.
    kalman : pandas.DataFrame
        ``q1`` (s, white FM: ``h_0`` / 2), ``q2`` (1/s, random-walk FM: 2 pi**2 ``h_-2``) and ``r``
        (s**2, white PM measurement noise sigma_x**2) with intervals; 0 where the model has no
        such term.
    fit : GmwmResult
        The joint fit (estimates, intervals, implied Allan variance, ``plot()``).
    candidates : pandas.DataFrame
        Every sum tried, ranked (:func:`avar.select_model`).
    rate : float
    n_samples : int
        Frequency values fitted.
    confidence : float
    in_band : float
        Share of levels whose implied deviation lies in the 95 % chi-squared band of OADEV.
    warnings : tuple of str
    """

    coefficients: pd.DataFrame
    kalman: pd.DataFrame
    fit: Any
    candidates: pd.DataFrame
    rate: float
    n_samples: int
    confidence: float
    in_band: float
    warnings: tuple[str, ...]

    @property
    def q(self) -> dict[str, float]:
        """The Kalman model's coefficients, for a filter: ``{"q1": s, "q2": 1/s, "r": s**2}``."""
        return {name: float(self.kalman.loc[name, "Value"]) for name in self.kalman.index}

    def summary(self) -> pd.DataFrame:
        """The power-law coefficients (see ``coefficients``)."""
        return self.coefficients.copy()

    def plot(self, **kwargs: Any):
        """The Allan deviation with the fitted model and its terms (the GMWM figure)."""
        return self.fit.plot(**kwargs)

    def __str__(self) -> str:
        lines = [f"Clock noise model at {self.rate:g} Hz, N = {self.n_samples} ({self.confidence:g} intervals):"]
        for _, row in self.coefficients.iterrows():
            lines.append(f"  {row['Noise']:<15} h({row['alpha']:+d}) = {row['h']:.4g}  [{row['Lower']:.4g}, {row['Upper']:.4g}]")
        for name, row in self.kalman.iterrows():
            unit = {"q1": "s", "q2": "1/s", "r": "s^2"}[name]
            lines.append(f"  {name} = {row['Value']:.4g} {unit}  [{row['Lower']:.4g}, {row['Upper']:.4g}]")
        lines.append(f"  fit: {self.in_band:.0%} of levels inside OADEV's 95 % band")
        lines.extend(f"  warning: {w}" for w in self.warnings)
        return "\n".join(lines)


def _frequency(x: Any, rate: float, data_type: str) -> np.ndarray:
    from avar.stability.shared.inputs import finite_vector

    values = finite_vector(x, "x", 34 if data_type == "phase" else 33)
    return np.diff(values) * rate if data_type == "phase" else values


def clock_report(x: Any, rate: float = 1.0, data_type: str = "phase", *, confidence: float = 0.95, B: int = 100,
                 seed: Any = None, processes: Any = None) -> ClockReport:
    """Power-law coefficients ``h_alpha`` and Kalman diffusion coefficients q of a clock, with intervals.

    Parameters
    ----------
    x : array_like
        Time error (s) with ``data_type="phase"`` or fractional frequency with ``"freq"``;
        1-D, finite, drift removed (:func:`avar.remove_drift`) if the clock drifts.
    rate : float
        Sampling rate in Hz.
    data_type : {"phase", "freq"}
    confidence : float
        Confidence level of the intervals, in (0, 1).
    B : int
        Bootstrap replicates of the intervals (>= 10).
    seed : None, int or numpy.random.Generator
        Seed of the bootstrap.
    processes : sequence of str, optional
        The processes to choose from (default all of ``"QN", "WN", "FN", "RW"``).

    Returns
    -------
    ClockReport

    Examples
    --------
    >>> import numpy as np, avar
    >>> y = (avar.WN(sigma2=1e-22) + avar.RW(gamma2=1e-28)).simulate(100_000, seed=1)   # 1 Hz
    >>> report = avar.clock_report(y, rate=1.0, data_type="freq", B=20, seed=2)
    >>> {"white FM", "random-walk FM"} <= set(report.coefficients["Noise"]), sorted(report.q)
    (True, ['q1', 'q2', 'r'])
    >>> h0 = report.coefficients.set_index("alpha").loc[0, "h"]
    >>> bool(abs(h0 / 2e-22 - 1) < 0.05)   # white FM: h_0 = 2 sigma2 / rate
    True
    """
    from avar._validation import check_freq
    from avar.fit.gmwm import gmwm
    from avar.fit.gmwm.selection import select_model
    from avar.stability.allan.estimator import avar as allan_variance
    from avar.stability.classic.deviations import oadev
    from avar.stability.shared.grids import octave_factors

    rate = check_freq(rate, "rate")
    if not isinstance(data_type, str) or data_type not in ("phase", "freq"):
        raise ValueError(f"data_type must be 'phase' (time error, s) or 'freq', got {short_repr(data_type)}")
    confidence = check_confidence(confidence)
    if isinstance(B, bool) or not isinstance(B, (int, np.integer)) or B < 10:
        raise ValueError(f"B must be a whole number of bootstrap replicates >= 10, got {short_repr(B)}")
    chosen = tuple(PROCESSES) if processes is None else tuple(processes)
    unknown = [p for p in chosen if p not in PROCESSES]
    if unknown or not chosen:
        raise ValueError(f"processes must be some of {list(PROCESSES)}, got {short_repr(list(chosen))}")
    y = _frequency(x, rate, data_type)
    scale = float(np.std(y)) or 1.0  # GMWM works on numbers of order 1: fit y / scale, rescale the variances
    av = allan_variance(y / scale, rate=rate, taus=octave_factors(y.size) / rate)
    candidates = [" + ".join(c) for k in range(1, len(chosen) + 1) for c in itertools.combinations(chosen, k)]
    ranked = select_model(av, candidates)
    names = candidates[int(ranked.index[0])].split(" + ")  # ranked rows are indexed by candidate
    fit = gmwm(av, " + ".join(names), ci=True, B=int(B), confidence=confidence, seed=seed)
    rows = []
    for name in names:
        parameter = next(label for label in fit.ci.index if label.startswith(f"{name}."))
        estimate, lower, upper = (fit.ci.loc[parameter, c] * scale**2 for c in ("Estimate", "Lower", "Upper"))
        alpha, h = h_coefficient(name, estimate, rate)
        unit = H_OF_PROCESS[name][1](rate)
        rows.append((PROCESSES[name], alpha, h, max(lower, 0.0) * unit, upper * unit, name))
    coefficients = pd.DataFrame(rows, columns=["Noise", "alpha", "h", "Lower", "Upper", "Process"])
    coefficients = coefficients.sort_values("alpha", ascending=False, ignore_index=True)
    by_alpha = {int(r.alpha): r for r in coefficients.itertuples()}

    def interval(alpha: int, factor: float) -> tuple[float, float, float]:
        row = by_alpha.get(alpha)
        return (0.0, 0.0, 0.0) if row is None else (row.h * factor, row.Lower * factor, row.Upper * factor)

    q1 = interval(0, kalman_q(1.0, 0.0).q1)
    q2 = interval(-2, kalman_q(0.0, 1.0).q2)
    r = interval(2, rate / (8.0 * math.pi**2))  # sigma_x**2 = q2_QN / rate**2 = h_2 rate / (8 pi**2)
    kalman = pd.DataFrame([q1, q2, r], index=["q1", "q2", "r"], columns=["Value", "Lower", "Upper"])
    check = oadev(y, rate=rate, taus=av.taus, confidence=0.95)
    implied = np.sqrt(np.interp(check.taus, av.taus, fit.implied_av) * scale**2)
    in_band = float(np.mean((implied >= check.lci) & (implied <= check.uci)))
    warnings = []
    if in_band < FIT_SHARE:
        warnings.append(f"the model's deviation lies inside OADEV's 95 % band at only {in_band:.0%} of levels "
                        f"(want {FIT_SHARE:.0%}): a drift, a jump or a noise outside {list(PROCESSES.values())}?")
    return ClockReport(coefficients, kalman, fit, ranked, rate, int(y.size), confidence, in_band, tuple(warnings))
