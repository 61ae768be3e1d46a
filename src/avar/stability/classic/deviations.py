"""The time-and-frequency deviation family: ADEV, OADEV, MDEV, TDEV, HDEV, OHDEV, TOTDEV, MHDEV, HTDEV.

Named and defined as in NIST SP 1065 (Riley 2008), Stable32 and
``allantools``. Every function validates its input once, computes the
variances in O(N) per level (:mod:`avar.stability.classic.core`, kernels in
:mod:`avar._kernels.classic.levels`), identifies the noise per level
(:func:`avar.stability.uncertainty.noise_id.identify_noise`) and bounds the deviation by
chi-squared with Greenhall's EDF (:mod:`avar.stability.uncertainty.edf`).

Conventions shared by all (x_i the phase in s, N phase points, tau0 = 1 /
rate, m the averaging factor, tau = m tau0):

* ``data_type="phase"``: the data are x_i. ``"freq"``: the data are the
  fractional frequency y_i, converted to phase as x = (0, cumsum(y)) tau0,
  as ``allantools.frequency2phase`` does (N = len(y) + 1).
* The levels are those with at least one term (NIST, Stable32);
  ``allantools`` drops the levels with a single term.
* Gaps: NaN values raise (``nan_policy="raise"``) or are skipped
  (``"omit"``): every term that touches a NaN (phase data: uses a missing
  point; frequency data: spans a missing value) is left out and ``n`` counts
  the terms used, as ``allantools.gradev`` does for ADEV. A level left with
  no term is dropped. The noise is then identified on the longest gap-free
  stretch, and the EDF is scaled by the fraction of the terms used (at least 1).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from avar.stability.classic.core import HADAMARD, OctaveMoments, deviation_levels_and_phase
from avar.stability.shared.deviation import Deviation
from avar.stability.shared.docstrings import fill_parameters
from avar.stability.shared.grids import deviation_factors
from avar.stability.shared.inputs import DEFAULT_CONFIDENCE, check_data, check_options, scaled
from avar.stability.shared.noise_types import ALPHA_PARAMETER, check_alpha
from avar.stability.shared.registry import MIN_PHASE_POINTS
from avar.stability.shared.term_counts import levels_with_terms
from avar.stability.uncertainty.chi2 import CATALOGUE_QUANTILES
from avar.stability.uncertainty.edf import chi2_bounds, estimator_edf, gap_scaled_edf
from avar.stability.uncertainty.noise_id import NOISE_ID_ESTIMATORS, identify_noise, octave_noise, phase_noise
from avar.stability.uncertainty.total_edf import totvar_bias


def _longest_stretch(values: np.ndarray) -> np.ndarray:
    """The longest run of finite values."""
    finite = np.concatenate(([False], np.isfinite(values), [False]))
    edges = np.flatnonzero(np.diff(finite.astype(np.int8)))
    starts, stops = edges[::2], edges[1::2]
    longest = int(np.argmax(stops - starts))
    return values[starts[longest] : stops[longest]]


def noise_exponents(estimator: str, values: np.ndarray, data_type: str, rate: float, factors: np.ndarray) -> np.ndarray:
    """Noise exponent per level from gap-free phase (the longest stretch when there are gaps)."""
    stretch = _longest_stretch(values) if np.isnan(values).any() else values
    if data_type == "freq":
        stretch = np.concatenate(([0.0], np.cumsum(stretch - stretch.mean()))) / rate
    alpha = np.zeros(factors.size, dtype=np.int64)
    fits = factors < stretch.size
    if stretch.size >= 4 and fits.any():
        alpha[fits] = identify_noise(stretch, factors[fits], estimator, from_frequency=data_type == "freq")
        alpha[~fits] = alpha[fits][-1]
    return alpha


def noise_of_levels(estimator: str, phase: np.ndarray | OctaveMoments, drift: float,
                     factors: np.ndarray, line: float | None) -> np.ndarray:
    """:func:`noise_exponents` of gap-free data from the detrended phase of the variances,
    or from the moments of the pyramid's levels; ``drift`` and ``line`` (None: frequency
    data) as in :func:`avar.stability.classic.core.phase_parts`."""
    if isinstance(phase, OctaveMoments):
        return octave_noise(phase.stats, phase.tails, factors, NOISE_ID_ESTIMATORS[estimator], drift, phase.phase,
                            phase.clusters)
    alpha = np.zeros(factors.size, dtype=np.int64)
    fits = factors < phase.size
    if phase.size >= 4 and fits.any():
        alpha[fits] = phase_noise(phase, factors[fits], NOISE_ID_ESTIMATORS[estimator], drift, line_free=True,
                                  line=line)
        alpha[~fits] = alpha[fits][-1]
    return alpha


def _estimate(estimator: str, data: Any, rate: Any, data_type: Any, taus: Any, confidence: Any,
              nan_policy: Any, alpha: Any = None, bias_correction: Any = False) -> Deviation:
    """Validate once, compute the variances, identify the noise (unless ``alpha`` fixes it), remove
    TOTVAR's bias, bound the deviation."""
    if not isinstance(bias_correction, (bool, np.bool_)):
        raise TypeError(f"bias_correction must be True or False, got {bias_correction!r}")
    fixed = check_alpha(alpha)
    rate = check_options(estimator, data, rate, data_type, confidence, nan_policy)
    drift_removed = estimator in HADAMARD and data_type == "freq"  # the scan finds the drift too
    values, scanned = check_data(data, data_type, nan_policy, weigh=drift_removed, statistic=estimator)
    n_missing = int(scanned.n_missing)
    n_phase = values.size + (data_type == "freq")
    needed = MIN_PHASE_POINTS[estimator] - (data_type == "freq")
    if values.size < needed:
        raise ValueError(f"data has {values.size} sample(s); {estimator} of {data_type} data needs at least {needed}")
    factors = deviation_factors(estimator, n_phase, rate, taus)
    values, scanned, exponent = scaled(values, scanned, drift_removed)
    variance, n, phase, drift, line = deviation_levels_and_phase(estimator, values, factors, data_type, rate, scanned)
    n, variance, factors, _ = levels_with_terms(estimator, n, variance, factors,
                                                f"the {n_missing} NaN value(s) of data" if n_missing else None)
    deviation = np.ldexp(np.sqrt(variance), exponent)
    if exponent:
        with np.errstate(over="ignore", under="ignore"):
            variance = np.ldexp(variance, 2 * exponent)
        if np.isinf(variance).any():  # an underflow is the correctly rounded variance (0 or subnormal)
            raise ValueError(f"the {estimator} variance of data of magnitude {2.0 ** exponent:.3g} is beyond the "
                             f"float64 range (the deviation reaches {deviation.max():.3g}); rescale the data, "
                             "e.g. to other units")
    if fixed is not None:
        alpha = np.full(factors.size, fixed, dtype=np.int64)
    elif n_missing:
        alpha = noise_exponents(estimator, values, data_type, rate, factors)
    else:  # the variances' own detrended phase: no second pass over the data
        alpha = noise_of_levels(estimator, phase, drift, factors, line)
    if bias_correction:
        bias = totvar_bias(alpha, factors, values.size)  # T = the record's count of points, as Stable32
        variance, deviation = variance / bias, deviation / np.sqrt(bias)
    edf = estimator_edf(estimator, alpha, factors, n_phase, n_given=values.size)
    if n_missing:
        edf = gap_scaled_edf(edf, n, estimator, n_phase, factors)
    lci, uci = chi2_bounds(deviation, edf, float(confidence), quantiles=CATALOGUE_QUANTILES)
    return Deviation(
        taus=factors / rate, averaging_factors=factors, deviation=deviation, variance=variance, n=n,
        alpha=alpha, edf=edf, lci=lci, uci=uci, estimator=estimator, data_type=data_type, rate=rate,
        n_samples=values.size, confidence=float(confidence),
    )


def adev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
         confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Allan deviation (non-overlapping), NIST SP 1065 eq. (7)::

        sigma_y^2(tau) = sum_{k} (x_{(k+2)m} - 2 x_{(k+1)m} + x_{km})^2 / (2 tau^2 n),

    with n = floor((N - 1) / m) - 1 terms (k = 0 .. n - 1) and m = 1 .. (N - 1) / 2.
    Dimensionless.
    {parameters}
    References
    ----------
    W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065, 2008.

    Examples
    --------
    >>> import avar
    >>> res = avar.adev([1.0, 3.0, 2.0, 4.0, 3.0, 5.0, 4.0])  # fractional frequency
    >>> res.averaging_factors.tolist(), res.n.tolist()
    ([1, 2], [6, 2])
    >>> res.deviation.round(6).tolist()  # sqrt((4 + 1 + 4 + 1 + 4 + 1) / (2 * 6)), ...
    [1.118034, 0.707107]
    """
    return _estimate("adev", data, rate, data_type, taus, confidence, nan_policy, alpha)


def oadev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
          confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Overlapping Allan deviation, NIST SP 1065 eq. (11)::

        sigma_y^2(tau) = sum_{i=0}^{N-2m-1} (x_{i+2m} - 2 x_{i+m} + x_i)^2 / (2 tau^2 (N - 2m)),

    n = N - 2m terms, m = 1 .. (N - 1) / 2. Dimensionless.
    {parameters}
    References
    ----------
    W. J. Riley, NIST SP 1065, 2008, section 5.2.4.

    Examples
    --------
    >>> import avar
    >>> res = avar.oadev([1.0, 3.0, 2.0, 4.0, 3.0, 5.0, 4.0], taus="all")
    >>> res.averaging_factors.tolist(), res.n.tolist()
    ([1, 2, 3], [6, 4, 2])
    >>> res.deviation.round(6).tolist()
    [1.118034, 0.707107, 1.118034]
    """
    return _estimate("oadev", data, rate, data_type, taus, confidence, nan_policy, alpha)


def mdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
         confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Modified Allan deviation, NIST SP 1065 eq. (14)::

        Mod sigma_y^2(tau) = sum_{j=0}^{N-3m} [sum_{i=j}^{j+m-1} (x_{i+2m} - 2 x_{i+m} + x_i)]^2 / (2 m^2 tau^2 (N - 3m + 1)),

    n = N - 3m + 1 terms, m = 1 .. N / 3. Dimensionless. Each level costs
    O(N): the inner sums are third differences of the running sum of x.
    {parameters}
    References
    ----------
    W. J. Riley, NIST SP 1065, 2008, section 5.2.5.

    Examples
    --------
    >>> import avar
    >>> res = avar.mdev([1.0, 3.0, 2.0, 4.0, 3.0, 5.0, 4.0], taus="all")
    >>> res.averaging_factors.tolist(), res.n.tolist(), res.deviation.round(6).tolist()
    ([1, 2], [6, 3], [1.118034, 0.707107])
    """
    return _estimate("mdev", data, rate, data_type, taus, confidence, nan_policy, alpha)


def tdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
         confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Time deviation, NIST SP 1065 eq. (15): sigma_x(tau) = tau / sqrt(3) Mod sigma_y(tau), in seconds.

    Same terms and levels as :func:`mdev`.
    {parameters}
    References
    ----------
    W. J. Riley, NIST SP 1065, 2008, section 5.2.6.

    Examples
    --------
    >>> import avar
    >>> res = avar.tdev([1.0, 3.0, 2.0, 4.0, 3.0, 5.0, 4.0], rate=2.0)
    >>> res.taus.tolist(), res.deviation.round(6).tolist()  # 0.5 s / sqrt(3) * 1.118034, ...
    ([0.5, 1.0], [0.322749, 0.408248])
    """
    return _estimate("tdev", data, rate, data_type, taus, confidence, nan_policy, alpha)


def hdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
         confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Hadamard deviation (non-overlapping), NIST SP 1065 eq. (18)::

        H sigma_y^2(tau) = sum_{k} (x_{(k+3)m} - 3 x_{(k+2)m} + 3 x_{(k+1)m} - x_{km})^2 / (6 tau^2 n),

    n = floor((N - 1) / m) - 2 terms, m = 1 .. (N - 1) / 3. Dimensionless;
    insensitive to a linear frequency drift.
    {parameters}
    References
    ----------
    W. J. Riley, NIST SP 1065, 2008, section 5.2.8.

    Examples
    --------
    >>> import avar
    >>> res = avar.hdev([1.0, 3.0, 2.0, 4.0, 3.0, 5.0, 4.0, 6.0])  # the drift is ignored
    >>> res.n.tolist(), res.deviation.round(6).tolist()
    ([6, 2], [1.224745, 0.0])
    """
    return _estimate("hdev", data, rate, data_type, taus, confidence, nan_policy, alpha)


def ohdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
          confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Overlapping Hadamard deviation, NIST SP 1065 eq. (20)::

        H sigma_y^2(tau) = sum_{i=0}^{N-3m-1} (x_{i+3m} - 3 x_{i+2m} + 3 x_{i+m} - x_i)^2 / (6 tau^2 (N - 3m)),

    n = N - 3m terms, m = 1 .. (N - 1) / 3. Dimensionless.
    {parameters}
    References
    ----------
    W. J. Riley, NIST SP 1065, 2008, section 5.2.9.

    Examples
    --------
    >>> import avar
    >>> res = avar.ohdev([1.0, 3.0, 2.0, 4.0, 3.0, 5.0, 4.0, 6.0], taus="all")
    >>> res.n.tolist(), res.deviation.round(6).tolist()
    ([6, 3], [1.224745, 0.0])
    """
    return _estimate("ohdev", data, rate, data_type, taus, confidence, nan_policy, alpha)


def totdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
           confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None,
           bias_correction: bool = True) -> Deviation:
    """Total deviation, NIST SP 1065 eq. (25)::

        Tot sigma_y^2(tau) = sum_{i=2}^{N-1} (x*_{i-m} - 2 x*_i + x*_{i+m})^2 / (2 tau^2 (N - 2)),

    with the phase extended by reflection at both ends, x*_{1-j} = 2 x_1 -
    x_{1+j} and x*_{N+j} = 2 x_N - x_{N-j} (j = 1 .. N - 2); n = N - 2 terms
    at every m = 1 .. N - 1 (the range where x* is defined, as
    ``allantools.totdev``; Stable32 stops at half the record). Dimensionless.
    {parameters}
    References
    ----------
    D. A. Howe, "The total deviation approach to long-term characterization of
    frequency stability", IEEE Trans. UFFC 47, 2000. W. J. Riley, NIST SP
    1065, 2008, section 5.2.11.

    Examples
    --------
    >>> import avar
    >>> res = avar.totdev([1.0, 3.0, 2.0, 4.0, 3.0, 5.0, 4.0], taus=[1, 6], bias_correction=False)
    >>> res.n.tolist(), res.deviation.round(6).tolist()
    ([6, 6], [1.118034, 1.096079])
    >>> avar.totdev([1.0, 3.0, 2.0, 4.0, 3.0, 5.0, 4.0], taus=[1, 6]).alpha.tolist()  # flicker FM: / (1 - a m / N)
    [-1, -1]
    """
    return _estimate("totdev", data, rate, data_type, taus, confidence, nan_policy, alpha, bias_correction)


def mhdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
          confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Modified Hadamard deviation, NIST SP 1065 section 5.2.10::

        Mod H sigma_y^2(tau) = sum_{j=0}^{N-4m} [sum_{i=j}^{j+m-1} (x_{i+3m} - 3 x_{i+2m} + 3 x_{i+m} - x_i)]^2
                               / (6 m^2 tau^2 (N - 4m + 1)),

    n = N - 4m + 1 terms, m = 1 .. N / 4. Dimensionless. Blind to a linear frequency
    drift, like HDEV, and, like MDEV, it tells white from flicker PM (its variance falls as
    tau^-3 and tau^-2). Each level costs O(N): the inner sums are fourth differences of the
    running sum of x. Noise identification as OHDEV's (lag-1 with up to three differences,
    B1 with this statistic's term count); EDF: Greenhall and Riley's algorithm for the
    modified Hadamard variance (d = 3, overlapping, phase averaged over m), which their
    paper covers (Stable32 does not compute this statistic).
    {parameters}
    References
    ----------
    S. Bregni and L. Jmoda, "Accurate estimation of the Hurst parameter of long-range
    dependent traffic using modified Allan and Hadamard variances", IEEE Trans.
    Communications 56, 2008. W. J. Riley, NIST SP 1065, 2008, section 5.2.10. C. A.
    Greenhall and W. J. Riley, "Uncertainty of stability variances based on finite
    differences", Proc. 35th PTTI, 2003.

    Examples
    --------
    >>> import avar
    >>> res = avar.mhdev([1.0, 3.0, 2.0, 5.0, 3.0, 4.0, 6.0, 2.0], taus="all")  # frequency: 9 phase points
    >>> res.n.tolist(), res.deviation.round(6).tolist()
    ([6, 2], [1.632993, 0.288675])
    """
    return _estimate("mhdev", data, rate, data_type, taus, confidence, nan_policy, alpha)


def htdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
          confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Hadamard time deviation: sigma_xH(tau) = tau / sqrt(10/3) Mod H sigma_y(tau), in seconds.

    What TDEV is to MDEV, HTDEV is to MHDEV (:func:`mhdev`: same terms, levels, noise and
    EDF): the factor makes it the standard deviation of the phase for white PM, whose
    Mod H sigma_y^2 is (10/3) sigma_x^2 / (m tau^2) (the weights 1, -3, 3, -1 of the four
    m-point phase sums: 1 + 9 + 9 + 1 = 20 = 6 (10/3)). Not in NIST SP 1065 nor Stable32:
    SigmaTau.jl (I. Lapinski) defines it, with this factor.
    {parameters}
    References
    ----------
    SigmaTau.jl, ``htdev`` (https://github.com/ianlap/SigmaTau.jl). W. J. Riley, NIST SP
    1065, 2008, sections 5.2.6 (TDEV) and 5.2.10 (MHDEV).

    Examples
    --------
    >>> import avar
    >>> res = avar.htdev([1.0, 3.0, 2.0, 5.0, 3.0, 4.0, 6.0, 2.0], rate=2.0)
    >>> res.taus.tolist(), res.deviation.round(6).tolist()  # 0.5 s / sqrt(10/3) * 1.632993, ...
    ([0.5, 1.0], [0.447214, 0.158114])
    """
    return _estimate("htdev", data, rate, data_type, taus, confidence, nan_policy, alpha)


_TOTDEV_BIAS = """    bias_correction : bool
        TOTVAR is biased low against the Allan variance for flicker and
        random-walk FM: E[TOTVAR] / AVAR = 1 - a tau / T, T = N tau0 (N the
        number of phase or frequency points given, as Stable32), a = 1 /
        (3 ln 2) and 3 / 4 (Howe 1999). ``True`` (default, as Stable32)
        divides by it at the levels whose alpha (identified or fixed) is
        -1 or -2; ``False`` gives the raw statistic, as ``allantools``.
"""
for _function in (adev, oadev, mdev, tdev, hdev, ohdev, totdev, mhdev, htdev):
    fill_parameters(_function, ALPHA_PARAMETER + (_TOTDEV_BIAS if _function is totdev else ""))
del _function
