"""Joint fit of the IEEE 952 noise terms to an Allan variance: :func:`fit_noise_terms`.

The Allan variance of a sum of independent processes is the sum of their
Allan variances (IEEE Std 952-1997, C.2), each linear in its squared
coefficient::

    AV(tau) = 3 Q^2 / tau^2 + N^2 / tau + (2 ln 2 / pi) B^2 + K^2 tau / 3 + R^2 tau^2 / 2

(quantization Q, white noise N, flicker / bias instability B, random walk K,
ramp R; ``TERMS``, the power laws of :mod:`avar.models`: each class's
``ieee_av`` and ``slope``). The squared coefficients are fitted at every level at
once by non-negative least squares, weighted by the inverse variance of each
level's estimate, Var AV(tau_j) = 2 model_j^2 / edf_j, iterated so that the
weights use the fitted model rather than the noisy estimate (which would
favour the levels that came out low). edf_j = N / m_j - 1, the degrees of
freedom of R ``avar``'s errors (1 / sqrt(2 (N / m - 1)) on the deviation).
A term whose coefficient is not at least ``z_present`` standard errors above
zero is *absent*: of the weak terms, the one whose removal raises the
weighted chi-square least is dropped (a weak ramp first: within one record
a random walk mimics a ramp, and the stochastic term is the one to report)
and the others refitted, until every term left is significant; so an absent process can neither be reported as a
noise value nor leak into the others.

References
----------
IEEE Std 952-1997, Annex C. D. W. Allan, "Statistics of atomic frequency
standards", 1966. N. El-Sheimy, H. Hou, X. Niu, "Analysis and modeling of
inertial sensors using Allan variance", IEEE TIM 57(1), 2008.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from avar.fit.terms import POWER_LAWS, process_class

__all__ = ["TERMS", "TERM_SLOPES", "term_regressors", "TermFit", "fit_noise_terms"]

#: Terms in IEEE order (by slope): quantization, white noise, flicker, random walk, ramp.
TERMS = tuple(cls.name for cls in POWER_LAWS)
#: Log-log slope of each term's Allan deviation.
TERM_SLOPES = {cls.name: cls.slope for cls in POWER_LAWS}


def term_regressors(tau: np.ndarray, terms: tuple[str, ...] = TERMS) -> np.ndarray:
    """Columns of AV(tau) per unit squared coefficient: 3/tau^2, 1/tau, 2 ln 2/pi, tau/3, tau^2/2 (``ieee_av``).

    >>> term_regressors(np.array([1.0, 2.0]), ("WN", "RW"))
    array([[1.        , 0.33333333],
           [0.5       , 0.66666667]])
    """
    tau = np.asarray(tau, dtype=np.float64)
    return np.column_stack([process_class(t).ieee_av(tau) for t in terms])


@dataclass(frozen=True)
class TermFit:
    """Squared coefficients of the terms fitted to one Allan variance.

    ``squared[t]`` is Q^2, N^2, B^2, K^2 or R^2 (0 for an absent term),
    ``variance[t]`` its sampling variance (0 when absent), ``present[t]``
    whether the term is in the model, and ``edf[t]`` the chi-squared degrees
    of freedom 2 squared^2 / variance of a present term.
    """

    squared: dict[str, float]
    variance: dict[str, float]
    present: dict[str, bool]
    tau: np.ndarray
    allan: np.ndarray

    def coefficient(self, term: str) -> float:
        """The coefficient sqrt(squared), 0 when absent."""
        return math.sqrt(self.squared[term])

    def edf(self, term: str) -> float:
        """Chi-squared degrees of freedom of the squared coefficient, 2 s^2 / Var(s)."""
        v = self.variance[term]
        return 2.0 * self.squared[term] ** 2 / v if v > 0 else math.inf

    def component_av(self, tau: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Allan variance of every present term at ``tau`` (default: the fitted levels)."""
        grid = self.tau if tau is None else np.asarray(tau, dtype=np.float64)
        present = tuple(t for t in TERMS if self.present[t])
        columns = term_regressors(grid, present) if present else np.zeros((grid.size, 0))
        return {t: columns[:, k] * self.squared[t] for k, t in enumerate(present)}

    def model_av(self, tau: np.ndarray | None = None) -> np.ndarray:
        """Sum of the terms' Allan variances (IEEE 952: the variances add)."""
        grid = self.tau if tau is None else np.asarray(tau, dtype=np.float64)
        return sum(self.component_av(grid).values(), np.zeros(grid.size))


def _weighted_nnls(design: np.ndarray, allan: np.ndarray, edf: np.ndarray, iterations: int) -> tuple:
    """Iteratively reweighted NNLS; returns the solution, its variances and the weighted chi-square."""
    from scipy.optimize import nnls

    model = allan.copy()
    solution = np.zeros(design.shape[1])
    for _ in range(iterations):
        # Var AV_j = 2 model_j^2 / edf_j; floor the model so a vanishing fit cannot blow a weight up
        scale = np.maximum(model, 1e-3 * allan) * np.sqrt(2.0 / edf)
        solution, _ = nnls(design / scale[:, None], allan / scale, maxiter=50 * design.shape[1])
        updated = design @ solution
        if np.allclose(updated, model, rtol=1e-6, atol=0.0):
            break
        model = updated
    scale = np.maximum(model, 1e-3 * allan) * np.sqrt(2.0 / edf)
    weighted = design / scale[:, None]
    covariance = np.linalg.pinv(weighted.T @ weighted)
    chi2 = float(np.sum(((allan - design @ solution) / scale) ** 2))
    return solution, np.diag(covariance), chi2


def fit_noise_terms(
    tau: np.ndarray,
    allan: np.ndarray,
    edf: np.ndarray,
    terms: tuple[str, ...] = TERMS,
    z_present: float = 3.0,
    iterations: int = 20,
) -> TermFit:
    """Weighted NNLS fit of the IEEE 952 terms to an Allan variance (see the module docstring).

    Parameters
    ----------
    tau, allan : ndarray
        Averaging times (s) and Allan variances (u^2) of the levels; levels
        with a non-finite or non-positive AV are left out.
    edf : ndarray
        Degrees of freedom of every level's estimate (e.g. N / m - 1).
    terms : tuple of str
        Candidate terms among ``TERMS``.
    z_present : float
        A term is kept when its squared coefficient is at least this many
        standard errors above zero (default 3: the standard errors treat the
        levels as independent, which the overlapping estimates are not, so 2
        lets a spurious term through in about half of long records).

    Returns
    -------
    TermFit

    Examples
    --------
    >>> tau = 2.0 ** np.arange(12)
    >>> av = 0.01 / tau + 1e-4 * tau / 3  # N = 0.1, K = 0.01, no noise
    >>> fit = fit_noise_terms(tau, av, np.full(12, 1e6))
    >>> round(fit.coefficient("WN"), 6), round(fit.coefficient("RW"), 6), fit.present["FN"]
    (0.1, 0.01, False)
    """
    tau = np.asarray(tau, dtype=np.float64)
    allan = np.asarray(allan, dtype=np.float64)
    edf = np.maximum(np.asarray(edf, dtype=np.float64), 1.0)
    usable = np.isfinite(allan) & (allan > 0) & np.isfinite(tau) & (tau > 0)
    if not usable.any():
        raise ValueError("the Allan variance has no finite positive level to fit the noise terms on")
    active = list(terms)
    squared = dict.fromkeys(TERMS, 0.0)
    variance = dict.fromkeys(TERMS, 0.0)
    while active:
        solution, variances, _ = _weighted_nnls(term_regressors(tau[usable], tuple(active)), allan[usable],
                                                edf[usable], iterations)
        z = solution / np.sqrt(np.maximum(variances, 1e-300))
        weak = [active[k] for k in range(len(active)) if z[k] < z_present]
        if not weak:
            squared.update(zip(active, solution.tolist()))
            variance.update(zip(active, variances.tolist()))
            break
        # backward elimination: drop the weak term whose removal worsens the fit least
        def chi2_without(term: str) -> float:
            rest = tuple(t for t in active if t != term)
            if not rest:
                return float(np.sum(edf[usable] / 2.0))
            return _weighted_nnls(term_regressors(tau[usable], rest), allan[usable], edf[usable], iterations)[2]

        active.remove("DR" if "DR" in weak else min(weak, key=chi2_without))
    present = {t: t in active for t in TERMS}
    return TermFit(squared=squared, variance=variance, present=present, tau=tau.copy(), allan=allan.copy())
