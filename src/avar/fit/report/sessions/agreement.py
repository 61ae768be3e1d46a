"""Do several logs of one sensor agree? Bartlett's test on their Allan variances, level by level.

Under the hypothesis that the k logs record one stationary process (the
near-stationarity across replicates of the multi-signal GMWM, Bakalli et al. 2017,
Radi et al. 2019), the log i's Allan variance at averaging factor m is a scaled
chi-square, AV_i ~ AV(m) chi2(d_i) / d_i, with d_i Greenhall's equivalent
degrees of freedom for N_i samples at the noise type of the pooled model there
(the power-law exponent -1 - slope of its Allan variance, as for the report's band).
The k estimates of one level are independent (different logs), and Bartlett's
statistic for the homogeneity of variances with those degrees of freedom,

    M = D ln(AV_p) - sum_i d_i ln(AV_i),   AV_p = sum_i d_i AV_i / D,   D = sum_i d_i,
    C = 1 + (sum_i 1/d_i - 1/D) / (3 (k - 1)),

gives M / C ~ chi2(k - 1) (Bartlett 1937; Snedecor & Cochran, Statistical
Methods, 11.3). Every level of every channel is a test; the logs are declared in
disagreement when any p-value is below ``false_alarm / T``, T the number of tests
(Bonferroni): the probability of a false alarm over all channels and levels is at
most ``false_alarm`` (the levels of one log are positively correlated, which
makes the bound conservative).

Which log: after a rejection, each log is compared with the pool of the others at
the rejected levels, z_i = ln(AV_i / AV_(-i)) / sqrt(2 / d_i + 2 / D_(-i)); the
log of largest |z| is named, set aside, and the test is run again on the rest
(a closed-testing step: the subsets are tested only once their superset is
rejected, so the family-wise rate holds). With two logs left in disagreement,
both are named. The term named is the one of the pooled model that carries the
largest share of the Allan variance at that log's most deviant level.

The spread of a term between logs (:func:`term_spread`): the ratio max/min of the
per-log estimates, and the between-log standard deviation beyond sampling of
DerSimonian & Laird (1986) on the log scale, tau^2 = max(0, (Q - (k - 1)) /
(W - sum w_i^2 / W)), Q = sum w_i (y_i - ybar_w)^2, y_i = ln(term_i),
w_i = 1 / se_i^2, W = sum w_i: reported as a percentage (100 tau ~ the relative
standard deviation of the term between units).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from avar.fit.report.noise_terms import TERM_NAMES
from avar.stability.allan.results import AllanVariance

__all__ = ["AGREEMENT_COLUMNS", "Disagreement", "LevelTests", "agreement_table", "bartlett", "level_tests", "name_disagreeing",
           "term_spread"]

#: Columns of the agreement table.
AGREEMENT_COLUMNS = ["Channel", "Tau (s)", "m", "Statistic", "Dof", "P-value"]
SPREAD_COLUMNS = ["Channel", "Term", "Process", "Unit", "Logs", "Min", "Max", "Max/min", "Excess SD (%)", "Q",
                  "P-value"]
_OTHER_NAMES = {"AR1": "Gauss-Markov", "SIN": "Sinusoid"}


class LevelTests(NamedTuple):
    """The logs' Allan variances of one channel at their common levels, and their degrees of freedom."""

    channel: str
    factors: np.ndarray
    taus: np.ndarray
    values: np.ndarray
    edf: np.ndarray


class Disagreement(NamedTuple):
    """A log that disagrees with the others in one channel.

    ``ratio``: its Allan variance over the pool of the others at its most deviant level ``tau`` (s);
    ``term``: the pooled model's term that carries that level; ``p_value``: the smallest p-value
    of the test that rejected (before the Bonferroni correction); ``taus``: the rejected levels.
    """

    log: str
    channel: str
    term: str
    tau: float
    ratio: float
    p_value: float
    taus: tuple[float, ...]

    def describe(self) -> str:
        first, last = min(self.taus), max(self.taus)
        where = f"tau = {first:.3g} s" if first == last else f"tau = {first:.3g} .. {last:.3g} s"
        p = "p < 1e-16" if self.p_value < 1e-16 else f"p = {self.p_value:.2g}"
        return (f"{self.log}: disagrees with the other logs in channel {self.channel}, {self.term} "
                f"(Allan variance {self.ratio:.3g} x the others' at tau = {self.tau:.3g} s; rejected at {where}, "
                f"smallest {p})")


def bartlett(values: np.ndarray, edf: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bartlett's statistic M / C and its p-value (chi2 with k - 1 dof) per column of ``values`` (logs x levels).

    >>> import numpy as np
    >>> statistic, p = bartlett(np.array([[1.0], [1.0]]), np.array([[10.0], [30.0]]))
    >>> float(statistic[0]), float(p[0])
    (0.0, 1.0)
    """
    from scipy.stats import chi2

    values, edf = np.asarray(values, dtype=np.float64), np.asarray(edf, dtype=np.float64)
    k = values.shape[0]
    total = edf.sum(axis=0)
    pooled = (edf * values).sum(axis=0) / total
    m = total * np.log(pooled) - (edf * np.log(values)).sum(axis=0)
    c = 1.0 + ((1.0 / edf).sum(axis=0) - 1.0 / total) / (3.0 * (k - 1))
    statistic = np.maximum(m / c, 0.0)
    return statistic, chi2.sf(statistic, k - 1)


def level_tests(channel: str, avs: Sequence[AllanVariance], implied: Any) -> LevelTests:
    """The logs' Allan variances at the common levels and their EDF at the pooled model's noise types.

    ``implied`` maps averaging factors to the pooled model's Allan variance (``SensorFit.implied``).
    """
    from avar.stability.uncertainty.edf import greenhall_edf

    factors = np.array(sorted(set.intersection(*(set(np.asarray(av.averaging_factors).tolist()) for av in avs))),
                       dtype=np.int64)
    model = np.asarray(implied(factors), dtype=np.float64)
    slope = np.gradient(np.log(model), np.log(factors)) if factors.size > 1 else np.zeros(1)
    noise = np.where(slope < -1.5, 2, np.clip(np.rint(-1.0 - slope), -2, 1)).astype(np.int64)
    values, edf = [], []
    for av in avs:
        index = {int(m): i for i, m in enumerate(av.averaging_factors)}
        values.append(np.asarray(av.allan)[[index[int(m)] for m in factors]])
        edf.append(greenhall_edf(noise, 2, factors, av.n + 1, overlapping=av.type == "mo", modified=False))
    rate = float(np.mean([av.freq for av in avs]))
    return LevelTests(channel, factors, factors / rate, np.array(values), np.array(edf, dtype=np.float64))


def agreement_table(tests: LevelTests) -> pd.DataFrame:
    """One row per level: Bartlett's statistic, its degrees of freedom (k - 1) and p-value over all logs."""
    statistic, p = bartlett(tests.values, tests.edf)
    return pd.DataFrame({"Channel": tests.channel, "Tau (s)": tests.taus, "m": tests.factors,
                         "Statistic": statistic, "Dof": tests.values.shape[0] - 1, "P-value": p},
                        columns=AGREEMENT_COLUMNS)


def _term_at(fit: Any, kind: str | None, factor: int) -> str:
    """The pooled model's term with the largest Allan variance at ``factor``: its name and process."""
    shares = [float(np.asarray(c.av(np.array([factor])))[0]) for c in fit.components]
    if not shares:
        return "no term"
    process = fit.components[int(np.argmax(shares))].kind
    name = TERM_NAMES.get(kind, TERM_NAMES[None]).get(process) or _OTHER_NAMES.get(process, process)
    return f"{name.lower()} ({process})"


def name_disagreeing(tests: LevelTests, logs: Sequence[str], threshold: float, fit: Any,
                     kind: str | None) -> list[Disagreement]:
    """The logs that disagree in one channel, by the closed-testing steps of the module (p < ``threshold``)."""
    remaining = list(range(len(logs)))
    found: list[Disagreement] = []
    while len(remaining) >= 2:
        values, edf = tests.values[remaining], tests.edf[remaining]
        _, p = bartlett(values, edf)
        rejected = np.flatnonzero(p < threshold)
        if rejected.size == 0:
            break
        taus = tuple(float(t) for t in tests.taus[rejected])
        best, best_z, best_level, best_ratio = 0, -1.0, int(rejected[0]), 1.0
        for j in range(len(remaining)):
            others = [i for i in range(len(remaining)) if i != j]
            d_others = edf[others][:, rejected].sum(axis=0)
            pooled = (edf[others][:, rejected] * values[others][:, rejected]).sum(axis=0) / d_others
            ratio = values[j, rejected] / pooled
            z = np.abs(np.log(ratio)) / np.sqrt(2.0 / edf[j, rejected] + 2.0 / d_others)
            at = int(np.argmax(z))
            if z[at] > best_z:
                best, best_z, best_level, best_ratio = j, float(z[at]), int(rejected[at]), float(ratio[at])
        named = [best] if len(remaining) > 2 else [0, 1]
        for j in named:
            ratio = best_ratio if j == best else 1.0 / best_ratio
            found.append(Disagreement(logs[remaining[j]], tests.channel,
                                      _term_at(fit, kind, int(tests.factors[best_level])),
                                      float(tests.taus[best_level]), ratio, float(p[rejected].min()), taus))
        remaining = [i for k, i in enumerate(remaining) if k not in named]
    return found


def term_spread(channel: str, process: str, term: str, unit: str, values: np.ndarray,
                errors: np.ndarray) -> dict[str, Any]:
    """The spread of one term between logs: max/min, DerSimonian-Laird excess SD (%) on the log scale, Q, p.

    ``values``: the per-log estimates (positive); ``errors``: the standard errors of their logarithms.

    >>> import numpy as np
    >>> row = term_spread("gx", "WN", "Angle random walk", "rad/s/sqrt(Hz)", np.array([1.0, 1.0, 1.0]),
    ...                   np.array([0.01, 0.01, 0.01]))
    >>> row["Max/min"], row["Excess SD (%)"], row["P-value"]
    (1.0, 0.0, 1.0)
    """
    from scipy.stats import chi2

    logs = np.log(np.asarray(values, dtype=np.float64))
    weights = 1.0 / np.asarray(errors, dtype=np.float64) ** 2
    k = logs.size
    mean = float(weights @ logs / weights.sum())
    q = float(weights @ (logs - mean) ** 2)
    scale = float(weights.sum() - (weights @ weights) / weights.sum())
    tau2 = max(0.0, (q - (k - 1)) / scale) if scale > 0 else 0.0
    return {"Channel": channel, "Term": term, "Process": process, "Unit": unit, "Logs": k,
            "Min": float(np.min(values)), "Max": float(np.max(values)),
            "Max/min": float(np.max(values) / np.min(values)), "Excess SD (%)": 100.0 * float(np.sqrt(tau2)),
            "Q": q, "P-value": float(chi2.sf(q, k - 1)) if k > 1 else 1.0}
