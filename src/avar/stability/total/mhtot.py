"""The modified Hadamard total deviation, MHTOTDEV.

No standard defines it (NIST SP 1065 and Stable32 stop at HTOTDEV); SigmaTau.jl introduced it as
the total (reflected-window) form of the modified Hadamard variance, and avar computes SigmaTau.jl's
definition (its default, half-means detrending), so the two libraries' numbers can be compared.
Same signature and :class:`~avar.stability.shared.deviation.Deviation` result as the rest of the
family; the level sums come from :mod:`avar._kernels.total.mhtot` (small levels by the direct
loop, large ones by the O(N) blocked expansion of :mod:`avar._kernels.total.mhtot_blocks`), or
while those kernels are not compiled yet, for short records, from their NumPy twin
(:mod:`avar.stability.total.small_mhtot`, through :func:`avar._kernels.runtime.paths.numpy_path`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from avar._kernels.runtime.paths import numpy_path
from avar._kernels.total.mhtot import level_kernels, level_sums, terms_per_window
from avar._kernels.total.windows import LevelSums
from avar.stability.classic.deviations import noise_exponents
from avar.stability.shared.deviation import Deviation
from avar.stability.shared.docstrings import fill_parameters
from avar.stability.shared.grids import largest_factor, total_factors
from avar.stability.shared.inputs import DEFAULT_CONFIDENCE
from avar.stability.shared.noise_types import ALPHA_PARAMETER, check_alpha
from avar.stability.shared.term_counts import levels_with_terms, term_counts
from avar.stability.total import small_mhtot
from avar.stability.total.deviations import prepared_phase
from avar.stability.uncertainty.chi2 import CATALOGUE_QUANTILES, chi2_bounds
from avar.stability.uncertainty.edf import estimator_edf

#: The statistic whose noise rules and EDF MHTOTDEV takes (see :func:`mhtotdev`).
REFERENCE = "mhdev"


def mhtotdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
             confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Modified Hadamard total deviation, as SigmaTau.jl defines it::

        Mod H tot var(tau) = 1 / (6 m^2 tau^2 (N - 4m + 1)) sum_{n=0}^{N-4m} [1 / (5m + 4) sum_{j=0}^{5m+3} A_j(n)^2],

    with A_j(n) = sum_{i=j}^{j+m-1} (e_i - 3 e_{i+m} + 3 e_{i+2m} - e_{i+3m}) the m-point
    sums of the third differences of e = (rev w, w, rev w): the 3m + 1 phase points x_n ..
    x_{n+3m} less the line through the means of their halves (the first floor((3m + 1) / 2)
    points and the rest), extended by uninverted even reflection to 9m + 3 points. tau = m
    tau0, m = 1 .. N / 4, n = N - 4m + 1 windows (MHDEV's term count). Dimensionless.

    What follows from the definition: each window is the MHDEV-type average of the
    reflected extension, as MTOTDEV is MDEV's (Howe and Vernotte 1999); a frequency offset
    cancels (each window's line takes it), a linear frequency drift does not (the
    reflected window keeps the curvature: remove the drift first, e.g.
    :func:`avar.remove_drift`). No bias correction is published, and none is applied (as
    SigmaTau.jl). No EDF law is published either: the bounds take :func:`avar.mhdev`'s
    (Greenhall and Riley's EDF of the modified Hadamard variance, d = 3, of the same N and
    m), the EDF of the non-total estimator of the same terms; a total estimator averages
    more (reflected) terms of the same windows, so its EDF is at least that of the plain
    one in the tau range where the extension adds information, and these bounds are
    conservative there. The noise is identified by MHDEV's rules (lag-1 with up to three
    differences, B1 with its term count). Each level costs O(N): its windows are summed in
    blocks, each block's sum expanded into sliding sums of the running sum of the phase
    (:mod:`avar._kernels.total.mhtot_blocks`; exact up to rounding, ~1e-13 from the direct
    O(N m) loop, which sums the small levels).
    {parameters}
    References
    ----------
    SigmaTau.jl, ``mhtotdev`` (https://github.com/ianlap/SigmaTau.jl, ``_mhtotdev_core``,
    ``detrend=:greenhall``). D. A. Howe and F. Vernotte, "Generalization of the total
    variance approach to the modified Allan variance", Proc. 31st PTTI, 1999. D. A. Howe et
    al., "A total estimator of the Hadamard function used for GPS operations", Proc. 32nd
    PTTI, 2000. W. J. Riley, NIST SP 1065, 2008, section 5.2.10 (MHDEV).

    Examples
    --------
    >>> import avar
    >>> res = avar.mhtotdev([0.0, 1.0, 0.0, 2.0, 0.0, 1.0, 3.0, 1.0], data_type="phase", taus="all")
    >>> res.n.tolist(), res.deviation.round(6).tolist()
    ([5, 1], [1.835857, 0.648181])
    """
    fixed = check_alpha(alpha)
    values, rate, x, bad, shift, scale, n_phase = prepared_phase("mhtotdev", data, rate, data_type, confidence,
                                                                 nan_policy)
    factors = total_factors("mhtotdev", n_phase, rate, taus)
    if factors.size == 0:
        raise ValueError(f"data has too few points for any mhtotdev level (largest factor "
                         f"{largest_factor('mhtotdev', n_phase)})")
    sums, counts = _level_sums(x, factors, bad, shift)
    m = factors.astype(np.float64)
    per_window = np.array([terms_per_window(f) for f in factors.tolist()], dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        variance = sums / (6.0 * m**4 * per_window * counts) / scale / scale
        if data_type == "phase":
            variance = variance * rate * rate
    variance[counts == 0] = np.nan
    n, variance, factors, _ = levels_with_terms("mhtotdev", counts, variance, factors,
                                                "the NaN values of data" if bad.size else None)
    if fixed is None:
        alphas = noise_exponents(REFERENCE, values, data_type, rate, factors)
    else:
        alphas = np.full(factors.size, fixed, dtype=np.int64)
    edf = estimator_edf(REFERENCE, alphas, factors, n_phase)
    if bad.size:
        edf = np.maximum(edf * n / term_counts("mhtotdev", n_phase, factors), 1.0)
    deviation = np.sqrt(variance)
    lci, uci = chi2_bounds(deviation, edf, float(confidence), quantiles=CATALOGUE_QUANTILES)
    return Deviation(taus=factors / rate, averaging_factors=factors, deviation=deviation, variance=variance, n=n,
                     alpha=alphas, edf=edf, lci=lci, uci=uci, estimator="mhtotdev", data_type=data_type, rate=rate,
                     n_samples=values.size, confidence=float(confidence))


fill_parameters(mhtotdev, ALPHA_PARAMETER)

#: The route of :func:`avar._kernels.runtime.paths.numpy_path` for MHTOTDEV's levels.
_LEVEL_ROUTE = "total.mhtot_levels"


def _level_sums(x: np.ndarray, factors: np.ndarray, bad: np.ndarray, shift: int) -> LevelSums:
    """The level sums and window counts: by the NumPy twin (:mod:`avar.stability.total.small_mhtot`)
    while the kernels the levels need are cold and the work is small, if it certifies its
    rounding; else compiled."""
    kernels = level_kernels(x.shape[0], factors, bool(bad.size))
    route = (_LEVEL_ROUTE, *(id(kernel) for kernel in kernels))
    if numpy_path(small_mhtot.TWIN_WORK * x.shape[0] * factors.size, small_mhtot.TWIN_LIMIT, kernels, route=route):
        twin = small_mhtot.level_sums(x, factors, bad, shift)
        if twin is not None:
            return twin
    return level_sums(x, factors, bad, shift)
