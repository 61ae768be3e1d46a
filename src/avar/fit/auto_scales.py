"""Automatic scale selection: where each noise process dominates an Allan deviation.

:func:`auto_scales` needs no user input. For every level j of the Allan
deviation it computes

* the **local log-log slope** s_j = d log AD / d log tau (central differences
  over the neighbouring levels, one-sided at the ends) and its standard error
  from the confidence band: the relative error e_j = 1 / sqrt(2 (N/m_j - 1))
  of AD_j is the standard deviation of log AD_j, so
  SE(s_j) = sqrt(e_{j-1}^2 + e_{j+1}^2) / (log tau_{j+1} - log tau_{j-1});
* the **share** of every process in the Allan variance, from the joint
  weighted fit of the IEEE 952 terms (:func:`avar.fit.noise_fit.fit_noise_terms`).

A process p (slope b_p: QN -1, WN -1/2, FN 0, RW +1/2, DR +1) is selected at
level j when its share is at least ``purity`` (default 0.8, so a fixed-slope
fit there is off by at most sqrt(1/0.8) - 1 = 12% in deviation) **and** the
local slope agrees with b_p within ``z`` standard errors plus the departure
of the fitted mixture's slope sum_q share_q b_q from b_p (the slope such a
level may show; a precise slope at small tau would otherwise reject a 99%
pure level for the 1% of another process). A process present in
the fit that is nowhere that pure gets the single level where its share is
largest, when it is the largest process there and the slope agrees.

The selections are 1-based scale numbers as everywhere in :func:`avar.avlr`
(``avar.avlr(x, wn="auto", rw="auto")`` or ``avar.avlr(x, auto=True)``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from avar._frozen import frozen_array, frozen_mapping
from avar.fit.noise_fit import TERM_SLOPES, TERMS, TermFit, fit_noise_terms
from avar.stability.allan.estimator import avar as allan_variance
from avar.stability.allan.results import AllanVariance

__all__ = ["AutoScales", "auto_scales", "level_edf", "local_slopes", "LocalSlopes"]


def level_edf(av: AllanVariance) -> np.ndarray:
    """Degrees of freedom of every level, N / m - 1 (R ``avar``'s errors: 1 / sqrt(2 edf))."""
    return np.maximum(av.n / av.averaging_factors.astype(np.float64) - 1.0, 1.0)


class LocalSlopes(NamedTuple):
    """The local log-log slope of the Allan deviation at every level and its standard error."""

    slope: np.ndarray
    se: np.ndarray


def local_slopes(tau: np.ndarray, adev: np.ndarray, errors: np.ndarray) -> LocalSlopes:
    """Local log-log slope of the Allan deviation and its standard error at every level.

    >>> tau = 2.0 ** np.arange(5)
    >>> slope, se = local_slopes(tau, 1 / np.sqrt(tau), np.full(5, 0.01))
    >>> slope.round(12).tolist()
    [-0.5, -0.5, -0.5, -0.5, -0.5]
    """
    log_tau, log_ad = np.log(tau), np.log(adev)
    n = tau.size
    if n < 2:
        return LocalSlopes(np.full(n, np.nan), np.full(n, np.inf))
    lower = np.r_[0, np.arange(n - 2), n - 2]
    upper = np.r_[1, np.arange(2, n), n - 1]
    span = log_tau[upper] - log_tau[lower]
    slope = (log_ad[upper] - log_ad[lower]) / span
    se = np.sqrt(errors[upper] ** 2 + errors[lower] ** 2) / span
    return LocalSlopes(slope, se)


@dataclass(frozen=True, eq=False)
class AutoScales:
    """Scales where each process dominates; build it with :func:`auto_scales`.

    Attributes
    ----------
    scales : Mapping[str, ndarray]
        Per process present (``QN``, ``WN``, ``FN``, ``RW``, ``DR``), its
        1-based scale numbers (possibly empty: present, nowhere dominant).
    slopes, slope_se : ndarray
        Local log-log slope of the AD at every level and its standard error.
    shares : Mapping[str, ndarray]
        Share of every present process in the fitted AV at every level.
    fit : TermFit
        The joint fit the shares come from.
    levels : ndarray
        tau (s) of the levels (the Allan variance's name of them).
    taus : ndarray
        (property) The same averaging times tau (s), under the name every result shares.
    """

    scales: Any
    slopes: np.ndarray
    slope_se: np.ndarray
    shares: Any
    fit: TermFit
    levels: np.ndarray

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        set_field(self, "scales", frozen_mapping({p: frozen_array(s, np.int64) for p, s in self.scales.items()}))
        set_field(self, "shares", frozen_mapping({p: frozen_array(s) for p, s in self.shares.items()}))
        for name in ("slopes", "slope_se", "levels"):
            set_field(self, name, frozen_array(getattr(self, name)))

    @property
    def taus(self) -> np.ndarray:
        """Averaging times tau (s) of the levels (the same as ``levels``)."""
        return self.levels

    def selection(self, processes: tuple[str, ...] = ("QN", "WN", "RW", "DR")) -> dict[str, np.ndarray]:
        """The non-empty selections of ``processes``, for :func:`avar.avlr`."""
        return {p: np.array(self.scales[p]) for p in processes if p in self.scales and len(self.scales[p])}

    def describe(self) -> str:
        """One line per process: its scales and tau range."""
        from avar.fit.slopes import format_scales

        parts = []
        for p, s in self.scales.items():
            if len(s):
                parts.append(f"{p}: scales {format_scales(s)} (tau {self.levels[s[0] - 1]:g} .. "
                             f"{self.levels[s[-1] - 1]:g} s)")
            else:
                parts.append(f"{p}: present, dominant nowhere")
        return "; ".join(parts) if parts else "no process detected"

    def __repr__(self) -> str:
        return f"<AutoScales {self.describe()}>"


def auto_scales(x: Any, purity: float = 0.8, z: float = 2.0, fit: TermFit | None = None) -> AutoScales:
    """Find the scales where each noise process dominates, with no user input.

    Parameters
    ----------
    x : AllanVariance or 1-D array_like
        An Allan variance, or a series (its default :func:`avar.avar`).
    purity : float
        Minimal share of the process in the fitted Allan variance, in (0, 1].
    z : float
        Width of the slope agreement band in standard errors (> 0).
    fit : TermFit, optional
        A joint fit of the same Allan variance, to reuse.

    Returns
    -------
    AutoScales

    Examples
    --------
    >>> import avar
    >>> x = (avar.WN(sigma2=1) + avar.RW(gamma2=1e-6)).simulate(100_000, seed=1)
    >>> sel = auto_scales(avar.avar(x))
    >>> {p: s.tolist() for p, s in sel.selection().items()}
    {'WN': [1, 2, 3, 4, 5, 6, 7, 8, 9], 'RW': [12, 13, 14, 15]}
    """
    av = x if isinstance(x, AllanVariance) else allan_variance(x)
    if isinstance(purity, bool) or not isinstance(purity, (int, float)) or not 0.0 < purity <= 1.0:
        raise ValueError(f"purity must be a number in (0, 1], got {purity!r}")
    if isinstance(z, bool) or not isinstance(z, (int, float)) or not z > 0:
        raise ValueError(f"z must be a number > 0 (standard errors), got {z!r}")
    if len(av) < 2:
        raise ValueError(f"x has an Allan variance of {len(av)} level(s); scale selection needs at least 2")
    if fit is None:
        fit = fit_noise_terms(av.levels, av.allan, level_edf(av))
    components = fit.component_av(av.levels)
    total = sum(components.values(), np.zeros(len(av)))
    safe = np.where(total > 0, total, np.inf)
    shares = {p: components[p] / safe for p in TERMS if p in components}
    slopes, se = local_slopes(av.levels, np.sqrt(np.maximum(av.allan, 1e-300)), av.errors)
    stacked = np.vstack(list(shares.values())) if shares else np.zeros((0, len(av)))
    scales = {}
    # the AD slope of the fitted mixture, sum_q share_q b_q: the slope a pure-enough level may show
    mixture = sum((share * TERM_SLOPES[p] for p, share in shares.items()), np.zeros(len(av)))
    for k, (p, share) in enumerate(shares.items()):
        agrees = np.abs(slopes - TERM_SLOPES[p]) <= z * se + np.abs(mixture - TERM_SLOPES[p])
        chosen = np.flatnonzero((share >= purity) & agrees) + 1
        if chosen.size == 0:
            best = int(np.argmax(share))
            if np.argmax(stacked[:, best]) == k and agrees[best]:
                chosen = np.array([best + 1])
        scales[p] = chosen
    return AutoScales(scales=scales, slopes=slopes, slope_se=se, shares=shares, fit=fit, levels=av.levels)
