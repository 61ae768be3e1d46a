"""Equivalent degrees of freedom (EDF) and chi-squared bounds of stability deviations.

:func:`greenhall_edf` (Greenhall and Riley 2003: Allan d = 2, Hadamard d = 3,
overlapping or not, modified or not), :func:`totdev_edf` (NIST SP 1065 Table
7), :func:`estimator_edf` (by estimator name, per level) and
:func:`~avar.stability.uncertainty.chi2.chi2_bounds` (a variance estimate is sigma**2 chi2(edf) / edf;
re-exported here).
Everything is vectorized over the levels; Greenhall's sums are NumPy's for a few
levels and compiled for many (:mod:`avar._kernels.uncertainty.edf`).
"""

from __future__ import annotations

from math import comb
from typing import Any

import numpy as np

from avar._validation import short_repr
from avar.stability.uncertainty.chi2 import DEFAULT_CONFIDENCE, chi2_bounds

__all__ = ["DEFAULT_CONFIDENCE", "EDF_ESTIMATORS", "ESTIMATORS", "J_MAX", "STABLE32_SIMPLE_EDF_OFFSET", "TOTDEV_EDF",
           "chi2_bounds", "estimator_edf", "gap_scaled_edf", "greenhall_edf", "simple_edf", "stable32_simple_edf",
           "totdev_edf"]

#: Greenhall's J_max: beyond it, tables or a summed stride replace the full sum.
J_MAX = 100
#: Estimator name -> (d, overlapping, modified) of Greenhall's algorithm.
ESTIMATORS = {"adev": (2, False, False), "oadev": (2, True, False), "mdev": (2, True, True),
              "tdev": (2, True, True), "hdev": (3, False, False), "ohdev": (3, True, False),
              "mhdev": (3, True, True), "htdev": (3, True, True)}
EDF_ESTIMATORS = (*ESTIMATORS, "totdev")

# Greenhall and Riley (2003), Tables 1 and 2: (a0, a1) by alpha (2 .. -4) and d (1 .. 3);
# NaN where alpha + 2 d <= 1. Table 3: (b0, b1) for alpha = 1 by d.
_NA = (np.nan, np.nan)
_TABLE1 = np.array([
    [(2 / 3, 1 / 3), (7 / 9, 1 / 2), (22 / 25, 2 / 3)], [(0.840, 0.345), (0.997, 0.616), (1.141, 0.843)],
    [(1.079, 0.368), (1.033, 0.607), (1.184, 0.848)], [_NA, (1.048, 0.534), (1.180, 0.816)],
    [_NA, (1.302, 0.535), (1.175, 0.777)], [_NA, _NA, (1.194, 0.703)], [_NA, _NA, (1.489, 0.702)],
])
_TABLE2 = np.array([
    [(3 / 2, 1 / 2), (35 / 18, 1.0), (231 / 100, 3 / 2)], [(78.6, 25.2), (790.0, 410.0), (9950.0, 6520.0)],
    [(2 / 3, 1 / 6), (2 / 3, 1 / 3), (7 / 9, 1 / 2)], [_NA, (0.852, 0.375), (0.997, 0.617)],
    [_NA, (1.079, 0.368), (1.033, 0.607)], [_NA, _NA, (1.053, 0.553)], [_NA, _NA, (1.302, 0.535)],
])
_TABLE3 = np.array([(6.0, 4.0), (15.23, 12.0), (47.8, 40.0)])
#: TOTVAR edf = b N / m - c for white, flicker and random-walk FM, N the number of points given, as
#: Stable32's bounds imply: b = 1.168, 0.927 and c = 0.358 of Howe's TOTVAR fits (NIST SP 1065 Table 7,
#: and ``allantools``, round them to 1.17, 0.93, 0.36), c = 0.22 at flicker FM. On a 1253-point record
#: (given as phase and as frequency) they reproduce Stable32's bounds at flicker FM (EDF 3.4 to 1463),
#: random-walk FM (580.4; Table 7's rounding: 582.3) and white FM to 6.6e-5.
TOTDEV_EDF = {0: (1.500, 0.0), -1: (1.168, 0.22), -2: (0.927, 0.358)}
#: What Stable32 adds to NIST SP 1065 Table 5's simple EDF where a total statistic takes it (TOTDEV at
#: white and flicker PM, HTOTDEV below m = 16 and at PM). No source states it; Stable32's printed
#: bounds imply it on four records (N = 1001, 1253, 55 688, 241 218 phase points; flicker PM, white,
#: flicker and random-walk FM; EDF 18 to 1090): 2.00 +- 0.02 wherever the bounds resolve it.
STABLE32_SIMPLE_EDF_OFFSET = 2.0


def greenhall_edf(alpha: Any, d: int, m: Any, n_phase: int, overlapping: bool, modified: bool) -> np.ndarray:
    """Greenhall's equivalent degrees of freedom of a finite-difference variance estimate.

    The estimators of the Allan (d = 2) and Hadamard (d = 3) variances, and of
    the first-difference variance (d = 1), overlapping (stride 1, S = m) or
    not (stride m, S = 1), modified (filter F = 1: phase averaged over m
    samples) or not (F = m), of ``n_phase`` phase points with power-law noise
    S_y(f) ~ f**alpha. With L = m / F + m d the filter length, the estimate
    averages M = 1 + floor(S (N - L) / m) squared filtered values, and with
    J = min(M, (d + 1) S)::

        1 / edf = BasicSum(J, M, S, F) / (M s_z(0)**2),
        BasicSum = s_z(0)**2 + (1 - J/M) s_z(J/S)**2 + 2 sum_{j=1}^{J-1} (1 - j/M) s_z(j/S)**2

    where s_z is the generalized autocovariance of the filtered phase (the
    paper's eqs. 7-9). For J > J_max = 100 the paper's Tables 1-3 (r = M / S
    > d + 1) or a sum at a coarser stride replace the sum; for white PM
    (alpha = 2) unmodified, with r = M / S and K = ceil(r), the exact
    1 / edf = (1/M) sum_{|k| <= min(d, K - 1)} (1 - |k|/r) rho_k**2,
    rho_k = C(2d, d + k) / C(2d, d) (for K > d, the paper's (a0 - a1/r) / M).

    Parameters
    ----------
    alpha : int or array_like of int
        Power-law exponent of the frequency noise, -4 .. 2, with alpha + 2d > 1
        (2 white PM, 1 flicker PM, 0 white FM, -1 flicker FM, -2 random-walk FM).
    d : {1, 2, 3}
        Order of the phase difference (2: Allan variances, 3: Hadamard).
    m : int or array_like of int
        Averaging factors (tau = m tau0); broadcast against ``alpha``.
    n_phase : int
        Number of phase points N.
    overlapping, modified : bool
        The estimator: stride 1 (S = m) or m (S = 1); averaged phase (F = 1) or not (F = m).

    Returns
    -------
    ndarray of float64, the broadcast shape of ``alpha`` and ``m``.

    References
    ----------
    C. A. Greenhall and W. J. Riley, "Uncertainty of stability variances based
    on finite differences", Proc. 35th PTTI Meeting, 2003. W. J. Riley, NIST
    SP 1065, 2008, section 5.3.

    Examples
    --------
    White FM, non-overlapping Allan variance of N = 1001 phase points at
    m = 100: M = 9 differences of independent averages, correlated -1/2 with
    their neighbours, so edf = 2 M**2 / (3 M - 1) = 162 / 26 exactly:

    >>> float(greenhall_edf(0, 2, 100, 1001, overlapping=False, modified=False))
    6.230769231...
    >>> greenhall_edf([2, 0, -2], 2, 8, 1001, overlapping=True, modified=True).round(2)
    array([154.38, 118.87,  94.19])
    >>> greenhall_edf(0, 3, [1, 10, 100], 1001, overlapping=True, modified=False).round(2)
    array([608.55, 113.7 ,   9.92])
    """
    alpha, m = _check_levels(alpha, m, "alpha", "m")
    if isinstance(d, (bool, np.bool_)) or not isinstance(d, (int, np.integer)) or d not in (1, 2, 3):
        raise ValueError(f"d must be 1, 2 or 3 (first-difference, Allan, Hadamard), got {short_repr(d)}")
    d = int(d)
    bad = alpha + 2 * d <= 1
    if bad.any():
        raise ValueError(f"alpha must satisfy alpha + 2 d > 1 (alpha >= {2 - 2 * d} for d = {d}), "
                         f"got {short_repr(np.unique(alpha[bad]).tolist())}")
    n = _check_count(n_phase, "n_phase")
    for name, flag in (("overlapping", overlapping), ("modified", modified)):
        if not isinstance(flag, (bool, np.bool_)):
            raise TypeError(f"{name} must be True or False, got {short_repr(flag)}")
    alpha, m = np.broadcast_arrays(alpha, m)
    shape = alpha.shape
    alpha, m = alpha.ravel(), m.ravel()
    mf = m.astype(np.float64)
    s = mf if overlapping else np.ones_like(mf)
    length = m * (d + 1) if modified else 1 + m * d  # L = m / F + m d
    short = length > n
    if short.any():
        need = "m (d + 1)" if modified else "m d + 1"
        raise ValueError(f"m = {short_repr(np.unique(m[short]).tolist())} too large for n_phase = {n}: "
                         f"the estimator needs {need} <= n_phase phase points (d = {d})")
    big_m = (1 + ((n - length) if overlapping else (n - length) // m)).astype(np.float64)
    j = np.minimum(big_m, (d + 1) * s)
    r = big_m / s
    inv = np.full(m.shape, np.nan)
    # The cases of the paper: which BasicSum (J, M, S, F), its normalization, or which table.
    sum_j, sum_m, sum_s, sum_f = j.copy(), big_m.copy(), s.copy(), np.ones_like(mf) if modified else mf.copy()
    norm = np.full(m.shape, np.nan)  # NaN: s_z(0, F) of the sum's own F
    denominator = big_m.copy()
    use_sum = np.zeros(m.shape, dtype=bool)
    small_j = j <= J_MAX
    coarse = ~small_j & (r <= d + 1)  # cases x.3: the sum at stride m' = J_max / r
    tabled = ~small_j & (r > d + 1)  # cases x.2: the tables
    row, col = 2 - alpha, d - 1
    if modified:  # case 1, all alpha
        use_sum = small_j | coarse
        a0, a1 = _TABLE1[row, col, 0], _TABLE1[row, col, 1]
        inv = np.where(tabled, (a0 - a1 / r) / r, inv)
    else:
        low = alpha <= 0  # case 2
        prime = np.where(mf * (d + 1) <= J_MAX, mf, np.inf)
        sum_f = np.where(low, np.where(small_j, prime, np.inf), sum_f)
        use_sum = np.where(alpha <= 1, small_j | coarse, False)
        a0, a1 = _TABLE2[row, col, 0], _TABLE2[row, col, 1]
        inv = np.where(tabled & low, (a0 - a1 / r) / r, inv)
        flicker = alpha == 1  # case 3
        b0, b1 = _TABLE3[col]
        log_norm = b0 + b1 * np.log(mf)
        inv = np.where(tabled & flicker, (a0 - a1 / r) / (log_norm**2 * r), inv)
        norm = np.where(flicker & coarse, log_norm, norm)
        sum_f = np.where(flicker & coarse, J_MAX / r, sum_f)
        white = alpha == 2  # case 4, exact for every r
        if white.any():
            inv = np.where(white, _white_pm_inverse(big_m, r, d), inv)
    sum_j = np.where(coarse, J_MAX, sum_j)
    sum_m = np.where(coarse, J_MAX, sum_m)
    sum_s = np.where(coarse, J_MAX / r, sum_s)
    denominator = np.where(coarse, J_MAX, denominator)
    if use_sum.any():
        k = np.flatnonzero(use_sum)
        from avar._kernels.uncertainty.edf import greenhall_sums  # compiled (for many rows): loaded on first use

        inv[k] = greenhall_sums(sum_j[k], sum_m[k], sum_s[k], sum_f[k].astype(np.float64), alpha[k], d, norm[k],
                                denominator[k])
    return (1.0 / inv).reshape(shape)


def _white_pm_inverse(big_m: np.ndarray, r: np.ndarray, d: int) -> np.ndarray:
    """1 / edf of the unmodified variances for white PM, summed exactly over the lags."""
    centre = comb(2 * d, d)
    total = np.ones_like(r)
    lags = np.ceil(r) - 1  # K - 1
    for k in range(1, d + 1):
        total += np.where(k <= lags, 2.0 * (1.0 - k / r) * (comb(2 * d, d + k) / centre) ** 2, 0.0)
    return total / big_m


def totdev_edf(n_phase: int, m: Any, alpha: Any) -> np.ndarray:
    """Equivalent degrees of freedom of the total deviation (Howe 2000; NIST SP 1065, Table 7).

    For white, flicker and random-walk FM (alpha = 0, -1, -2)::

        edf = b N / m - c,  (b, c) = (1.500, 0), (1.168, 0.22), (0.927, 0.358)

    with N the number of data points (T / tau = N / m; Stable32 counts the
    points given, phase or frequency); SP 1065's Table 7 rounds b to two
    decimals (see :data:`TOTDEV_EDF`). SP 1065 gives no TOTVAR EDF for white and
    flicker PM (alpha = 2, 1); there, as Stable32, the handbook's simple
    approximations for the Allan variance (its Table 5, Stein 1985) plus 2
    (:data:`STABLE32_SIMPLE_EDF_OFFSET`): alpha = 2: (N + 1)(N - 2m) / (2 (N - m)) + 2;
    alpha = 1: exp(sqrt(ln((N - 1) / 2m) ln((2m + 1)(N - 1) / 4))) + 2. Those
    two fall to 0 (or are undefined) as m reaches N / 2: every EDF is floored at 1.
    ``allantools`` takes Table 7's rounded coefficients and Table 5 without the 2.

    Parameters
    ----------
    n_phase : int
        Number of data points N: Stable32 counts those given (frequency data: one
        fewer than their phase points).
    m : int or array_like of int
        Averaging factors.
    alpha : int or array_like of int
        Power-law exponents, -2 .. 2; broadcast against ``m``.

    Returns
    -------
    ndarray of float64

    References
    ----------
    W. J. Riley, "Handbook of Frequency Stability Analysis", NIST SP 1065,
    2008, sections 5.2.11 and 5.3.3 (Tables 5 and 7). S. R. Stein, "Frequency
    and time: their measurement and characterization", 1985.

    Examples
    --------
    >>> totdev_edf(1001, [1, 16, 256], 0).round(3)
    array([1501.5  ,   93.844,    5.865])
    >>> totdev_edf(1001, 16, [0, -1, -2, 1]).round(3)
    array([ 93.844,  72.853,  57.637, 264.791])
    """
    m, alpha = _check_levels(m, alpha, "m", "alpha")
    if ((alpha < -2) | (alpha > 2)).any():
        raise ValueError(f"alpha must be in -2 .. 2 for totdev_edf, got {short_repr(np.unique(alpha).tolist())}")
    n = float(_check_count(n_phase, "n_phase"))
    if (m > n).any():  # m = N: the longest level of N frequency values
        raise ValueError(f"m must be <= n_phase = {int(n)}, got {short_repr(np.unique(m[m > n]).tolist())}")
    m, alpha = np.broadcast_arrays(m.astype(np.float64), alpha)
    edf = stable32_simple_edf(n, m, alpha)
    for a, (b, c) in TOTDEV_EDF.items():
        edf = np.where(alpha == a, b * n / m - c, edf)
    return np.where(np.isnan(edf) | (edf < 1), 1.0, edf)


def simple_edf(n_phase: float, m: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """NIST SP 1065 Table 5: the simple EDF approximations of the overlapping Allan variance
    (Howe, Allan and Barnes 1981; Stein 1985), N phase points, per level (not floored)::

        white PM      (N + 1)(N - 2m) / (2 (N - m))
        flicker PM    exp(sqrt(ln((N - 1) / 2m) ln((2m + 1)(N - 1) / 4)))
        white FM      (3 (N - 1) / 2m - 2 (N - 2) / N) 4 m^2 / (4 m^2 + 5)
        flicker FM    2 (N - 2)^2 / (2.3 N - 4.9) at m = 1, else 5 N^2 / (4 m (N + 3m))
        random-walk   (N - 2) / m ((N - 1)^2 - 3 m (N - 1) + 4 m^2) / (N - 3)^2

    TOTDEV's at white and flicker PM (where Table 7 has none) and HTOTDEV's below m = 16 and at
    PM take them plus 2, as Stable32 (:func:`stable32_simple_edf`; the overlapping Hadamard
    variance's Greenhall EDF is 10 to 36 % lower there, simulated records have more still:
    ``benchmarks/total_edf_simulation.py``).

    >>> simple_edf(1001, np.array([1, 8, 1, 4]), np.array([0, 0, -1, -2])).round(2).tolist()
    [665.78, 181.95, 868.81, 247.76]
    """
    n = float(n_phase)
    m = np.asarray(m, dtype=np.float64)
    alpha = np.asarray(alpha)
    with np.errstate(divide="ignore", invalid="ignore"):
        wpm = (n + 1) * (n - 2 * m) / (2 * (n - m))
        fpm = np.exp(np.sqrt(np.log((n - 1) / (2 * m)) * np.log((2 * m + 1) * (n - 1) / 4)))
        wfm = (3 * (n - 1) / (2 * m) - 2 * (n - 2) / n) * 4 * m * m / (4 * m * m + 5)
        ffm = np.where(m == 1, 2 * (n - 2) ** 2 / (2.3 * n - 4.9), 5 * n * n / (4 * m * (n + 3 * m)))
        rwfm = (n - 2) / m * ((n - 1) ** 2 - 3 * m * (n - 1) + 4 * m * m) / (n - 3) ** 2
    return np.select([alpha == 2, alpha == 1, alpha == 0, alpha == -1, alpha == -2], [wpm, fpm, wfm, ffm, rwfm],
                     np.nan)


def stable32_simple_edf(n_phase: float, m: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """:func:`simple_edf` + 2: Stable32's EDF where a total statistic takes the simple approximations.

    TOTDEV at white and flicker PM, HTOTDEV below m = 16 and at PM (see
    :data:`STABLE32_SIMPLE_EDF_OFFSET` for the evidence).

    >>> stable32_simple_edf(1001, np.array([256, 8]), np.array([1, 0])).round(3).tolist()
    [18.544, 183.95]
    """
    return simple_edf(n_phase, m, alpha) + STABLE32_SIMPLE_EDF_OFFSET


def estimator_edf(estimator: str, alpha: np.ndarray, factors: np.ndarray, n_phase: int,
                  n_given: int | None = None) -> np.ndarray:
    """EDF of a named stability estimator at every level.

    ``"adev"`` (d = 2, non-overlapping), ``"oadev"`` (d = 2, overlapping),
    ``"mdev"`` and ``"tdev"`` (d = 2, modified, overlapping), ``"hdev"``
    (d = 3, non-overlapping), ``"ohdev"`` (d = 3, overlapping), ``"mhdev"`` and ``"htdev"``
    (d = 3, modified, overlapping: Greenhall and Riley's algorithm covers the modified
    Hadamard variance too) by :func:`greenhall_edf`; ``"totdev"`` by :func:`totdev_edf`.

    Parameters
    ----------
    estimator : str
        One of ``"adev"``, ``"oadev"``, ``"mdev"``, ``"tdev"``, ``"hdev"``, ``"ohdev"``, ``"mhdev"``,
        ``"htdev"``, ``"totdev"``.
    alpha : array_like of int
        Power-law exponent per level, -2 .. 2 (see :func:`avar.stability.uncertainty.noise_id.identify_noise`).
    factors : array_like of int
        Averaging factors m per level.
    n_phase : int
        Number of phase points (frequency data of N values: N + 1).
    n_given : int, optional
        Number of data points given (frequency data: ``n_phase - 1``), which
        TOTDEV's EDF counts, as Stable32; default ``n_phase``.

    Returns
    -------
    ndarray of float64, one EDF per level.

    Examples
    --------
    >>> estimator_edf("oadev", [0, 0], [1, 4], 1001).round(2)
    array([782.03, 306.09])
    >>> estimator_edf("totdev", [0], [4], 1001), estimator_edf("totdev", [0], [4], 1001, n_given=1000)
    (array([375.375]), array([375.]))
    """
    if not isinstance(estimator, str) or estimator.lower() not in EDF_ESTIMATORS:
        raise ValueError(f"estimator must be one of {list(EDF_ESTIMATORS)}, got {short_repr(estimator)}")
    estimator = estimator.lower()
    alpha, factors = _check_levels(alpha, factors, "alpha", "factors")
    if ((alpha < -2) | (alpha > 2)).any():
        raise ValueError(f"alpha must hold integers in -2 .. 2, got {short_repr(np.unique(alpha).tolist())}")
    if estimator == "totdev":
        return totdev_edf(n_phase if n_given is None else n_given, factors, alpha)
    d, overlapping, modified = ESTIMATORS[estimator]
    return greenhall_edf(alpha, d, factors, n_phase, overlapping=overlapping, modified=modified)


def gap_scaled_edf(edf: np.ndarray, used: np.ndarray, estimator: str, n_phase: int, factors: np.ndarray) -> np.ndarray:
    """EDF of levels that lost terms to gaps: scaled by the fraction of terms used, never below 1.

    ``used`` terms of the gap-free count (:func:`avar.stability.shared.term_counts.term_counts`)
    remain at each level; one Gaussian term is one degree of freedom, the floor.
    """
    from avar.stability.shared.term_counts import term_counts

    return np.maximum(edf * used / term_counts(estimator, n_phase, factors), 1.0)


def _check_count(n: Any, name: str) -> int:
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) or n < 2:
        raise ValueError(f"{name} must be an integer number of points >= 2, got {short_repr(n)}")
    return int(n)


def _check_levels(first: Any, second: Any, name1: str, name2: str) -> tuple[np.ndarray, np.ndarray]:
    """Two integer arrays (alpha, m in either order) that broadcast; m >= 1."""
    out = []
    for name, values in ((name1, first), (name2, second)):
        array = np.asarray(values)
        if array.dtype.kind == "f" and np.isfinite(array).all() and (array == np.round(array)).all():
            array = array.astype(np.int64)
        if array.dtype.kind not in "iu" or isinstance(values, (bool, np.bool_)):
            raise TypeError(f"{name} must be an integer or an array of integers, got {short_repr(values)}")
        array = array.astype(np.int64)
        if name in ("m", "factors") and (array < 1).any():
            raise ValueError(f"{name} must be averaging factors >= 1, got {short_repr(np.unique(array[array < 1]).tolist())}")
        if name == "alpha" and ((array < -4) | (array > 2)).any():
            raise ValueError(f"alpha must be a power-law exponent in -4 .. 2, got {short_repr(np.unique(array).tolist())}")
        out.append(array)
    try:
        np.broadcast(*out)
    except ValueError:
        raise ValueError(f"{name1} and {name2} must broadcast together, got shapes "
                         f"{out[0].shape} and {out[1].shape}") from None
    return out[0], out[1]
