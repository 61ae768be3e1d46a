"""The total and Theo statistics: MTOTDEV, TTOTDEV, HTOTDEV and Theo1.

Defined as in NIST SP 1065 (Riley 2008) and Stable32, with the signature and
:class:`~avar.stability.shared.deviation.Deviation` result of
:func:`avar.adev` ... :func:`avar.totdev` (see :mod:`avar.stability.classic.deviations`
for the shared conventions: frequency data become phase x = (0, cumsum(y))
tau0, NaN gaps, confidence), plus ``alpha`` to fix the noise type and
``bias_correction``. The variances come from the kernels of
:mod:`avar._kernels.total.windows` (which sends the long MTOTDEV and HTOTDEV levels to
the O(N) expansion of :mod:`avar._kernels.total.blocks`), or while those are not compiled
yet, for short records, from their NumPy twins (:mod:`avar.stability.total.small`); levels,
EDF and bias from :mod:`avar.stability.uncertainty.total_edf`.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from avar._kernels.classic.phase import PHASE_KERNELS
from avar._kernels.runtime.paths import numpy_path
from avar._kernels.total.fft import HANKEL_KERNELS, autocorrelation
from avar._kernels.total.theo1 import THEO1_KERNELS, theo1_sums
from avar._kernels.total.windows import THEO1_DIRECT_KERNELS, level_sums
from avar.stability.classic.core import phase_line, phase_parts
from avar.stability.classic.deviations import noise_exponents
from avar.stability.shared.deviation import Deviation
from avar.stability.shared.grids import largest_factor, total_factors
from avar.stability.shared.inputs import DEFAULT_CONFIDENCE, check_data, check_not_tiny, check_options
from avar.stability.shared.noise_types import ALPHA_PARAMETER, check_alpha
from avar.stability.shared.term_counts import levels_with_terms, term_counts
from avar.stability.total import small
from avar.stability.total.theobr import MIN_THEOBR_POINTS, theobr_factor
from avar.stability.uncertainty.chi2 import CATALOGUE_QUANTILES, chi2_bounds
from avar.stability.uncertainty.total_edf import MTOT_EDF, htot_bias, theo1_bias, total_edf

#: MTOTVAR / MVAR per noise type (Howe and Vernotte 1999; Riley, "CI2"), applied on request only.
MTOT_BIAS = {2: 0.94, 1: 0.83, 0: 0.73, -1: 0.70, -2: 0.69}
_KIND = {"mtotdev": 0, "ttotdev": 0, "htotdev": 1, "theo1": 2}
#: The noise identification rules each statistic follows: the totals' own (TOTDEV's lag-1 rule, B1 with
#: their term counts from 6 averages), as Stable32 (its tables of two records: the MDEV and OHDEV rules
#: miss its alpha where few terms remain); Theo1 OADEV's at 0.75 m.
_NOISE_RULES = {"mtotdev": "mtotdev", "ttotdev": "ttotdev", "htotdev": "htotdev", "theo1": "oadev"}
_MIN_PHASE = {"mtotdev": 3, "ttotdev": 3, "htotdev": 4, "theo1": 3, "mhtotdev": 4}

_PARAMETERS = """
    Parameters
    ----------
    data : array_like or pandas.Series
        1-D fractional frequency y (``data_type="freq"``) or phase x in
        seconds (``"phase"``); NaN marks a gap (see ``nan_policy``).
    rate : float, optional
        Sampling rate in Hz; tau0 = 1 / rate. Default: the rate of the regular
        time index of a pandas Series, else 1 Hz (as :func:`avar.oadev`).
    data_type : {"freq", "phase"}
    taus : {"octave", "decade", "all"} or array_like of float
        Averaging times (see :func:`avar.stability.uncertainty.total_edf.total_factors`).
    confidence : float
        Two-sided confidence level of ``lci``/``uci`` in (0, 1); one sigma (0.6827,
        Stable32's 0.683) by default.
    nan_policy : {"raise", "omit"}
        ``"omit"``: every term (window) touching a gap is skipped; ``n`` counts
        the terms used and the EDF is scaled by the fraction used.
{alpha}
    Returns
    -------
    Deviation
"""


def _check_bias(bias_correction: Any, estimator: str) -> bool | str | None:
    if estimator == "theo1" and (bias_correction is None or (isinstance(bias_correction, str)
                                                             and bias_correction == "theobr")):
        return bias_correction
    if not isinstance(bias_correction, (bool, np.bool_)):
        choices = "None, 'theobr', True or False" if estimator == "theo1" else "True or False"
        raise TypeError(f"bias_correction must be {choices}, got {bias_correction!r}")
    return bool(bias_correction)


class PreparedPhase(NamedTuple):
    """The validated data of a total deviation and the phase its kernels read (:func:`prepared_phase`)."""

    #: The data as validated (phase, s, or fractional frequency).
    values: np.ndarray
    #: Sampling rate (Hz).
    rate: float
    #: The detrended phase, scaled by ``scale`` (a power of two), gaps filled (contiguous float64).
    phase: np.ndarray
    #: The prefix count of the gaps (int64; empty without gaps), as the kernels take it.
    bad: np.ndarray
    #: 1 for frequency data (the phase has one point more than the data), else 0.
    shift: int
    scale: float
    n_phase: int


def prepared_phase(estimator: str, data: Any, rate: Any, data_type: Any, confidence: Any,
                   nan_policy: Any) -> PreparedPhase:
    """Validate once: the :class:`PreparedPhase`; its ``phase`` is the detrended phase (scaled by
    ``scale``, a power of two; HTOTDEV: its linear frequency drift removed too, as every statistic
    here is blind to it) with gaps filled, ``bad`` their prefix count."""
    rate = check_options(estimator, data, rate, data_type, confidence, nan_policy)
    values, scanned = check_data(data, data_type, nan_policy, statistic=estimator)
    check_not_tiny(estimator, scanned)
    needed = _MIN_PHASE.get(estimator, 3) - (data_type == "freq")
    if values.size < needed:
        raise ValueError(f"data has {values.size} sample(s); {estimator} of {data_type} data needs at least {needed}")
    kind = "ohdev" if estimator == "htotdev" else "oadev"
    n_increments = values.size - (data_type == "phase")
    if numpy_path(n_increments, small.PHASE_LIMIT, PHASE_KERNELS, route=_PHASE_ROUTE):
        # cold kernels: the kernel's phase, bit for bit (:func:`avar.stability.total.small.twin_phase`)
        filled, bad, _, centre, slope, scale = phase_line(values, data_type, kind, scanned)
        x = small.twin_phase(filled, int(data_type == "phase"), centre, slope, scale)
    else:
        x, _, scale, _, bad, *_ = phase_parts(values, data_type, kind, scanned)
    bad = np.zeros(0, dtype=np.int64) if bad is None else np.ascontiguousarray(bad, dtype=np.int64)
    return PreparedPhase(values, rate, np.ascontiguousarray(x), bad, int(data_type == "freq"), scale,
                         values.size + (data_type == "freq"))


def raw_variances(estimator: str, x: np.ndarray, factors: np.ndarray, bad: np.ndarray, shift: int,
                  scale: float, rate: float, is_phase: bool,
                  autocorr: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Unbiased-as-defined variances and term counts (NaN where no term is left); ``autocorr``:
    the FFT autocorrelation of gap-free ``x`` for Theo1, if at hand."""
    if estimator == "theo1" and autocorr is None and numpy_path(
            lambda: small.theo1_work(x.shape[0], factors) // small.THEO1_UNITS, small.THEO1_LIMIT,
            THEO1_KERNELS + HANKEL_KERNELS + THEO1_DIRECT_KERNELS, route=_THEO1_ROUTE):  # cold kernels: NumPy twin
        sums, counts = small.theo1_level_sums(x, factors, bad, shift)
    elif estimator == "theo1" and bad.size == 0:  # long levels by FFT (exact to ~1e-11)
        sums = theo1_sums(x, factors, small.theo1_direct(bad, shift), autocorr).sums
        counts = x.shape[0] - factors
    else:  # HTOTDEV's m = 1 is OHDEV (below): its level is not summed
        first = int(estimator == "htotdev" and factors.size > 0 and factors[0] == 1)
        sums, counts = _level_sums(_KIND[estimator], x, factors[first:], bad, shift)
        sums = np.concatenate((np.zeros(first), sums))
        counts = np.concatenate((np.zeros(first, dtype=counts.dtype), counts))
    m = factors.astype(np.float64)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # overflow: an error below
        if estimator == "htotdev":
            variance = sums / (6.0 * counts)
            if factors.size and factors[0] == 1:  # NIST, Stable32: OHDEV at m = 1
                variance[0], counts[0] = _ohvar1(x, bad, shift)
        elif estimator == "theo1":
            variance = sums / (0.75 * counts * m * m)
            counts = counts * (factors // 2)  # Stable32's count: the inner terms
        else:
            variance = sums / (2.0 * m * m * counts)
        variance = variance / scale / scale * (rate * rate if is_phase else 1.0)
    variance[counts == 0] = np.nan
    return variance, counts


def _level_sums(kind: int, x: np.ndarray, factors: np.ndarray, bad: np.ndarray,
                shift: int) -> tuple[np.ndarray, np.ndarray]:
    """MTOTDEV's (``kind`` 0) or HTOTDEV's (1) level sums and window counts: by the NumPy twin
    (:mod:`avar.stability.total.small`) while the kernels the levels need are cold and the work
    is small (:func:`avar._kernels.runtime.paths.numpy_path`) and the twin certifies its
    rounding, else compiled."""
    n_values = x.shape[0] - kind
    kernels = small.compiled_kernels(kind, n_values, factors, bool(bad.size))  # (a loop over the factors)
    route = (_LEVEL_ROUTE, *(id(kernel) for kernel in kernels))
    if kind < 2 and factors.size and numpy_path(small.TWIN_WORK * n_values * factors.size, small.TWIN_LIMIT,
                                                kernels, route=route):
        twin = small.level_sums(kind, x, factors, bad, shift)
        if twin is not None:
            return twin.sums, twin.n_terms
    return level_sums(kind, x, factors, bad, shift)


#: Routes of :func:`avar._kernels.runtime.paths.numpy_path` (found compiled once, never asked again).
_PHASE_ROUTE = "total.phase"
_LEVEL_ROUTE = "total.levels"
_THEO1_ROUTE = "total.theo1"


def _ohvar1(x: np.ndarray, bad: np.ndarray, shift: int) -> tuple[float, int]:
    """The overlapping Hadamard variance at m = 1 (in the units of ``x`` per sample)."""
    third = x[3:] - 3.0 * x[2:-1] + 3.0 * x[1:-2] - x[:-3]
    if bad.size:
        third = third[bad[4 - shift :] - bad[: third.size] == 0]
    if third.size == 0:
        return np.nan, 0
    return float(third @ third / (6.0 * third.size)), int(third.size)


def estimate(estimator: str, data: Any, rate: Any, data_type: Any, taus: Any, confidence: Any, nan_policy: Any,
             alpha: Any, bias_correction: Any) -> Deviation:
    """Validate, compute the variances, identify the noise, correct the bias, bound the deviation."""
    alpha = check_alpha(alpha)
    bias = _check_bias(bias_correction, estimator)
    if bias is None:  # Theo1 as Stable32: TheoBR's factor once the noise is fixed to other than white FM
        bias = "theobr" if alpha not in (None, 0) else False
    values, rate, x, bad, shift, scale, n_phase = prepared_phase(estimator, data, rate, data_type, confidence,
                                                                 nan_policy)
    factors = total_factors(estimator, n_phase, rate, taus)
    if factors.size == 0:
        raise ValueError(f"data has too few points for any {estimator} level (largest factor "
                         f"{largest_factor(estimator, n_phase)})")
    # Theo1 scaled by kf: one FFT autocorrelation of the record serves both
    autocorr = autocorrelation(x) if bias == "theobr" and bad.size == 0 else None
    variance, n = raw_variances(estimator, x, factors, bad, shift, scale, rate, data_type == "phase", autocorr)
    n, variance, factors, _ = levels_with_terms(estimator, n, variance, factors,
                                                "the NaN values of data" if bad.size else None)
    if alpha is None:
        noise_factors = np.maximum(1, np.round(0.75 * factors)).astype(np.int64) if estimator == "theo1" else factors
        alphas = noise_exponents(_NOISE_RULES[estimator], values, data_type, rate, noise_factors)
    else:
        alphas = np.full(factors.size, alpha, dtype=np.int64)
    if bias == "theobr":
        if bad.size or n_phase < MIN_THEOBR_POINTS:
            raise ValueError(f"theo1's TheoBR bias factor needs gap-free data of at least {MIN_THEOBR_POINTS} phase "
                             f"points (got {n_phase}{' with NaN' if bad.size else ''}); pass bias_correction=False "
                             "for the raw statistic or True for the fixed noise's correction")
        variance = variance * theobr_factor(x, autocorr).kf
    elif bias:
        variance = correct_bias(estimator, variance, alphas, factors)
    tau = (0.75 * factors if estimator == "theo1" else factors) / rate
    if estimator == "ttotdev":
        variance = variance * tau * tau / 3.0
    edf = total_edf(estimator, alphas, factors, n_phase, n_given=values.size)
    if bad.size:
        edf = np.maximum(edf * n / term_counts(estimator, n_phase, factors), 1.0)
    deviation = np.sqrt(variance)
    lci, uci = chi2_bounds(deviation, edf, float(confidence), quantiles=CATALOGUE_QUANTILES)
    return Deviation(taus=tau, averaging_factors=factors, deviation=deviation, variance=variance, n=n, alpha=alphas,
                     edf=edf, lci=lci, uci=uci, estimator=estimator, data_type=data_type, rate=rate,
                     n_samples=values.size, confidence=float(confidence))


def correct_bias(estimator: str, variance: np.ndarray, alpha: np.ndarray, factors: np.ndarray) -> np.ndarray:
    """Stable32's bias removal: HTOTVAR / (1 + a), Theo1 x AVAR/Theo1, MTOTVAR / (its MVAR ratio)."""
    if estimator == "htotdev":
        return variance / htot_bias(alpha, factors)
    if estimator == "theo1":
        return variance * theo1_bias(alpha, factors)
    return variance / np.array([MTOT_BIAS[int(a)] for a in alpha])


def mtotdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
            confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None,
            bias_correction: bool = False) -> Deviation:
    """Modified total deviation, NIST SP 1065 eq. (27)::

        Mod Tot var(tau) = 1 / (2 tau^2 (N - 3m + 1)) sum_{n=0}^{N-3m} [1 / (6m) sum_{j=0}^{6m-1} z_j(n)^2],

    with z_j(n) = (A_j - 2 B_j + C_j) / m the second difference of three
    adjacent m-point phase averages of x*(n): the 3m-point window x_n ..
    x_{n+3m-1} less the line through the means of its halves, extended at both
    ends by uninverted even reflection to 9m points. tau = m tau0, m = 1 .. N / 3,
    n = N - 3m + 1 terms. Dimensionless. The noise is identified by TOTDEV's
    lag-1 rule and, where few averages remain, B1 with n terms (as Stable32).
    EDF: the modified Allan variance's (Greenhall) below m = 10, as Stable32,
    then Stable32's b (N - 1) / m - c at white FM, flicker PM and flicker FM and
    NIST SP 1065 Table 8's b N / m - c at the other noises (see
    :func:`avar.stability.uncertainty.total_edf.total_edf`).
    ``bias_correction=True`` divides by MTOTVAR / MVAR (0.94, 0.83, 0.73, 0.70,
    0.69 for alpha = 2 .. -2), as Stable32 when its bias removal is on; its
    default and ``allantools`` do not (default False).
    Each level costs O(N) (the blocked expansion of :mod:`avar._kernels.total.blocks`
    over the runs of windows that avoid the gaps, exact up to rounding; small
    levels take the direct O(N m) loop, cheaper there).
    {parameters}
    References
    ----------
    D. A. Howe and F. Vernotte, "Generalization of the total variance approach
    to the modified Allan variance", Proc. 31st PTTI, 1999. W. J. Riley, NIST
    SP 1065, 2008, section 5.2.12.

    Examples
    --------
    >>> import avar
    >>> res = avar.mtotdev([0.0, 1.0, 0.0, 2.0, 0.0, 1.0], data_type="phase", taus="all")
    >>> res.n.tolist(), res.deviation.round(6).tolist()
    ([4, 1], [1.541104, 0.220625])
    """
    return estimate("mtotdev", data, rate, data_type, taus, confidence, nan_policy, alpha, bias_correction)


def ttotdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
            confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None,
            bias_correction: bool = False) -> Deviation:
    """Time total deviation, NIST SP 1065 eq. (28): sigma_x^2(tau) = tau^2 / 3 Mod Tot var(tau), in seconds.

    Same terms, levels, noise identification and EDF as :func:`mtotdev`.
    {parameters}
    References
    ----------
    W. J. Riley, NIST SP 1065, 2008, section 5.2.13 (its tau^3 is a misprint for tau^2).

    Examples
    --------
    >>> import avar
    >>> res = avar.ttotdev([0.0, 1.0, 0.0, 2.0, 0.0, 1.0], rate=2.0, data_type="phase", taus="all")
    >>> res.taus.tolist(), res.deviation.round(6).tolist()  # 0.5 s / sqrt(3) * MTOTDEV
    ([0.5, 1.0], [0.889757, 0.254756])
    """
    return estimate("ttotdev", data, rate, data_type, taus, confidence, nan_policy, alpha, bias_correction)


def htotdev(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
            confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None,
            bias_correction: bool = True) -> Deviation:
    """Hadamard total deviation, NIST SP 1065 eq. (29)::

        Htot var(tau) = 1 / (6 (M - 3m + 1)) sum_{n=0}^{M-3m} [1 / (6m) sum_{j=0}^{6m-1} H_j(n)^2],

    on the M = N - 1 fractional frequencies y, with H_j(n) = ybar_j - 2
    ybar_{j+m} + ybar_{j+2m} of m-point averages of y*(n): the window y_n ..
    y_{n+3m-1} less the line through the means of its halves, extended by
    uninverted even reflection to 9m points. At m = 1 the overlapping Hadamard
    variance is used (NIST, Stable32). n = N - 3m terms, m = 1 .. (N - 1) / 3.
    Insensitive to a linear frequency drift. Dimensionless.
    ``bias_correction=True`` (default, Stable32) divides by E[Htot var] / Hvar
    = 1 + a for m > 1, a = -0.005, -0.149, -0.229 for alpha = 0, -1, -2 (none
    for PM noise); ``allantools`` applies none. Noise identified as for
    :func:`mtotdev`. EDF: NIST SP 1065 Table 5's plus 2 below m = 16 and at PM,
    then (N / m) / (b0 + b1 m / N) (see :func:`avar.stability.uncertainty.total_edf.total_edf`),
    as Stable32's printed bounds.
    Each level costs O(N), as :func:`mtotdev`.
    {parameters}
    References
    ----------
    D. A. Howe, R. L. Beard, C. A. Greenhall, F. Vernotte and W. J. Riley, "A
    total estimator of the Hadamard function used for GPS operations", Proc.
    32nd PTTI, 2000. W. J. Riley, NIST SP 1065, 2008, section 5.2.14.

    Examples
    --------
    >>> import avar
    >>> y = [1.0, 3.0, 2.0, 5.0, 3.0, 4.0, 6.0]
    >>> res = avar.htotdev(y, taus="all", bias_correction=False)
    >>> res.n.tolist(), res.deviation.round(6).tolist()
    ([5, 2], [1.414214, 0.584984])
    """
    return estimate("htotdev", data, rate, data_type, taus, confidence, nan_policy, alpha, bias_correction)


def theo1(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
          confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None,
          bias_correction: bool | str | None = None) -> Deviation:
    """Theo1 deviation, NIST SP 1065 eq. (30), at tau = 0.75 m tau0 with m even::

        Theo1(m) = 1 / (0.75 (N - m) (m tau0)^2) sum_{i=0}^{N-m-1} sum_{d=0}^{m/2-1}
                   [(x_i - x_{i-d+m/2}) + (x_{i+m} - x_{i+d+m/2})]^2 / (m/2 - d),

    m = 2, 4, ... <= N - 1, n = (N - m) m / 2 terms (Stable32's ``Thêo1 #``). Dimensionless. Unbiased
    against the Allan variance for white FM only. ``bias_correction``: None
    (default, as Stable32) gives the raw statistic, as NIST SP 1065 and
    ``allantools`` (which reports it at tau = m tau0), unless ``alpha`` fixes
    the noise to other than white FM, where it multiplies every level by
    TheoBR's factor kf of the data (:func:`avar.stability.total.theobr.theobr_factor`;
    Stable32's tables of two records, alpha = 1 and -1, print exactly this);
    ``"theobr"`` always does; ``True`` multiplies by the fixed noise's AVAR /
    Theo1 = a + b / r^c, r = 0.75 m (Howe and Tasset 2004; white PM 0.09, 0.74,
    0.40; flicker PM 0.14, 0.82, 0.30; white FM 1; flicker FM 1.87, -1.05, 0.79;
    random-walk FM 2.70, -1.53, 0.85); ``False`` never corrects.
    The noise is identified at the factor 0.75 m by the OADEV rules; EDF:
    Howe and Tasset (see :func:`avar.stability.uncertainty.total_edf.total_edf`). Each
    level costs O(N m / 2) directly; long levels of gap-free data are expanded into the
    record's FFT autocorrelation and the autocorrelations of its ends (O(m log m) per
    level after O(N log N) shared work, see :mod:`avar._kernels.total.theo1`) wherever
    that keeps 1e-11 relative accuracy.
    {parameters}
    References
    ----------
    D. A. Howe and T. K. Peppler, "Very long-term frequency stability:
    estimation using a special-purpose statistic", Proc. 2003 IEEE FCS. D. A.
    Howe and T. N. Tasset, "Theo1: characterization of very long-term
    frequency stability", Proc. 18th EFTF, 2004. W. J. Riley, NIST SP 1065,
    2008, section 5.2.15.

    Examples
    --------
    >>> import avar
    >>> res = avar.theo1([0.0, 1.0, 0.0, 2.0, 0.0, 1.0], data_type="phase", taus="all")
    >>> res.averaging_factors.tolist(), res.taus.tolist(), res.n.tolist()
    ([2, 4], [1.5, 3.0], [4, 4])
    >>> res.deviation.round(6).tolist()
    [1.779513, 0.790569]
    """
    return estimate("theo1", data, rate, data_type, taus, confidence, nan_policy, alpha, bias_correction)


for _function in (mtotdev, ttotdev, htotdev, theo1):
    _function.__doc__ = _function.__doc__.replace("{parameters}", _PARAMETERS.replace("{alpha}", ALPHA_PARAMETER))
del _function
assert set(MTOT_EDF) == set(MTOT_BIAS)
