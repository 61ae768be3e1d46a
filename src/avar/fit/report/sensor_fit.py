"""The noise model of a real sensor, its terms chosen by the data: :func:`fit_sensor_model`.

Real inertial sensors are not textbook sums of IEEE 952 power laws: their
Allan variance carries quantization, Gauss-Markov bumps and periodic
disturbances too. This module fits, to the maximal-overlap Allan variance
nu_hat_j at averaging factors m_j (octaves from m = 1), a sum of
independent processes whose Allan variances add::

    nu(m) = sum_k c_k g_k(m; s_k)

with c_k >= 0 a per-sample variance and g_k the process's Allan variance per
unit c_k (:mod:`avar.models`): QN 3 / m^2, WN 1 / m, FN flicker (exact),
RW (2 m^2 + 1) / (6 m), DR m^2 / 2, AR1 Zhang's form with shape phi, and a
sinusoid SIN with shape f (cycles per sample).

**Likelihood.** Each level is treated as a scaled chi-square,
nu_hat_j edf_j / nu_j ~ chi2(edf_j), independent across levels, so the
model is fitted by maximum likelihood, i.e. by minimizing the deviance::

    D = sum_j edf_j (r_j - 1 - log r_j),   r_j = nu_hat_j / nu_j,

which is zero for a perfect fit and close to chi2(L - p) for a right one.
With the shapes fixed the model is linear in c, and the maximum is found by
iteratively reweighted non-negative least squares (a Gamma GLM with identity
link: weights edf_j / nu_j^2 at the current fit), so a term the data do not
support gets c = 0 rather than a negative variance. The shapes are profiled:
a grid over correlation times / periods at the levels, then a local search.

**Selection.** Forward and backward, by the penalized deviance
``D + penalty * p`` (p the number of free parameters, ``penalty`` log of the
summed degrees of freedom by default, BIC's): start from the five IEEE terms
(those the non-negative fit zeroes drop out), add the Gauss-Markov or
sinusoid term that lowers the criterion most while one does (at most two AR1
and two SIN), or drop the term whose removal lowers it most, while one does.
A ramp is tried only beside a random walk (within one record a random walk
mimics a ramp, and the stochastic term is the one to report). Given a fit
check, terms are then added while the model fits fewer than 90 % of the
levels and an addition raises that share. Given the record's length, the
long-tau terms (random walk, a long Gauss-Markov term, flicker) are chosen
again before that, by their exact likelihood (:mod:`avar.fit.report.long_tau`).

edf_j = (N - 2 m_j + 1) / m_j, the nearly independent differences of level j (Percival & Walden 2000, 8.4).

References
----------
IEEE Std 952-1997, Annex C. S. Guerrier et al., "Wavelet-variance-based
estimation for composite stochastic processes", JASA 108(503), 2013.
P. McCullagh, J. A. Nelder, Generalized Linear Models, 1989, ch. 8 (Gamma deviance).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from avar.fit.report.long_tau import LONG_KINDS, choose_long_terms
from avar.fit.report.sandwich import independent_levels, parameter_covariance
from avar.fit.report.sensor_terms import KINDS, LINEAR, deviance, weight_edf
from avar.fit.terms import Component, basis

__all__ = ["SensorFit", "Enlarged", "fit_sensor_model", "enlarged_fit", "term_bound"]

#: How many of each shaped term a model may hold.
MAX_COPIES = {"AR1": 2, "SIN": 2}
#: Shape grid points per octave of correlation time / period.
GRID_PER_OCTAVE = 1
#: Rounds of stepwise selection and shape polishing.
PASSES = 3
#: Share of the levels that must fit (see :func:`avar.fit.report.checks.fit_check`).
FIT_SHARE = 0.90
#: Relative change of the model at which a scan's reweighting stops (rankings need no more).
SCAN_TOLERANCE = 1e-4


@dataclass(frozen=True, eq=False)
class SensorFit:
    """The selected model of one channel and its uncertainty.

    ``components``: the selected terms, in :data:`KINDS` order (AR1 by correlation time); ``covariance``: of
    (scales of every component, then the shapes of the shaped ones); ``factors``, ``nu_hat``, ``edf``: the data
    (averaging factors, Allan variances, their degrees of freedom); ``deviance``, ``criterion``: the fitted
    deviance and the penalized criterion that selected the model, of ``penalty`` per parameter; ``levels``: the
    covariance of the Allan variance estimates under the selected model
    (:func:`avar.fit.report.uncertainty.with_level_covariance`), None for independent levels of ``edf``.
    """

    components: tuple[Component, ...]
    covariance: np.ndarray
    factors: np.ndarray
    nu_hat: np.ndarray
    edf: np.ndarray
    deviance: float
    criterion: float
    penalty: float
    levels: np.ndarray | None = None

    def implied(self, m: np.ndarray | None = None) -> np.ndarray:
        """The model's Allan variance at ``m`` (default: the fitted factors)."""
        grid = self.factors if m is None else np.asarray(m)
        return sum((c.av(grid) for c in self.components), np.zeros(np.shape(grid)))

    def scale_variance(self, k: int) -> float:
        """Sampling variance of the scale of component ``k``."""
        return float(self.covariance[k, k])

    def shape_variance(self, k: int) -> float:
        """Sampling variance of the shape of component ``k`` (nan when it has none)."""
        if self.components[k].shape is None:
            return math.nan
        shaped = [j for j, c in enumerate(self.components) if c.shape is not None]
        at = len(self.components) + shaped.index(k)
        return float(self.covariance[at, at])

    @property
    def kinds(self) -> tuple[str, ...]:
        return tuple(c.kind for c in self.components)


def _irls(columns: np.ndarray, nu_hat: np.ndarray, edf: np.ndarray, iterations: int = 30,
          start: np.ndarray | None = None, tolerance: float = 1e-6) -> tuple[np.ndarray, float]:
    """Maximum-likelihood non-negative scales for fixed shapes: the scales and the deviance.

    ``start``: a model Allan variance to take the first weights from (default the data).
    """
    from scipy.optimize import nnls

    model = nu_hat.copy() if start is None else np.maximum(start, 1e-3 * nu_hat)
    scales = np.zeros(columns.shape[1])
    root = np.sqrt(edf)
    for _ in range(iterations):
        weight = root / np.maximum(model, 1e-6 * nu_hat)
        scales, _ = nnls(columns * weight[:, None], nu_hat * weight, maxiter=50 * columns.shape[1])
        updated = columns @ scales
        change = float(np.max(np.abs(updated - model) / np.maximum(model, 1e-300)))
        model = updated
        if change < tolerance:
            break
    return scales, deviance(nu_hat, model, edf)


class _Problem:
    """The data of one fit, and the deviance of any set of terms with given shapes."""

    def __init__(self, factors: np.ndarray, nu_hat: np.ndarray, edf: np.ndarray,
                 sampling_edf: np.ndarray | None = None) -> None:
        self.factors, self.nu_hat, self.edf = factors, nu_hat, edf
        self.sampling_edf = edf if sampling_edf is None else sampling_edf
        self._cache: dict[tuple, np.ndarray] = {}
        top = math.log2(max(float(factors[-1]), 2.0))
        exponents = np.arange(0.0, top + 1.0 / GRID_PER_OCTAVE, 1.0 / GRID_PER_OCTAVE)
        times = 2.0 ** exponents[(exponents >= 1.0) & (exponents <= top - 2.0)]
        self.grids = {"AR1": np.exp(-1.0 / times),                                 # phi of correlation time 2^e
                      "SIN": np.unique(np.clip(0.37 / 2.0**exponents, None, 0.45))}  # f peaking at m = 2^e
        self.phi_range = (math.exp(-0.5), math.exp(-4.0 / max(float(factors[-1]), 8.0)))
        # a sinusoid slower than the record is a ramp; faster than 2.2 samples, white noise
        self.f_range = (0.37 / max(float(factors[-1]), 1.0), 0.45)

    def column(self, kind: str, shape: float | None) -> np.ndarray:
        key = (kind, None if shape is None else round(float(shape), 15))
        found = self._cache.get(key)
        if found is None:
            found = basis(kind, shape, self.factors)
            if len(self._cache) > 4096:
                self._cache.clear()
            self._cache[key] = found
        return found

    def solve(self, terms: list[tuple[str, float | None]], start: np.ndarray | None = None,
              tolerance: float = 1e-6) -> tuple[np.ndarray, float]:
        columns = np.column_stack([self.column(kind, shape) for kind, shape in terms])
        return _irls(columns, self.nu_hat, self.edf, start=start, tolerance=tolerance)

    def model(self, terms: list[tuple[str, float | None]]) -> np.ndarray:
        """The fitted Allan variance of ``terms``."""
        scales, _ = self.solve(terms)
        return np.column_stack([self.column(kind, shape) for kind, shape in terms]) @ scales

    def regrid(self, terms: list[tuple[str, float | None]]) -> tuple[list[tuple[str, float | None]], float]:
        """Move each shaped term in turn to its best grid point, the others fixed."""
        terms = list(terms)
        value = self.solve(terms)[1]
        for k, (kind, shape) in enumerate(terms):
            if shape is None:
                continue
            base = self.model(terms[:k] + terms[k + 1:]) if len(terms) > 1 else None
            for trial in self.grids[kind]:
                moved = terms[:k] + [(kind, float(trial))] + terms[k + 1:]
                score = self.solve(moved, start=base, tolerance=SCAN_TOLERANCE)[1]
                if score < value:
                    terms, value = moved, score
        return terms, value

    def refine(self, terms: list[tuple[str, float | None]]) -> tuple[list[tuple[str, float | None]], float]:
        """Local search of the shapes (profiled deviance), from the given values."""
        from scipy.optimize import minimize

        shaped = [k for k, (_, shape) in enumerate(terms) if shape is not None]
        if not shaped:
            return terms, self.solve(terms)[1]

        def unpack(free: np.ndarray) -> list[tuple[str, float | None]]:
            out = list(terms)
            for k, u in zip(shaped, free):
                kind = terms[k][0]
                shape = math.exp(-math.exp(-u)) if kind == "AR1" else 0.5 / (1.0 + math.exp(-u))
                low, high = self.phi_range if kind == "AR1" else self.f_range
                out[k] = (kind, min(max(shape, low), high))
            return out

        def pack(values: list[tuple[str, float | None]]) -> np.ndarray:
            free = []
            for k in shaped:
                kind, shape = values[k]
                free.append(-math.log(-math.log(shape)) if kind == "AR1" else math.log(2 * shape / (1 - 2 * shape)))
            return np.array(free)

        def objective(free: np.ndarray) -> float:
            return self.solve(unpack(np.clip(free, -40.0, 40.0)))[1]

        start = pack(terms)
        at_start = objective(start)
        found = minimize(objective, start, method="Nelder-Mead",
                         options={"xatol": 1e-4, "fatol": 1e-6, "maxfev": 150 * len(shaped)})
        if found.fun < at_start:
            return unpack(np.clip(found.x, -40.0, 40.0)), float(found.fun)
        return unpack(np.clip(start, -40.0, 40.0)), at_start


def _size(terms: list[tuple[str, float | None]]) -> int:
    return sum(1 if shape is None else 2 for _, shape in terms)


def _ordered(terms: list[tuple[str, float | None]]) -> list[tuple[str, float | None]]:
    return sorted(terms, key=lambda t: (KINDS.index(t[0]), (t[1] or 0.0)))


def _additions(problem: _Problem, terms: list, kinds: tuple[str, ...], budget: int, linear: bool) -> list[tuple]:
    """(terms with one more, deviance): each shaped kind at its best grid point, each absent IEEE term (a ramp
    only beside a random walk, unless ``linear``)."""
    trials = []
    for kind in ("AR1", "SIN"):
        if kind not in kinds or sum(k == kind for k, _ in terms) >= MAX_COPIES[kind] or _size(terms) + 2 > budget:
            continue
        grid = problem.grids[kind]
        if grid.size == 0:
            continue
        base = problem.model(terms)
        scores = [problem.solve(terms + [(kind, float(s))], start=base, tolerance=SCAN_TOLERANCE)[1] for s in grid]
        trials.append((terms + [(kind, float(grid[int(np.argmin(scores))]))], min(scores)))
    extra = [k for k in LINEAR if k in kinds and (k, None) not in terms and (k != "DR" or linear or ("RW", None) in terms)]
    for kind in extra:
        if _size(terms) < budget:
            trials.append((terms + [(kind, None)], problem.solve(terms + [(kind, None)])[1]))
    return trials


def _stepwise(problem: _Problem, terms: list, kinds: tuple[str, ...], budget: int, penalty: float) -> list:
    """Add or drop one term at a time while the penalized deviance falls."""
    best = problem.solve(terms)[1] + penalty * _size(terms)
    while True:
        trials = _additions(problem, terms, kinds, budget, linear=False)
        for removal in range(len(terms)):
            rest = terms[:removal] + terms[removal + 1:]
            if rest:
                trials.append((rest, problem.solve(rest)[1]))
        if not trials:
            return terms
        candidate, value = min(trials, key=lambda t: t[1] + penalty * _size(t[0]))
        if value + penalty * _size(candidate) >= best - 1e-9:
            return terms
        terms, best = candidate, value + penalty * _size(candidate)


def _repair(problem: _Problem, terms: list, kinds: tuple[str, ...], budget: int,
            check: Callable[[np.ndarray], float]) -> list:
    """Add terms while the model fails the fit check and an addition raises the share of levels that fit."""
    share = check(problem.model(terms))
    while share < FIT_SHARE:
        scored = []
        for candidate, value in _additions(problem, terms, kinds, budget, linear=True):
            candidate, value = problem.refine(candidate)
            scored.append((check(problem.model(candidate)), -value, candidate))
        if not scored:
            break
        best_share, _, best = max(scored, key=lambda t: (t[0], t[1]))
        if best_share <= share:
            break
        terms, share = best, best_share
    return terms


def fit_sensor_model(factors: np.ndarray, nu_hat: np.ndarray, edf: np.ndarray, *, penalty: float | None = None,
                     kinds: tuple[str, ...] = KINDS, check: Callable[[np.ndarray], float] | None = None,
                     n_samples: int | None = None) -> SensorFit:
    """Select and fit the noise model of one channel (see the module docstring).

    Parameters
    ----------
    factors : ndarray of int
        Averaging factors m_j (samples), increasing.
    nu_hat : ndarray
        Maximal-overlap Allan variances at ``factors`` (> 0).
    edf : ndarray
        Degrees of freedom of every level.
    penalty : float, optional
        Criterion penalty per parameter (default: log of the summed edf).
    kinds : tuple of str
        The terms allowed (default all of :data:`~avar.fit.report.sensor_terms.KINDS`).
    check : callable, optional
        ``check(implied_av) -> share`` of the levels where a model fits the data. When the selected
        model's share is below 90 %, terms are added (each kind tried, the best share kept) while the
        share rises: the simplest model by the criterion, then as much more as the data demand.
    n_samples : int, optional
        The record's length N. Given, the long-tau terms of the selected model (FN, RW, a long
        Gauss-Markov term) are chosen again among all their subsets by the same criterion on the
        levels' exact likelihood, a candidate that passes ``check`` first
        (:func:`avar.fit.report.long_tau.choose_long_terms`).

    Returns
    -------
    SensorFit

    Examples
    --------
    >>> m = 2 ** np.arange(18)
    >>> nu = 1.0 / m + 1e-6 * (2.0 * m**2 + 1) / (6.0 * m)     # WN + RW, exact
    >>> fit = fit_sensor_model(m, nu, np.maximum((2**18 - 2 * m + 1) / m, 1.0))
    >>> fit.kinds, [round(c.scale, 9) for c in fit.components]
    (('WN', 'RW'), [1.0, 1e-06])
    """
    factors = np.asarray(factors, dtype=np.int64)
    nu_hat = np.asarray(nu_hat, dtype=np.float64)
    sampling_edf = np.maximum(np.asarray(edf, dtype=np.float64), 1.0)
    edf = weight_edf(sampling_edf)
    problem = _Problem(factors, nu_hat, edf, sampling_edf)
    penalty = math.log(float(np.sum(edf))) if penalty is None else float(penalty)
    budget = max(1, factors.size - 2)  # never more parameters than the levels support

    # a ramp only beside a random walk: within one record a random walk mimics a ramp, and the
    # stochastic term is the one to report unless the ramp adds to it
    linear = [(kind, None) for kind in LINEAR if kind in kinds and kind != "DR"]
    scales, _ = problem.solve(linear)
    terms = [t for t, c in zip(linear, scales) if c > 0] or [("WN", None)]
    for round_ in range(PASSES):  # stepwise on grid shapes, then polish the shapes; again while the terms change
        chosen = _stepwise(problem, terms, kinds, budget, penalty)
        unchanged = round_ > 0 and [k for k, _ in chosen] == [k for k, _ in terms]
        terms = chosen if unchanged else problem.refine(problem.regrid(chosen)[0])[0]
        if unchanged:
            break
    if n_samples is not None:  # the long taus: RW, long AR1 or FN, by their exact likelihood (long_tau.py)
        terms = choose_long_terms(problem, terms, int(n_samples), budget, penalty, check,
                                  tuple(k for k in LONG_KINDS if k in kinds)).terms
    if check is not None:
        terms = _repair(problem, terms, kinds, budget, check)
    terms = _ordered(terms)
    scales, current = problem.solve(terms)
    kept = [(t, c) for t, c in zip(terms, scales) if c > 0]
    components = tuple(Component(kind, float(c), shape) for (kind, shape), c in kept)
    covariance = parameter_covariance(components, factors, edf, independent_levels(components, factors, sampling_edf))
    return SensorFit(components=components, covariance=covariance, factors=factors, nu_hat=nu_hat, edf=sampling_edf,
                     deviance=current, criterion=current + penalty * _size([(c.kind, c.shape) for c in components]),
                     penalty=penalty)


class Enlarged(NamedTuple):
    """The selected model with more linear terms refitted: ``components``, their ``covariance``, its ``deviance``."""
    components: tuple[Component, ...]
    covariance: np.ndarray
    deviance: float


def enlarged_fit(fit: SensorFit, kinds: tuple[str, ...]) -> Enlarged:
    """The selected terms plus linear ``kinds``, scales refitted (non-negative maximum likelihood, shapes kept),
    and the sandwich covariance of (scales, shapes) around ``fit.levels`` (a scale the fit zeroes is floored at
    1e-300: the covariance at the boundary, where the added terms compete with the kept ones)."""
    problem = _Problem(fit.factors, fit.nu_hat, weight_edf(fit.edf))
    terms = [(c.kind, c.shape) for c in fit.components] + [(kind, None) for kind in kinds]
    scales, value = problem.solve(terms)
    floor = tuple(Component(k, max(float(c), 1e-300), s) for (k, s), c in zip(terms, scales))
    levels = independent_levels(floor, fit.factors, fit.edf) if fit.levels is None else fit.levels
    return Enlarged(floor, parameter_covariance(floor, fit.factors, weight_edf(fit.edf), levels), value)


def term_bound(fit: SensorFit, kind: str, level: float = 0.95) -> float:
    """One-sided upper bound of the per-sample variance of a linear term the model left out.

    The term is added to the selected model and the scales refitted (:func:`enlarged_fit`); the bound is
    c + z sqrt(Var c) with z the ``level`` normal quantile, from the sandwich covariance of the enlarged model.
    """
    from scipy.special import ndtri  # the normal quantile (scipy.stats takes 0.5 s to import)

    components, covariance, _ = enlarged_fit(fit, (kind,))
    at = len(components) - 1
    scale = components[at].scale if components[at].scale > 1e-300 else 0.0
    return scale + float(ndtri(level)) * math.sqrt(max(float(covariance[at, at]), 0.0))
