"""The long taus of a sensor model: rate random walk, a long Gauss-Markov term or flicker, by what the data support.

At the longest averaging times three terms compete, and a record of a few hours
tells them apart only through its last octaves: a random walk RW (the Allan
deviation rises as sqrt(tau) without end), a first-order Gauss-Markov term of
long correlation time T (it rises as sqrt(tau) for tau << T, peaks near
1.89 T, falls as 1 / sqrt(tau)), and flicker FN (flat). The stepwise selection
of :mod:`avar.fit.report.sensor_fit` weighs every level as independent, while
the last octaves are strongly correlated (80 % for a random walk): a few high
last levels count there as many independent pieces of evidence, and a curve
that flattens past 100 s was given a random walk that overshoots it (+107 %
at 328 s on a real accelerometer), with nothing to take the random walk out
again (the fit check's repair only adds terms).

**Comparison.** Keeping the other terms of the selected model (white noise,
quantization, sinusoids, short Gauss-Markov terms), every subset of
{FN, RW, AR1 of long T} is a candidate. Each is fitted by generalized least
squares on the log Allan variances, the GMWM objective with the levels'
**exact covariance** (:func:`~avar.fit.covariance.structure.structure_covariance`;
the last octaves of a random walk are 80 % correlated, which the independent
weighting ignores), the long correlation time free, and scored by::

    -2 log L = r' C^-1 r + log det C,   r_j = log(nu_hat_j / nu_j) - b_j,

the Gaussian likelihood of the log Allan variances. C and b are those of the
encompassing model (the other terms with FN, RW and the long AR1, fitted),
one weight matrix for every candidate, so that their objectives compare (and
log det C is common); its levels correlate as S does, each level a scaled
chi-square of k_j = 2 nu_j^2 / S_jj degrees of freedom: the mean of its log
b_j = psi(k_j / 2) - log(k_j / 2) and its variance psi'(k_j / 2) (digamma,
trigamma; a level of 2 degrees of freedom reads 0.58 low in log, with
variance 1.64, not the delta method's 1), plus the model discrepancy
(:data:`~avar.fit.report.sensor_terms.DISCREPANCY`) squared on the diagonal.
The criterion is the selection's, ``-2 log L + penalty p`` (Schwarz's, with
log of the summed degrees of freedom as the log of the number of observations):
only the likelihood changes, from independent levels to correlated ones. (The
L levels' log L, 2.7-2.9 per parameter, was tried: it let a Gauss-Markov term
of a few seconds stand for the flicker of 2 of 6 simulated 8-minute logs.)

Given a fit check (share of the levels where the implied deviation fits the
empirical band), a candidate that fits at least 90 % of the levels is
preferred to one that does not (a model the data reject is not admissible,
however few its parameters); among the admissible the criterion decides;
when none is admissible, the largest share does, and the report warns. The
selection's own long terms stand unless another admissible candidate's
criterion is lower by more than :data:`EVIDENCE` = 2 (twice the log Bayes
factor BIC approximates; below 2 the evidence is "not worth more than a bare
mention", Kass & Raftery 1995): a near tie does not overturn it. When the
choice leaves levels outside their band, a larger candidate (the chosen long
kinds and more) that fits more of them replaces it if a likelihood-ratio test
at 5 % supports the addition (each added variance on its boundary: 2.71 for
one; Self & Liang 1987). BIC's penalty (12.7 on a 2.8 h log) asks more of a term
seen at the last octaves than their few degrees of freedom can give, and their
log-normal law understates a high last level (tail 0.005 under the band's
chi-square, 0.03 under the normal): the band is the evidence of the miss.

Simulated 2.8 h logs at 100 Hz, 8 seeds each (white noise of N = 3.4e-4 /
sqrt(Hz), flicker of B = 6e-5, in g): with a Gauss-Markov term of sigma 2e-4
and T = 300 s, a random walk was selected on 3 of 8 before this comparison
(the implied deviation up to 6 times the last level's), 2 of 8 after; with a
random walk of K = 6e-6 / sqrt(s), it was kept on 8 of 8 before and after;
white + flicker alone gained none before or after.

**Cost.** The law is the one exact covariance of the comparison: computed once per fit (and
kept for a refit with the fit check, the same encompassing model), whitened once (``L^-1``,
C = L L'), and every candidate's generalized least squares runs on it with the scales'
Jacobian in closed form. The covariance's lag nodes are laid once per log length and grid
(:mod:`avar.fit.covariance.structure`): a 6-channel 2.8 h log's report went from 4.9 to 2.8 s
of CPU with them (``benchmarks/bench_report_speed.py``).

References
----------
G. Schwarz, "Estimating the dimension of a model", Ann. Statist. 6(2), 1978.
S. G. Self, K.-Y. Liang, "Asymptotic properties of maximum likelihood estimators and likelihood ratio
tests under nonstandard conditions", JASA 82(398), 1987.
R. E. Kass, A. E. Raftery, "Bayes factors", JASA 90(430), 1995.
S. Guerrier et al., "Wavelet-variance-based estimation for composite stochastic
processes", JASA 108(503), 2013 (the Allan variance's covariance in the GMWM
objective). N. El-Sheimy, H. Hou, X. Niu, "Analysis and
modeling of inertial sensors using Allan variance", IEEE Trans. Instrum. Meas.
57(1), 2008 (a Gauss-Markov term against rate random walk at long taus).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from avar.fit.covariance.structure import ACCURACY, structure_covariance
from avar.fit.report.checks import FIT_SHARE
from avar.fit.report.sensor_terms import DISCREPANCY
from avar.fit.terms import Component, basis

__all__ = ["LONG_KINDS", "LONG_OCTAVES", "LongTauChoice", "LogGaussian", "is_long_term", "choose_long_terms",
           "log_gaussian", "log_likelihood"]

#: The terms that compete at the long taus.
LONG_KINDS = ("FN", "RW", "AR1")
#: A Gauss-Markov term is a long-tau term when the peak of its Allan deviation, near 1.89 T, lies within
#: the last this many octaves of the levels (where a random walk or flicker would otherwise be read).
LONG_OCTAVES = 6
#: Where a Gauss-Markov bump of correlation time T (samples) peaks: m = 1.89 T.
PEAK = 1.89

#: Difference of the criterion (2 log of a Bayes factor) below which the selection's own long terms stand:
#: Kass & Raftery's "not worth more than a bare mention" (0 to 2).
EVIDENCE = 2.0
#: Level of the likelihood-ratio test a larger long-tau model must pass to replace a selection that misses levels.
SIGNIFICANCE = 0.05

Term = tuple[str, float | None]


class LongTauChoice(NamedTuple):
    """The chosen ``terms`` (kind, shape), their ``criterion`` (-2 log L + penalty p) and ``share`` of fitting levels (None
    without a check), and every candidate's (long kinds, criterion, share) in ``candidates``."""

    terms: list[Term]
    criterion: float
    share: float | None
    candidates: tuple[tuple[tuple[str, ...], float, float | None], ...]


def is_long_term(kind: str, shape: float | None, top_factor: float) -> bool:
    """Whether a term competes at the long taus: FN, RW, or AR1 peaking in the last :data:`LONG_OCTAVES` octaves.

    >>> is_long_term("AR1", math.exp(-1 / 30000), 2**18), is_long_term("AR1", math.exp(-1 / 2), 2**18)
    (True, False)
    """
    if kind in ("FN", "RW"):
        return True
    if kind != "AR1" or shape is None:
        return False
    return PEAK * (-1.0 / math.log(shape)) >= top_factor / 2.0**LONG_OCTAVES


def _log_moments(relative_variance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and variance of log(nu_hat / nu) for a scaled chi-square of k = 2 / relative variance degrees of
    freedom: psi(k / 2) - log(k / 2) and psi'(k / 2) (digamma, trigamma)."""
    from scipy.special import digamma, polygamma

    half = 1.0 / np.maximum(relative_variance, 1e-300)  # k / 2
    return digamma(half) - np.log(half), polygamma(1, half)


class LogGaussian(NamedTuple):
    """The log Allan variances' law under a model: ``bias`` (mean of log(nu_hat / nu)), ``covariance`` C and
    ``whiten`` = L^-1 (C = L L', so that |L^-1 r|^2 = r' C^-1 r), computed once for every candidate."""

    bias: np.ndarray
    covariance: np.ndarray
    whiten: np.ndarray


#: The last laws computed, by model, grid and length: a channel refitted with its fit check (the same
#: encompassing model) and the candidates of one fit share them.
_LAWS: dict[tuple, LogGaussian] = {}


def log_gaussian(components: tuple[Component, ...], factors: np.ndarray, n_samples: int) -> LogGaussian:
    """Mean and covariance of log(nu_hat / nu) under ``components`` (module docstring)."""
    key = (tuple((c.kind, c.scale, c.shape) for c in components), tuple(np.asarray(factors).tolist()), int(n_samples))
    found = _LAWS.get(key)
    if found is None:
        found = _LAWS[key] = _log_gaussian(components, factors, n_samples)
        while len(_LAWS) > 8:
            _LAWS.pop(next(iter(_LAWS)))
    return found


def _log_gaussian(components: tuple[Component, ...], factors: np.ndarray, n_samples: int) -> LogGaussian:
    nu = np.sum([c.av(factors) for c in components], axis=0)
    levels = structure_covariance(components, n_samples, factors) / np.outer(nu, nu)
    relative = np.maximum(np.diag(levels), 1e-300)
    spread = np.sqrt(relative)
    values, vectors = np.linalg.eigh(levels / np.outer(spread, spread))
    values = np.maximum(values, ACCURACY)  # directions the sums over lags do not resolve are not trusted
    correlation = (vectors * values) @ vectors.T
    unit = np.sqrt(np.diag(correlation))
    bias, variance = _log_moments(relative)
    spread = np.sqrt(variance)
    covariance = correlation / np.outer(unit, unit) * np.outer(spread, spread) + DISCREPANCY**2 * np.eye(nu.size)
    law = LogGaussian(bias, covariance, np.linalg.inv(np.linalg.cholesky(covariance)))
    for array in law:
        array.flags.writeable = False  # shared through _LAWS
    return law


def log_likelihood(components: tuple[Component, ...], factors: np.ndarray, nu_hat: np.ndarray,
                   n_samples: int, law: LogGaussian | None = None) -> float:
    """-2 log L of the log Allan variances under ``components`` with their exact covariance (module docstring);
    ``law``: their law to use instead of the model's own.

    >>> m = 2 ** np.arange(10)
    >>> right, wrong = (Component("WN", 1.0),), (Component("WN", 1.5),)
    >>> log_likelihood(right, m, 1.0 / m, 2**14) < log_likelihood(wrong, m, 1.0 / m, 2**14)
    True
    """
    nu = np.sum([c.av(factors) for c in components], axis=0)
    law = log_gaussian(components, factors, n_samples) if law is None else law
    residual = law.whiten @ (np.log(nu_hat / nu) - law.bias)
    logdet = -2.0 * float(np.sum(np.log(np.diag(law.whiten))))  # log det C = -2 log det L^-1
    return float(residual @ residual + logdet)


def _refit(components: tuple[Component, ...], factors: np.ndarray, nu_hat: np.ndarray, law: LogGaussian,
           time_range: tuple[float, float]) -> tuple[Component, ...]:
    """The scales (and a long AR1's correlation time, last) maximizing the likelihood under a fixed ``law``:
    generalized least squares on the log Allan variances (the GMWM step with the exact covariance)."""
    from scipy.optimize import least_squares

    whiten = law.whiten  # residuals and Jacobians whitened by a product
    shaped = components[-1].kind == "AR1" and is_long_term("AR1", components[-1].shape, float(factors[-1])) \
        and time_range[1] > time_range[0]
    start = [math.log(c.scale) for c in components]
    if shaped:
        start.append(math.log(min(max(-1.0 / math.log(components[-1].shape), time_range[0]), time_range[1])))

    def unpack(u: np.ndarray) -> tuple[Component, ...]:
        out = [Component(c.kind, math.exp(v), c.shape) for c, v in zip(components, u)]
        if shaped:
            out[-1] = Component("AR1", out[-1].scale, math.exp(-math.exp(-u[-1])))
        return tuple(out)

    columns = np.column_stack([basis(c.kind, c.shape, factors) for c in components])  # unit AVs, shapes fixed
    target = np.log(nu_hat) - law.bias

    def residual(u: np.ndarray) -> np.ndarray:
        scales = np.exp(u[:len(components)])
        if shaped:
            columns[:, -1] = basis("AR1", math.exp(-math.exp(-u[-1])), factors)
        return whiten @ (target - np.log(columns @ scales))

    def jacobian(u: np.ndarray) -> np.ndarray:
        """d residual / d u: the scales' columns in closed form, a long AR1's log correlation time by a
        forward difference."""
        scales = np.exp(u[:len(components)])
        if shaped:
            columns[:, -1] = basis("AR1", math.exp(-math.exp(-u[-1])), factors)
        model = columns @ scales
        out = np.empty((factors.size, len(u)))
        out[:, :len(components)] = -columns * scales / model[:, None]
        if shaped:
            step = 1e-6 * max(1.0, abs(float(u[-1])))
            moved = basis("AR1", math.exp(-math.exp(-(u[-1] + step))), factors) * scales[-1]
            out[:, -1] = -(np.log(model - columns[:, -1] * scales[-1] + moved) - np.log(model)) / step
        return whiten @ out

    # Scales stay within e**60 of their start (a term that vanishes reaches 1e-26 of it): an unbounded
    # step of the solver would overflow exp() on an ill-conditioned curve.
    low = np.array(start, dtype=float) - 60.0
    high = np.array(start, dtype=float) + 60.0
    if shaped:
        low[-1], high[-1] = math.log(time_range[0]), math.log(time_range[1])
    start = np.clip(np.array(start), low + 1e-9, high - 1e-9)
    found = least_squares(residual, start, jac=jacobian, bounds=(low, high), x_scale=1.0,
                          max_nfev=100 * len(start))
    better = found.x if float(np.sum(found.fun**2)) < float(np.sum(residual(start) ** 2)) else start
    return unpack(better)


def _long_start(problem: Any, rest: list[Term], top_factor: float) -> float | None:
    """The long correlation time's best grid point (as phi) beside ``rest``, by the deviance."""
    grid = [float(phi) for phi in problem.grids["AR1"] if is_long_term("AR1", float(phi), top_factor)]
    if not grid:
        return None
    base = problem.model(rest) if rest else None
    scores = [problem.solve(rest + [("AR1", phi)], start=base, tolerance=1e-4)[1] for phi in grid]
    return grid[int(np.argmin(scores))]


def _profiled(problem: Any, candidate: list[Term], top_factor: float) -> list[Term]:
    """The candidate with its long correlation time (its last term) at the deviance's minimum, the rest fixed."""
    from scipy.optimize import minimize_scalar

    low, high = _time_range(problem, top_factor)
    if not high > low:
        return candidate
    head = candidate[:-1]  # the long AR1 is the last term (LONG_KINDS order)

    def objective(log_time: float) -> float:
        return problem.solve(head + [("AR1", math.exp(-math.exp(-log_time)))], tolerance=1e-5)[1]

    start = -1.0 / math.log(candidate[-1][1])
    found = minimize_scalar(objective, bounds=(math.log(low), math.log(high)), method="bounded",
                            options={"xatol": 0.02})
    best = found.x if found.fun < objective(math.log(min(max(start, low), high))) else math.log(min(max(start, low), high))
    return head + [("AR1", math.exp(-math.exp(-best)))]


def _time_range(problem: Any, top_factor: float) -> tuple[float, float]:
    """Correlation times (samples) of a long Gauss-Markov term: from the long range's floor to the shape search's
    ceiling."""
    return top_factor / 2.0**LONG_OCTAVES / PEAK, -1.0 / math.log(problem.phi_range[1])


def _size(terms: list[Term]) -> int:
    return sum(1 if shape is None else 2 for _, shape in terms)


def choose_long_terms(problem: Any, terms: list[Term], n_samples: int, budget: int, penalty: float,
                      check: Callable[[np.ndarray], float] | None = None,
                      kinds: tuple[str, ...] = LONG_KINDS) -> LongTauChoice:
    """Replace the long-tau terms of ``terms`` by the subset of {FN, RW, long AR1} the data support best.

    Parameters
    ----------
    problem
        The fit's data and solver (:func:`~avar.fit.report.sensor_fit.fit_sensor_model`'s): ``factors``,
        ``nu_hat``, ``edf`` (weights), ``grids``, ``solve(terms)``, ``model(terms)``, ``refine(terms)``.
    terms : list of (kind, shape)
        The selected model.
    n_samples : int
        The record's length N (the levels' exact covariance depends on it).
    budget : int
        Most free parameters a model may hold.
    penalty : float
        The criterion's penalty per parameter (the selection's: log of the summed degrees of freedom).
    check : callable, optional
        ``check(implied_av) -> share`` of the levels that fit.
    kinds : tuple of str
        The long kinds allowed.

    Returns
    -------
    LongTauChoice
    """
    factors = np.asarray(problem.factors)
    top = float(factors[-1])
    long_ar1 = [t for t in terms if t[0] == "AR1" and is_long_term(t[0], t[1], top)]
    kept_long = max(long_ar1, key=lambda t: t[1]) if long_ar1 else None  # the longest; any other stays as it is
    rest = [t for t in terms if t[0] not in ("FN", "RW") and t is not kept_long]
    allowed = [k for k in LONG_KINDS if k in kinds]
    long_phi = kept_long[1] if kept_long is not None else None
    if "AR1" in allowed and long_phi is None:
        long_phi = _long_start(problem, rest, top)
    scored = []
    weights = _common_law(problem, rest, allowed, long_phi, n_samples, budget)
    for size in range(0 if rest else 1, len(allowed) + 1):
        for subset in itertools.combinations(allowed, size):
            if "AR1" in subset and long_phi is None:
                continue
            candidate = rest + [(k, long_phi if k == "AR1" else None) for k in subset]
            if _size(candidate) > budget:
                continue
            if "AR1" in subset:
                candidate = _profiled(problem, candidate, top)
            scales, _ = problem.solve(candidate)
            kept = [(t, c) for t, c in zip(candidate, scales) if c > 0]
            if not kept or len(kept) < len(candidate):
                continue  # a term the fit zeroes: the smaller candidate is scored on its own
            components = _refit(tuple(Component(kind, float(c), shape) for (kind, shape), c in kept), factors,
                                problem.nu_hat, weights, _time_range(problem, top))
            candidate = [(c.kind, c.shape) for c in components]
            criterion = log_likelihood(components, factors, problem.nu_hat, n_samples, weights)
            criterion += penalty * _size(candidate)
            # the check sees the model the report will give: these shapes, the scales of the fit's own likelihood
            share = None if check is None else check(problem.model(candidate))
            scored.append((candidate, criterion, share, subset))
    if not scored:
        return LongTauChoice(terms, math.nan, None, ())
    chosen = min(scored, key=_ranking)
    present = {kind for kind, _ in terms} | ({"AR1"} if kept_long is not None else set())
    incumbent = tuple(k for k in allowed if k in present and (k != "AR1" or kept_long is not None))
    held = [entry for entry in scored if entry[3] == incumbent]
    if held and _ranking(held[0])[0] == _ranking(chosen)[0] == 0 and held[0][1] - chosen[1] <= EVIDENCE:
        chosen = held[0]  # the selection's own long terms stand unless the data give positive evidence against
    if chosen[2] is not None and chosen[2] < 1.0:  # levels outside their band: a larger model fitting more, supported
        fitting = [entry for entry in scored if set(entry[3]) > set(chosen[3]) and entry[2] is not None
                   and entry[2] > chosen[2] and _supported(entry, chosen, penalty)]
        if fitting:
            chosen = max(fitting, key=lambda entry: (entry[2], -entry[1]))
    listed = tuple((subset, criterion, share) for _, criterion, share, subset in scored)
    return LongTauChoice(chosen[0], chosen[1], chosen[2], listed)


def _supported(larger: tuple, smaller: tuple, penalty: float) -> bool:
    """Whether -2 log of the likelihood ratio of ``larger`` to the nested ``smaller`` (scored entries) exceeds the
    chi-square(d) quantile 1 - 2 :data:`SIGNIFICANCE`, d the parameters added (a variance on its boundary: 2.71)."""
    from scipy.special import chdtri

    added = _size(larger[0]) - _size(smaller[0])
    ratio = smaller[1] - larger[1] + penalty * added  # the criteria less their penalties
    return added > 0 and ratio > float(chdtri(added, 2.0 * SIGNIFICANCE))


def _common_law(problem: Any, rest: list[Term], allowed: list[str], long_phi: float | None, n_samples: int,
                budget: int) -> LogGaussian:
    """The law of the log Allan variances under the encompassing model: the other terms with every long kind
    (the terms its fit zeroes left out)."""
    top = float(problem.factors[-1])
    full = rest + [(k, long_phi if k == "AR1" else None) for k in allowed if k != "AR1" or long_phi is not None]
    while _size(full) > budget and len(full) > 1:
        full = full[:-1]
    if any(k == "AR1" for k, _ in full[len(rest):]):
        full = _profiled(problem, full, top)
    scales, _ = problem.solve(full)
    kept = tuple(Component(kind, float(c), shape) for (kind, shape), c in zip(full, scales) if c > 0)
    return log_gaussian(kept, np.asarray(problem.factors), n_samples)


def _ranking(entry: tuple) -> tuple:
    """Admissible first (share >= 90 %, or no check), then the criterion; none admissible: the largest share."""
    _, criterion, share, _ = entry
    if share is None or share >= FIT_SHARE:
        return (0, criterion, 0.0)
    return (1, -share, criterion)
