"""Model comparison for the joint estimator: :func:`select_model`."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pandas as pd

from avar.fit.gmwm.estimator import empirical_allan_variance, fit_allan_variance
from avar.fit.gmwm.model import parse_model
from avar.fit.gmwm.objective import equivalent_dof, fit_av

__all__ = ["select_model"]


def select_model(x: Any, candidates: Sequence[Any], *, taus: Any = "octave", penalty: float = 2.0) -> pd.DataFrame:
    """Rank candidate models by a penalized GMWM objective (a wavelet variance information criterion).

    Every candidate is fitted by :func:`avar.gmwm` (diagonal weights), then
    refitted from there with one weight matrix shared by all candidates, the
    data's: W = diag(1 / s_j^2), s_j = nu_hat_j sqrt(2 / edf_j), the estimated
    standard deviation of nu_hat_j (edf_j as in :mod:`avar.fit.gmwm.objective`).
    With a common W the objectives are comparable (a candidate's own weights
    would favour a model that predicts large variances where it fits badly,
    and a model nested in another can never reach a lower minimum). The
    criterion is::

        C = min_theta sum_j ((nu_hat_j - nu_j(theta)) / s_j)^2 + penalty * p

    with p the number of parameters. With W close to the inverse covariance
    of nu_hat, the fitted objective is approximately chi-square with L - p
    degrees of freedom, and the optimism penalty of the WVIC of Guerrier et al.
    (the trace of the product of W with the covariance of nu_hat and the fitted
    values, times 2) reduces to 2 p: C is its AIC-type form. Use
    ``penalty=np.log(N)`` for a BIC-type, more parsimonious choice.

    Parameters
    ----------
    x : array_like, pandas.Series or AllanVariance
        As for :func:`avar.gmwm`.
    candidates : sequence of models
        Two or more models in any form :func:`avar.gmwm` accepts.
    taus : "octave" or as in :func:`avar.avar`
        Scales, as for :func:`avar.gmwm`.
    penalty : float
        Penalty per parameter (>= 0), 2 by default.

    Returns
    -------
    pandas.DataFrame
        One row per candidate, best (smallest criterion) first: ``Model`` (the
        fitted model), ``Parameters``, ``Objective``, ``Criterion`` and
        ``Rank``, indexed by the candidate's position in ``candidates``.

    References
    ----------
    S. Guerrier, R. Molinari, Y. Stebler, "Wavelet-based improvements for
    inertial sensor error modeling", IEEE Trans. Instrum. Meas. 65(12), 2016
    (the WVIC). H. Akaike, 1974.

    Examples
    --------
    >>> from avar.models import AR1, RW, WN
    >>> x = (WN(sigma2=1.0) + RW(gamma2=1e-5)).simulate(50_000, seed=3)
    >>> table = select_model(x, ["WN", "WN + RW", "WN + RW + AR1"])
    >>> table["Parameters"].tolist(), int(table.index[0])
    ([2, 4, 1], 1)
    """
    if isinstance(candidates, (str, bytes)) or not isinstance(candidates, Sequence) or len(candidates) < 2:
        raise ValueError("candidates must be a list of two or more models, e.g. ['WN + RW', 'WN + RW + AR1']")
    penalty = float(penalty)
    if not (np.isfinite(penalty) and penalty >= 0):
        raise ValueError(f"penalty must be a finite number >= 0, got {penalty!r}")
    specs = [parse_model(model) for model in candidates]
    av = empirical_allan_variance(x, taus)
    factors = np.asarray(av.averaging_factors, dtype=np.int64)
    edf = equivalent_dof(av.n, factors, np.asarray(av.n_differences), av.type)
    whitener = 1.0 / (av.allan * np.sqrt(2.0 / edf))
    refits = []
    for spec in specs:
        first = fit_allan_variance(av, spec)
        refits.append(fit_av(spec, factors, av.allan, edf, "diagonal", starts=[spec.free(first.estimates.to_numpy())],
                             whitener=whitener))
    objective = np.array([refit.objective for refit in refits])
    sizes = np.array([spec.size for spec in specs])
    criterion = objective + penalty * sizes
    table = pd.DataFrame(
        {"Model": [repr(spec.model(refit.theta)) for spec, refit in zip(specs, refits)], "Parameters": sizes, "Objective": objective,
         "Criterion": criterion},
        index=pd.RangeIndex(len(specs), name="Candidate"),
    ).sort_values("Criterion", kind="stable")
    table["Rank"] = np.arange(1, len(specs) + 1)
    return table
