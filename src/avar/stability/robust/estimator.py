"""The Allan variance of a series with spikes: :func:`robust_allan_variance`, :func:`count_outliers`.

Outliers (isolated spikes: a bad sample, a transmission error) are found by
their distance from the line through their neighbours, in robust standard
deviations of that residual; the Allan variance is then computed without them (see
:func:`robust_allan_variance` for why the samples are set aside rather than
the wavelet coefficients down-weighted).
"""

from __future__ import annotations

import sys
import warnings
from typing import Any

import numpy as np

from avar._validation import as_series, check_real
from avar.imu import IMU
from avar.stability.allan.columns import allan_variance_columns
from avar.stability.allan.intervals import relative_errors
from avar.stability.robust.results import Outliers, RobustAllanVariance
from avar.stability.robust.small import outlier_kernels, squares_kernel
from avar.stability.shared.grids import averaging_factors
from avar.stability.shared.term_counts import n_differences

#: 1 / Phi^{-1}(3/4): the MAD of a Gaussian times this is its standard deviation.
MAD_TO_SD = 1.482602218505602
#: Interquartile range of a standard Gaussian, 2 Phi^{-1}(3/4).
IQR_TO_SD = 1.3489795003921634
#: Share of residuals tied with their MAD beyond which the data are taken as quantized.
GROUPED_TIES = 0.01
#: Samples read by the preliminary robust scales (every k-th): their relative standard error is ~1.2 / sqrt(this).
PRELIMINARY_SAMPLES = 2**17
#: Half width of the running median that finds the candidates (11 samples).
MEDIAN_HALF_WIDTH = 5
#: The fill's bias bound per flagged fraction p: linear interpolation adds 1.5 p to white noise's AV.
FILL_BIAS = 1.5
#: Passes of the candidates' release at most (it settles in a few).
MAX_PASSES = 50


def robust_scale(residuals: np.ndarray) -> float:
    """Robust standard deviation of ``residuals``: 1.4826 median|r - median r|.

    Quantized data (a sensor whose step is comparable to its noise) take
    few distinct values, and their MAD is a whole or half step: 0, or up to
    50 % off. When more than 1 % of the |r - median r| equal the MAD, the
    scale is instead (Q3 - Q1) / 1.349 with grouped-data quartiles: each
    value spread uniformly over its quantization bin (the smallest gap
    between distinct values), i.e. the quartiles of the data plus uniform
    dither, whose standard deviation is sqrt(sigma**2 + step**2 / 12)
    (Sheppard). 0 only when every residual is equal. A series that is
    constant but for its spikes has the spikes as its step, and they are
    not flagged.

    >>> round(robust_scale(np.array([0.0] * 9 + [1.0, -1.0, 0.0])), 4)
    0.4448
    """
    if residuals.size == 0:
        return 0.0
    centred = np.array(residuals, dtype=np.float64)  # one copy, reordered by the in-place medians
    centred -= np.median(centred, overwrite_input=True)
    spread = np.abs(centred)
    mad = float(np.median(spread, overwrite_input=True))
    if mad > 0 and np.count_nonzero(spread == mad) <= GROUPED_TIES * spread.size:
        return MAD_TO_SD * mad
    return grouped_iqr_scale(centred)


def grouped_iqr_scale(values: np.ndarray) -> float:
    """(Q3 - Q1) / 1.349 of quantized ``values``, each spread uniformly over its bin.

    The bin width h is the smallest gap between distinct values (gaps below
    1e-9 of the range are rounding, merged); bins are centred on multiples
    of h. A quartile falls in bin k of lower edge (k - 1/2) h, holding c_k
    of the values with F below it: q_p = (k - 1/2) h + (p N - F) / c_k * h.

    >>> round(grouped_iqr_scale(np.array([-1.0] * 25 + [0.0] * 950 + [1.0] * 25)), 4)
    0.3902
    """
    distinct, counts = np.unique(values, return_counts=True)
    span = float(distinct[-1] - distinct[0])
    if span == 0:
        return 0.0
    gaps = np.diff(distinct)
    step = float(gaps[gaps > 1e-9 * span].min())
    bins = np.rint(np.clip(distinct / step, -2.0**62, 2.0**62)).astype(np.int64)
    bins, where = np.unique(bins, return_inverse=True)
    counts = np.bincount(where, weights=counts)
    cumulative = np.cumsum(counts)
    quartiles = []
    for p in (0.25, 0.75):
        target = p * cumulative[-1]
        k = int(np.searchsorted(cumulative, target, side="right"))
        k = min(k, bins.size - 1)
        below = cumulative[k - 1] if k > 0 else 0.0
        quartiles.append((bins[k] - 0.5 + (target - below) / counts[k]) * step)
    return float(quartiles[1] - quartiles[0]) / IQR_TO_SD


def _every_kth(values: np.ndarray) -> np.ndarray:
    """At most about PRELIMINARY_SAMPLES evenly spaced values (a view): enough for a preliminary scale."""
    return values[::max(1, values.size // PRELIMINARY_SAMPLES)]


def flag_outliers(values: np.ndarray, threshold: float) -> Outliers:
    """Flag the samples whose interpolation residual exceeds threshold robust SDs (validated float64 input).

    s: the robust scale of the residuals from the neighbours' line, all
    samples. Candidates C: |x_t - med_t| > (threshold / 2) min(s_med, s),
    med the 11-sample running median (mirrored at the ends), s_med the
    robust scale of x - med. Then F = C, and passes F <- F & (|r| >
    threshold s), r the residuals from the line through the samples not in
    F, until F settles (a clean sample whose line spanned other candidates
    is released once they are). Twice: the second time with s the robust
    scale of r outside F (the first s counts the spikes' residuals too).
    The two preliminary scales (s_med and the first s) read every k-th
    sample, at most about ``PRELIMINARY_SAMPLES`` (relative error ~0.3 %).
    """
    n, kernels = values.size, outlier_kernels(values)  # the compiled loops, or their NumPy twins while cold
    flagged, residuals = np.zeros(n, dtype=bool), np.empty(n)
    kernels.interpolation_residuals(values, flagged, residuals)
    scale = robust_scale(_every_kth(residuals))
    median = np.empty(n)
    kernels.running_median(values, MEDIAN_HALF_WIDTH, median)
    departure = values - median
    candidates = np.abs(departure) > threshold / 2 * min(robust_scale(_every_kth(departure)), scale)
    for final in (False, True):
        flagged = candidates.copy()
        kernels.release_candidates(values, flagged, residuals, threshold * scale, MAX_PASSES)
        if not final and not flagged.all():
            scale = robust_scale(residuals[~flagged])
    indices = np.flatnonzero(flagged)
    return Outliers(count=int(indices.size), indices=indices, n=n, threshold=threshold, scale=scale)


def _series(x: Any, freq: Any) -> tuple[np.ndarray, float]:
    """Validated contiguous float64 values and rate of one series (an IMU or a table is refused by name)."""
    pd = sys.modules.get("pandas")  # not loaded: x cannot be a pandas object
    if isinstance(x, IMU) or (pd is not None and isinstance(x, pd.DataFrame)):
        raise TypeError(f"x must be one series, got {'an avar.IMU' if isinstance(x, IMU) else 'a DataFrame'}; "
                        "give its channels one at a time, e.g. x=imu.data[:, j] with freq=imu.freq")
    values, rate = as_series(x, freq)
    return np.ascontiguousarray(values, dtype=np.float64), rate


def _check_threshold(threshold: Any) -> float:
    threshold = check_real(threshold, "threshold")
    if not threshold > 0:
        raise ValueError(f"threshold must be > 0 (robust standard deviations, e.g. 6.0), got {threshold!r}")
    return threshold


def count_outliers(x: Any, threshold: float = 6.0) -> Outliers:
    """Samples that lie more than ``threshold`` robust standard deviations from their neighbours' line.

    Two steps. Candidates: the samples far from the median of the 11
    samples centred on them (more than threshold / 2 robust standard
    deviations of that departure); the running median ignores spikes and
    bursts of up to 5 samples. Then, with a < t < b the nearest samples
    that are not (still) candidates, the residual r_t is the distance of x_t from
    the straight line through x_a and x_b (for an isolated sample,
    r_t = x_t - (x_{t-1} + x_{t+1}) / 2), and a candidate is an outlier when::

        |r_t| > threshold * s,   s = 1.4826 * median|r - median(r)|  (over the other samples)

    repeated until no candidate is released (a clean sample whose line
    spanned other candidates is released once they are).

    The residual is a fixed linear combination of samples, so for any
    Gaussian process (white noise, random walk, drift, their sums) it is
    Gaussian, and s is its standard deviation (see :func:`robust_scale`
    for quantized data), not inflated by the outliers (they are left
    out of s and of the lines). A clean Gaussian series
    exceeds 6 s with probability about 2e-9 per sample: the count is 0.
    (The running median alone is not enough: a random walk's departure
    from its running median has heavier tails than a Gaussian's, so its
    MAD would flag hundreds of clean samples.) A step (a level shift that
    stays, or a burst of more than 5 samples) is not an outlier.

    Parameters
    ----------
    x : array_like or pandas.Series
        1-D real series (finite values).
    threshold : float
        In robust standard deviations (> 0); 6 by default.

    Returns
    -------
    Outliers
        ``count``, ``indices``, ``fraction``, ``scale`` (s, data units).

    References
    ----------
    F. R. Hampel, "The influence curve and its role in robust estimation",
    JASA 69:383-393, 1974 (the MAD scale). R. K. Pearson, "Outliers in
    process modeling and identification", IEEE Trans. Control Syst.
    Technol. 10(1):55-63, 2002 (Hampel-type filters).

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> x = np.random.default_rng(1).standard_normal(10_000)
    >>> avar.count_outliers(x).count
    0
    >>> x[[100, 101, 5000, 7001]] += [20.0, 20.0, -15.0, 30.0]
    >>> found = avar.count_outliers(x)
    >>> found.count, found.indices.tolist()
    (4, [100, 101, 5000, 7001])
    """
    threshold = _check_threshold(threshold)
    return flag_outliers(_series(x, None)[0], threshold)


def intact_counts(flagged: np.ndarray, n: int, factors: np.ndarray) -> np.ndarray:
    """Differences (2m consecutive samples) that hold no flagged sample, per factor m.

    A run of L unflagged samples holds max(0, L - 2m + 1) of them.

    >>> intact_counts(np.array([3]), 10, np.array([1, 2, 3])).tolist()
    [7, 3, 1]
    """
    edges = np.concatenate(([-1], flagged, [n]))
    runs = np.diff(edges) - 1
    return np.array([np.maximum(runs - 2 * m + 1, 0).sum() for m in factors], dtype=np.int64)


def fill_excess(raw: np.ndarray, factors: np.ndarray, fraction: float, scale: float) -> np.ndarray:
    """What interpolating a fraction ``fraction`` of the samples adds to the "mo" AV(m) of white noise.

    Each interpolated sample adds the variance of its interpolation error
    to a cluster sum: ``scale**2`` (the robust variance of the residual
    x_t - (x_{t-1} + x_{t+1}) / 2, 1.5 sigma**2 for white noise); a
    difference spans 2m samples, so AV(m) gains p s**2 / m. Never more than
    white noise's share of ``raw``, raw * 1.5 p / (1 + 1.5 p): for a random
    walk the excess is negligible (s**2 = gamma**2 / 2 against gamma**2 m / 3).

    >>> fill_excess(np.array([0.5 * 1.075, 0.25]), np.array([2, 4]), 0.05, np.sqrt(1.5)).round(4).tolist()
    [0.0375, 0.0174]
    """
    white = fraction * scale * scale / factors
    return np.minimum(white, raw * FILL_BIAS * fraction / (1.0 + FILL_BIAS * fraction))


def robust_allan_variance(x: Any, rate: float | None = None, taus: Any = "octave",
                          threshold: float = 4.0, *, freq: float | None = None) -> RobustAllanVariance:
    """Allan variance ("mo") of the clean process behind a series with spikes.

    Outlying samples are flagged as in :func:`count_outliers` (``threshold``
    robust standard deviations from the line through their neighbours) and
    set aside; then at each averaging factor m (tau = m / freq) one of two
    estimators of the clean process's AV(m) = E[(ybar_{t+m}(m) - ybar_t(m))**2] / 2:

    * **intact**: the mean of (ybar_{t+m}(m) - ybar_t(m))**2 / 2 over the
      differences whose 2m samples hold no flagged sample (as
      ``avar.avar(x, nan_policy="omit")`` with the flagged samples as gaps).
      Spike times do not depend on the clean process, so this is unbiased;
      but a fraction about 1 - (1 - p)**(2m) ~= 2 m p of the differences is
      lost (p the flagged fraction), all of them at large m.
    * **filled**: the ordinary "mo" estimator of the series with each flagged
      sample replaced by linear interpolation between its unflagged
      neighbours, less the fill's excess (:func:`fill_excess`). Every
      difference is kept; a random walk or drift is interpolated almost
      exactly, but white noise is not: an interpolated sample adds the
      variance of its interpolation error, s**2 (= 1.5 sigma**2), to a
      cluster sum, i.e. p s**2 / m to AV(m), 1.5 p relative (any
      level-preserving linear fill adds at least p sigma**2 / m), and this
      excess is subtracted.

    A level is ``intact`` when its relative sampling error, about
    sqrt(2 m / C) for C intact differences, is at most the uncorrected
    fill's bias bound 1.5 p; otherwise it is filled. With no sample flagged the result is
    ``avar.avar(x, type="mo")`` exactly.

    Why not a robust scale of the differences: the Haar wavelet coefficients
    W_t(m) = (ybar_{t+m}(m) - ybar_t(m)) / sqrt(2), whose mean square is
    AV(m), are Gaussian for Gaussian noise, and M-estimators of their scale
    (Mondal & Percival 2012; Guerrier et al.'s robust wavelet variance)
    resist a fraction of contaminated coefficients up to their breakdown
    point. But one spike contaminates 2m coefficients, so that fraction is
    ~= 2 m p: with 5 % spikes, 20 % at m = 2, 40 % at m = 4 and 80 % at
    m = 8. In simulations (white noise + random walk, 5 % spikes of 20
    sigma; ``benchmarks/bench_robust.py``) such an estimator is within 1 %
    at m = 2, 30 % high at m = 4 and 20x high beyond, while this one is
    within 5 % at every level with N / 2m >= 100 (median within 0.5 %),
    and on the series without spikes its spread equals the ordinary one. The result's ``contaminated`` gives 1 - C /
    (N - 2m + 1) per level, the breakdown measure of a coefficient-domain
    estimator.

    Where it can no longer resist: spikes smaller than ``threshold`` robust
    standard deviations are not flagged and count fully (at most
    threshold**2 scale**2 each); a burst longer than 5 samples looks like a
    step and is not flagged; and the filled levels assume the noise at the
    sampling rate is white or smoother: for quantization noise (AV
    proportional to 1 / m**2, a "blue" noise whose cluster sums telescope)
    an interpolated sample breaks the telescoping, and a filled level is
    raised by about p s**2 / m, which dominates at large m (with 5 % spikes
    on pure quantization noise, 3.3x at m = 32 and more beyond). Real
    sensors have white noise above quantization noise beyond the shortest
    taus.

    Parameters
    ----------
    x : array_like or pandas.Series
        1-D real series (finite values).
    rate : float, optional
        Sampling rate in Hz (default: the rate of a Series' time index, else 1 Hz).
    taus : {"octave", "decade", "all"} or array_like of float
        Tau grid, as for :func:`avar.avar` (the same levels).
    threshold : float
        Flagging threshold in robust standard deviations of the residual
        (default 4: a Gaussian residual passes it with probability 6e-5,
        and setting a clean sample aside costs next to nothing: on 1e6
        samples of white noise + random walk, 27 flagged, the AV changed by
        < 0.1 %; spikes of 8 sigma of white noise, 6.5 residual SDs, are
        found, where a threshold of 5 misses 10 % of them and leaves the AV
        40 % high).

    Returns
    -------
    RobustAllanVariance
        An :class:`avar.AllanVariance` of type "mo", plus ``outliers``,
        ``intact`` and ``contaminated`` per level.

    References
    ----------
    D. Mondal and D. B. Percival, "M-estimation of wavelet variance",
    Annals of the Institute of Statistical Mathematics 64:27-53, 2012.
    S. Guerrier, R. Molinari, M.-P. Victoria-Feser, "Robust inference for
    time series models: a wavelet-based framework", 2020 (robust GMWM).
    D. B. Percival and P. Guttorp, "Long-memory processes, the Allan
    variance and wavelets", 1994 (AV(m) = 2 Haar wavelet variance).

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> rng = np.random.default_rng(7)
    >>> clean = rng.standard_normal(20_000)
    >>> spiky = clean.copy()
    >>> spiky[rng.choice(20_000, 400, replace=False)] += 20.0  # 2 % spikes of 20 sigma
    >>> res = avar.robust_avar(spiky)
    >>> res.outliers.count
    400
    >>> ordinary = avar.avar(spiky).allan / avar.avar(clean).allan
    >>> robust = res.allan / avar.avar(clean).allan
    >>> bool(ordinary[0] > 4), bool(np.all(np.abs(robust[:6] - 1) < 0.05))  # N / 2m >= 150
    (True, True)
    """
    threshold = _check_threshold(threshold)
    if freq is not None:  # the former spelling, kept for one minor release
        if rate is not None:
            raise TypeError("give rate= or freq= (its deprecated alias), not both")
        warnings.warn("robust_avar(freq=...) is deprecated; use rate= (freq= goes in 0.3.0)", DeprecationWarning,
                      stacklevel=2)
        rate = freq
    values, rate = _series(x, rate)
    n = values.size
    factors = averaging_factors(n, rate, taus)
    outliers = flag_outliers(values, threshold)
    total = n_differences(n, factors, "mo")
    counts = intact_counts(outliers.indices, n, factors)
    p = outliers.fraction
    with np.errstate(divide="ignore"):
        intact = (counts > 0) & (np.sqrt(2.0 * factors / np.maximum(counts, 1)) <= FILL_BIAS * p)
    if outliers.count == 0:
        intact[:] = True
    allan = np.empty(factors.size)
    filled = values
    if outliers.count:
        keep = np.ones(n, dtype=bool)
        keep[outliers.indices] = False
        filled = values.copy()
        filled[~keep] = np.interp(outliers.indices, np.flatnonzero(keep), values[keep])
        if intact.any():
            exponent = int(np.frexp(np.max(np.abs(filled)))[1])  # |filled| < 2**exponent: an exact rescaling
            centred = np.ldexp(filled, -exponent)
            centred -= centred.mean()
            for j in np.flatnonzero(intact):
                m = int(factors[j])
                squares, used = squares_kernel(centred)(centred, ~keep, m)
                with np.errstate(over="ignore"):  # reported below
                    allan[j] = np.ldexp(squares / (2.0 * m * m * used), 2 * exponent)
            if not np.isfinite(allan[intact]).all():
                raise ValueError("the Allan variance overflows float64; rescale the data, e.g. to other units")
    rest = ~intact if outliers.count else intact
    if rest.any():
        raw = allan_variance_columns(filled[:, None], factors[rest], "mo")[0]
        allan[rest] = raw - fill_excess(raw, factors[rest], outliers.fraction, outliers.scale)
    return RobustAllanVariance(
        levels=factors / rate, averaging_factors=factors, allan=allan, errors=relative_errors(n, factors),
        n_differences=np.where(intact, counts, total), type="mo", freq=rate, n=n, outliers=outliers,
        intact=intact, contaminated=1.0 - counts / total,
    )


#: The public name (``avar.robust_avar``), after ``avar.avar``.
robust_avar = robust_allan_variance
