"""MTIE, TIE rms and the parabolic deviation (PDEV), with the deviation family's signature.

Conventions as :mod:`avar.stability.classic.deviations` (x_i the phase in s, N phase
points, tau0 = 1 / rate, m the averaging factor, tau = m tau0; frequency data
y convert to x = (0, cumsum(y - mean y)) tau0 as ``allantools``). Every level
costs O(N) (:mod:`avar._kernels.time_error`); the levels are those with at
least one term. ``alpha=`` fixes the noise exponent of every level instead of
identifying it (as Stable32 allows). While a kernel is cold and the record short, its NumPy
twin answers (:func:`level_kernel`, :mod:`avar.stability.time_error.small`): nothing to compile.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from avar._kernels import time_error as kernels
from avar._kernels.runtime.paths import numpy_path
from avar.stability.classic.deviations import noise_exponents, noise_of_levels
from avar.stability.shared.deviation import Deviation
from avar.stability.shared.docstrings import fill_parameters
from avar.stability.shared.grids import grid_factors, largest_factor
from avar.stability.shared.inputs import DEFAULT_CONFIDENCE, check_data, check_not_tiny, check_options
from avar.stability.shared.noise_types import ALPHA_PARAMETER, check_alpha
from avar.stability.shared.term_counts import levels_with_terms
from avar.stability.time_error import small
from avar.stability.uncertainty.chi2 import CATALOGUE_QUANTILES
from avar.stability.uncertainty.edf import chi2_bounds, estimator_edf, gap_scaled_edf


class PreparedPhase(NamedTuple):
    """Gap-filled phase, the running count of missing values and the kernels' ``extra``."""

    phase: np.ndarray
    gaps: np.ndarray
    extra: int


def prepared_phase(values: np.ndarray, data_type: str, rate: float) -> PreparedPhase:
    """Gap-filled phase, the running count of missing values and the kernels' ``extra``.

    Phase data: gaps filled by linear interpolation (small increments), ``extra`` = 1.
    Frequency data: the mean removed, gaps set to 0, phase = (0, cumsum(y)) / rate, ``extra`` = 0.
    """
    missing = np.isnan(values)
    gaps = np.concatenate(([0], np.cumsum(missing, dtype=np.int64)))
    if data_type == "phase":
        phase = values
        if gaps[-1]:
            good = np.flatnonzero(~missing)
            phase = values.copy()
            phase[missing] = np.interp(np.flatnonzero(missing), good, values[good])
        return PreparedPhase(np.ascontiguousarray(phase, dtype=np.float64), gaps, 1)
    centred = np.where(missing, 0.0, values - np.nanmean(values))
    phase = np.concatenate(([0.0], np.cumsum(centred))) / rate
    return PreparedPhase(phase, gaps, 0)


def _estimate(statistic: str, data: Any, rate: Any, data_type: Any, taus: Any, confidence: Any,
              nan_policy: Any, alpha: Any) -> Deviation:
    rate = check_options(statistic, data, rate, data_type, confidence, nan_policy)
    fixed = check_alpha(alpha)
    values, scanned = check_data(data, data_type, nan_policy, statistic=statistic)
    if statistic != "mtie":  # a range needs no square
        check_not_tiny(statistic, scanned)
    n_phase = values.size + (data_type == "freq")
    if n_phase < 3:
        raise ValueError(f"data has {values.size} sample(s); {statistic} of {data_type} data needs at least "
                         f"{3 - (data_type == 'freq')}")
    largest = largest_factor(statistic, n_phase)
    factors = grid_factors(taus, rate, largest, first_octave=0,
                           context=f"of {statistic} (averaging factors 1..{largest} at rate = {rate:g} Hz "
                                   f"with {n_phase} phase points)")
    phase, gaps, extra = prepared_phase(values, data_type, rate)
    if statistic == "pdev":
        phase = _line_free(phase, gaps, extra)
    levels = level_kernel(statistic, phase, factors)
    if statistic == "mtie":
        # a window with a gap is skipped, so the filled values never reach a result
        deviation, n = levels(phase, factors, gaps, extra)
        with np.errstate(over="ignore"):  # an overflow is an error below
            variance = deviation**2
    else:
        with np.errstate(over="ignore"):  # the twins' squares overflow as the kernels' do: an error below
            sums, n = levels(phase, factors, gaps, extra)
        if statistic == "pdev":
            m = factors.astype(np.float64)
            scale = np.where(factors == 1, 2.0, m**4 / 72.0)
        else:
            m, scale = factors.astype(np.float64), 1.0
            if data_type == "freq":  # m = N: the one term spans the mean-removed data, zero by construction
                sums = np.where((factors == n_phase - 1) & (n > 0), 0.0, sums)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):  # overflow: an error below
            variance = sums / (scale * n)
        if statistic == "pdev":
            variance = variance / (m / rate) ** 2
        deviation = np.sqrt(variance)
    n, variance, factors, deviation = levels_with_terms(statistic, n, variance, factors,
                                                        f"the {int(gaps[-1])} NaN value(s) of data", deviation)
    alpha_levels = level_noise(fixed, values, phase, gaps, data_type, rate, factors)
    if statistic == "pdev":
        edf = pdev_edf(alpha_levels, factors, n_phase)
        if gaps[-1]:
            edf = gap_scaled_edf(edf, n, "oadev", n_phase, factors)
        lci, uci = chi2_bounds(deviation, edf, float(confidence), quantiles=CATALOGUE_QUANTILES)
    else:
        edf = lci = uci = np.full(factors.size, np.nan)
    return Deviation(
        taus=factors / rate, averaging_factors=factors, deviation=deviation, variance=variance, n=n,
        alpha=alpha_levels, edf=edf, lci=lci, uci=uci, estimator=statistic, data_type=data_type, rate=rate,
        n_samples=values.size, confidence=float(confidence),
    )


def level_kernel(statistic: str, phase: np.ndarray, factors: np.ndarray) -> Callable:
    """The levels' loop of ``statistic`` (``"mtie"``, ``"tierms"``, ``"pdev"`` or ``"gcodev"``): the
    compiled kernel of :mod:`avar._kernels.time_error`, or its NumPy twin
    (:mod:`avar.stability.time_error.small`: same arguments, same results) while the kernel is cold
    and the work (phase points times levels) small (:func:`avar._kernels.runtime.paths.numpy_path`).

    >>> from avar._kernels.runtime.paths import forced
    >>> with forced("numpy"):
    ...     level_kernel("mtie", np.zeros(4), np.array([1])).__module__
    'avar.stability.time_error.small'
    """
    kernel = getattr(kernels, f"{statistic.replace('gcodev', 'codev')}_levels")
    if numpy_path(small.TWIN_WORK[statistic] * phase.size * factors.size, small.TWIN_LIMIT, (kernel,), phase,
                  route=f"time_error.{statistic}"):
        return getattr(small, kernel.__name__)
    return kernel


def level_noise(fixed: int | None, values: np.ndarray, phase: np.ndarray, gaps: np.ndarray, data_type: str,
                rate: float, factors: np.ndarray) -> np.ndarray:
    """``alpha=`` at every level, or the noise identified as for OADEV (lag-1 autocorrelation, B1, R(n)).

    Gap-free data: on the phase less the line through its end points (B1 and
    R(n) are blind to a frequency offset; the lag-1 method removes its own line
    for frequency data and gets the line back for phase data, as Stable32),
    which spares the identification a least-squares fit.
    """
    if fixed is not None:
        return np.full(factors.size, fixed, dtype=np.int64)
    if gaps[-1]:
        return noise_exponents("oadev", values, data_type, rate, factors)
    ramp = np.linspace(phase[0], phase[-1], phase.size)
    slope = (phase[-1] - phase[0]) / (phase.size - 1) if data_type == "phase" else None  # phase data keep it
    return noise_of_levels("oadev", np.ascontiguousarray(phase - ramp), 0.0, factors, slope)


def pdev_edf(alpha: np.ndarray, factors: np.ndarray, n_phase: int) -> np.ndarray:
    """EDF of PDEV, approximated by Greenhall's EDF of a neighbour (no closed form is used here).

    At m = 1 PDEV is OADEV (its EDF exactly). Above, the EDF of OADEV (same
    span 2m and N - 2m terms) for FM noise (alpha <= 0) and that of MDEV for
    PM noise (alpha >= 1, where PDEV, like MDEV, averages the phase; 1 where
    m > N / 3, beyond MDEV's levels). Checked
    by simulation (``benchmarks/bench_catalogue.py``, N = 1024, 300 series
    per noise, m = 2 .. 128): the empirical EDF is within about 25 % of this
    one, which is mostly the lower (wider bounds).

    >>> pdev_edf(np.array([0, 0, 2]), np.array([1, 8, 8]), 1025).round(0).tolist()
    [801.0, 170.0, 158.0]
    """
    edf = estimator_edf("oadev", alpha, factors, n_phase)
    pm = (alpha >= 1) & (factors > 1)
    fits = pm & (3 * factors <= n_phase)  # MDEV's EDF exists for m <= N / 3; beyond it, 1 (the floor)
    if fits.any():
        edf[fits] = estimator_edf("mdev", alpha[fits], factors[fits], n_phase)
    edf[pm & ~fits] = 1.0
    return edf


def _line_free(phase: np.ndarray, gaps: np.ndarray, extra: int) -> np.ndarray:
    """The phase less its least-squares line (PDEV's weights cancel a line exactly): smaller terms."""
    if gaps[-1]:
        return phase
    index = np.arange(phase.size, dtype=np.float64)
    slope, intercept = np.polyfit(index - index.mean(), phase, 1)
    return np.ascontiguousarray(phase - intercept - slope * (index - index.mean()))


def mtie(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
         confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Maximum time interval error, the largest peak-to-peak phase excursion in a window of tau::

        MTIE(tau) = max_{i=0}^{N-m-1} [ max_{i <= k <= i+m} x_k - min_{i <= k <= i+m} x_k ],

    over every window of m + 1 phase points (n = N - m windows, m = 1 .. N - 1),
    in seconds (NIST SP 1065 section 5.2.14; ``allantools.mtie``, Stable32's
    "fast" MTIE). O(N) per level by the van Herk / Gil-Werman sliding
    extremum. ``variance`` is MTIE**2; no chi-squared bounds (``edf``,
    ``lci``, ``uci`` are NaN); ``alpha`` is informative only.
    {parameters}
    References
    ----------
    W. J. Riley, NIST SP 1065, 2008, section 5.2.14. S. Bregni, "Fast
    algorithms for TVAR and MTIE computation", IEEE Trans. Instrum. Meas. 2001.

    Examples
    --------
    >>> import avar
    >>> res = avar.mtie([0.0, 1.0, 3.0, 2.0, 2.5], data_type="phase", taus="all")
    >>> res.averaging_factors.tolist(), res.n.tolist(), res.deviation.tolist()
    ([1, 2, 3, 4], [4, 3, 2, 1], [2.0, 3.0, 3.0, 3.0])
    """
    return _estimate("mtie", data, rate, data_type, taus, confidence, nan_policy, alpha)


def tierms(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
           confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Time interval error rms::

        TIErms(tau) = sqrt( sum_{i=0}^{N-m-1} (x_{i+m} - x_i)**2 / (N - m) ),

    n = N - m terms, m = 1 .. N - 1, in seconds (NIST SP 1065 section 5.2.15;
    ``allantools.tierms``). No chi-squared bounds (``edf``, ``lci``, ``uci``
    are NaN); ``alpha`` is informative only.
    {parameters}
    References
    ----------
    W. J. Riley, NIST SP 1065, 2008, section 5.2.15.

    Examples
    --------
    >>> import avar
    >>> res = avar.tierms([0.0, 1.0, 3.0, 2.0, 2.5], data_type="phase", taus=[1, 4])
    >>> res.n.tolist(), res.deviation.round(6).tolist()  # sqrt((1 + 4 + 1 + 0.25) / 4), 2.5
    ([4, 1], [1.25, 2.5])
    """
    return _estimate("tierms", data, rate, data_type, taus, confidence, nan_policy, alpha)


def pdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
         confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Parabolic deviation (the deviation of the Omega counter's least-squares frequency)::

        PVAR(tau) = 72 / ((N - 2m) m**4 tau**2) sum_{i=0}^{N-2m-1} [ sum_{k=0}^{m-1} ((m - 1) / 2 - k) (x_{i+k} - x_{i+k+m}) ]**2

    for m >= 2, n = N - 2m terms, m = 1 .. (N - 1) / 2 (term i spans x_i ..
    x_{i+2m-1}, so the last phase point is unused, as in Vernotte et al. 2020
    and ``allantools.pdev``); at m = 1 the weights vanish and PDEV is OADEV
    at tau0, as ``allantools.pdev``. Dimensionless.
    Like MDEV it falls as tau**-3/2 for white PM, but it spans 2 tau, as ADEV.
    O(N) per level (the inner sums by a recurrence, recomputed every m steps).
    The chi-squared bounds use an approximation of PDEV's EDF, that of OADEV
    (FM noise) or MDEV (PM noise): :func:`pdev_edf`.
    {parameters}
    References
    ----------
    F. Vernotte, M. Lenczner, P.-Y. Bourgeois and E. Rubiola, "The parabolic
    variance (PVAR): a wavelet variance based on the least-square fit", IEEE
    Trans. UFFC 63(4), 2016. F. Vernotte et al., IEEE Trans. UFFC 67(8), 2020.

    Examples
    --------
    >>> import avar
    >>> res = avar.pdev([0.0, 1.0, 3.0, 2.0, 2.5, 4.0], data_type="phase", taus="all")
    >>> res.n.tolist(), res.deviation.round(6).tolist()
    ([4, 2], [1.286954, 0.9375])
    """
    return _estimate("pdev", data, rate, data_type, taus, confidence, nan_policy, alpha)


for _function in (mtie, tierms, pdev):
    fill_parameters(_function, ALPHA_PARAMETER)
del _function
