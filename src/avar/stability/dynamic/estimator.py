"""Dynamic deviations: a classic statistic in every window of a sliding window, as Stable32's DAVAR.

:func:`dynamic` (any statistic of the classic family), :func:`dadev` (OADEV) and :func:`dhdev`
(OHDEV). Validation happens here once; the windows' sums come from one pass over the record's
terms per level (:mod:`avar._kernels.dynamic.windows`; while that kernel and the phase's are cold
and the work small, their NumPy twins in :mod:`avar.stability.dynamic.small`), so a window costs
O(1) per level, and
each window equals its statistic computed alone (the noise, EDF and bounds of every window are
the public function's). TOTDEV, whose terms reflect the window's own ends, is computed window by
window by the classic core.
"""

from __future__ import annotations

import numbers
from typing import Any, NamedTuple

import numpy as np

from avar._kernels.classic.phase import PHASE_KERNELS
from avar._kernels.dynamic.windows import window_sums
from avar._kernels.runtime.paths import numpy_path
from avar._kernels.runtime.tasks import run_tasks
from avar._validation import short_repr
from avar.stability.classic import deviations as classic
from avar.stability.classic.core import HADAMARD, deviation_levels_and_phase, phase_parts, variance_of_sums
from avar.stability.dynamic import small
from avar.stability.dynamic.results import DynamicDeviation
from avar.stability.shared.docstrings import PARAMETERS
from avar.stability.shared.grids import grid_factors
from avar.stability.shared.inputs import DEFAULT_CONFIDENCE, check_data, check_options, scaled
from avar.stability.shared.registry import CLASSIC, KERNEL_CODES
from avar.stability.shared.term_counts import term_counts
from avar.stability.uncertainty.chi2 import CATALOGUE_QUANTILES, chi2_bounds
from avar.stability.uncertainty.edf import estimator_edf
from avar.stability.uncertainty.total_edf import totvar_bias

#: The statistics a dynamic deviation takes: the classic family.
DYNAMIC_STATISTICS = CLASSIC
#: Stable32's rule: the largest averaging factor is a quarter of the window.
WINDOW_FRACTION = 4
#: The smallest window (in samples): one level, m = 1.
MIN_WINDOW = 4
#: The routes of :func:`avar._kernels.runtime.paths.numpy_path` (found compiled once, never asked again).
_WINDOW_ROUTE = "dynamic.window_sums"
_PHASE_ROUTE = "dynamic.phase"


class WindowLevels(NamedTuple):
    """Variances (windows x levels, in the data's units, NaN where no term is left) and term counts."""

    variance: np.ndarray
    n_terms: np.ndarray


def check_window(window: Any, step: Any, n_samples: int) -> tuple[int, int]:
    """``window`` (default a tenth of the record, at least :data:`MIN_WINDOW`) and ``step``
    (default a tenth of the window) in samples, or an error naming the argument.

    >>> check_window(None, None, 1000), check_window(100, 25, 1000)
    ((100, 10), (100, 25))
    >>> check_window(2, None, 1000)
    Traceback (most recent call last):
    ...
    ValueError: window must be a number of samples in 4 .. 1000 (the length of data), got 2
    """
    if n_samples < MIN_WINDOW:
        raise ValueError(f"data has {n_samples} sample(s); a dynamic deviation needs at least {MIN_WINDOW}")
    if window is None:
        window = max(MIN_WINDOW, n_samples // 10)
    if isinstance(window, (bool, np.bool_)) or not isinstance(window, numbers.Integral):
        raise TypeError(f"window must be an integer number of samples, got {short_repr(window)}")
    if not MIN_WINDOW <= int(window) <= n_samples:
        raise ValueError(f"window must be a number of samples in {MIN_WINDOW} .. {n_samples} (the length of data), "
                         f"got {int(window)}")
    window = int(window)
    if step is None:
        step = max(1, window // 10)
    if isinstance(step, (bool, np.bool_)) or not isinstance(step, numbers.Integral):
        raise TypeError(f"step must be an integer number of samples, got {short_repr(step)}")
    if int(step) < 1:
        raise ValueError(f"step must be a positive number of samples, got {int(step)}")
    return window, int(step)


def window_factors(statistic: str, window: int, rate: float, taus: Any) -> np.ndarray:
    """Averaging factors 1 <= m <= window / 4 of a named grid or explicit taus (s), as Stable32.

    >>> window_factors("oadev", 100, 1.0, "octave").tolist(), window_factors("oadev", 100, 10.0, [0.1, 2.5]).tolist()
    ([1, 2, 4, 8, 16], [1, 25])
    """
    largest = window // WINDOW_FRACTION
    return grid_factors(taus, rate, largest, first_octave=0,
                        context=f"of a dynamic {statistic} (averaging factors 1..{largest}: a quarter of the window "
                                f"of {window} samples, at rate = {rate:g} Hz)")


def _check_statistic(statistic: Any) -> str:
    if not isinstance(statistic, str) or statistic not in DYNAMIC_STATISTICS:
        raise ValueError(f"statistic must be one of {', '.join(DYNAMIC_STATISTICS)} (the classic family), "
                         f"got {short_repr(statistic)}")
    return statistic


def window_levels(statistic: str, values: np.ndarray, data_type: str, rate: float, scanned: tuple,
                  factors: np.ndarray, starts: np.ndarray, window: int) -> WindowLevels:
    """The variance and term count of every window (rows) at every level (columns), in the units
    of ``values``: one pass over the record's terms per level; TOTDEV window by window."""
    n_windows, n_levels = starts.size, factors.size
    if statistic == "totdev":
        variance = np.empty((n_windows, n_levels))
        counts = np.empty((n_windows, n_levels), dtype=np.int64)
        for w, start in enumerate(starts.tolist()):
            levels = deviation_levels_and_phase(statistic, values[start:start + window], factors, data_type, rate)
            variance[w], counts[w] = levels.variance, levels.n_terms
        return WindowLevels(variance, counts)
    if numpy_path(values.size, small.PHASE_LIMIT, PHASE_KERNELS, route=_PHASE_ROUTE):  # cold: NumPy, bit for bit
        hi, lo, scale, mode, bad = small.twin_phase_parts(values, data_type, statistic, scanned)
    else:
        hi, lo, scale, mode, bad, *_ = phase_parts(values, data_type, statistic, scanned)
    bad = np.zeros(1, dtype=np.int64) if bad is None else np.ascontiguousarray(bad, dtype=np.int64)
    points = window + (data_type == "freq")
    full = term_counts(statistic, points, factors)
    sums = np.empty((n_levels, n_windows))
    counts = np.empty((n_levels, n_windows), dtype=np.int64)
    code = KERNEL_CODES[statistic]
    strided = statistic in ("adev", "hdev")

    if numpy_path(lambda: small.twin_work(hi.shape[0], factors, n_windows, full), small.TWIN_LIMIT, (window_sums,),
                  route=_WINDOW_ROUTE):  # cold kernel, small work: the NumPy twin (nothing to compile)
        for i, m in enumerate(factors.tolist()):
            sums[i], counts[i] = small.window_sums(hi, lo, code, m, m if strided else 1, starts, int(full[i]), mode,
                                                   bad)
    else:
        def level(i: int) -> None:  # nogil: the levels run on the threads, each into its own row
            m = int(factors[i])
            window_sums(hi, lo, code, m, m if strided else 1, starts, int(full[i]), mode, bad, sums[i], counts[i])

        run_tasks(n_levels, level)
    variance = variance_of_sums(statistic, sums.T, counts.T, factors[None, :], scale, data_type, rate)
    return WindowLevels(variance, np.ascontiguousarray(counts.T))


def window_noise(statistic: str, values: np.ndarray, data_type: str, rate: float, factors: np.ndarray,
                 starts: np.ndarray, window: int) -> np.ndarray:
    """The noise exponent of every window at every level, by the statistic's own rules, on the
    window's phase as the public function builds it (its mean frequency removed; phase data
    keep their frequency offset for the lag-1 rule); a window with gaps on its longest gap-free
    stretch (:func:`avar.stability.classic.deviations.noise_exponents`); 0 for a window without
    four finite values."""
    alpha = np.zeros((starts.size, factors.size), dtype=np.int64)
    ramp = np.arange(window, dtype=np.float64)
    for w, start in enumerate(starts.tolist()):
        part = values[start:start + window]
        finite = np.isfinite(part)
        if finite.all():
            if data_type == "freq":
                phase, line = np.concatenate(([0.0], np.cumsum(part - part.mean()))), None
            else:
                line = (part[-1] - part[0]) / (window - 1)
                phase = part - part[0] - line * ramp
            alpha[w] = classic.noise_of_levels(statistic, phase, 0.0, factors, line)
        elif np.count_nonzero(finite) >= MIN_WINDOW:
            alpha[w] = classic.noise_exponents(statistic, part, data_type, rate, factors)
    return alpha


def window_edf(statistic: str, alpha: np.ndarray, factors: np.ndarray, window: int, data_type: str,
               n_terms: np.ndarray, gaps: np.ndarray) -> np.ndarray:
    """The EDF of every window and level: the statistic's (Greenhall's; TOTDEV: NIST SP 1065's) for
    a window of ``window`` samples, computed once per noise exponent; scaled by the fraction of the
    terms used in windows with gaps (``gaps``: one flag per window), never below 1."""
    points = window + (data_type == "freq")
    table = np.stack([estimator_edf(statistic, np.full(factors.size, a), factors, points, n_given=window)
                      for a in range(-2, 3)])
    edf = table[alpha + 2, np.arange(factors.size)[None, :]]
    if gaps.any():
        scaled_edf = np.maximum(edf * n_terms / term_counts(statistic, points, factors)[None, :], 1.0)
        edf = np.where(gaps[:, None], scaled_edf, edf)
    return np.where(n_terms > 0, edf, np.nan)


def dynamic(statistic: str, data: Any, rate: float | None = None, data_type: str = "freq", window: int | None = None,
            step: int | None = None, taus: Any = "octave", confidence: float = DEFAULT_CONFIDENCE,
            nan_policy: str = "raise") -> DynamicDeviation:
    """A classic deviation in every window of ``window`` samples, stepped by ``step`` samples.

    Stable32's dynamic stability (DAVAR): window ``w`` holds the samples ``w step .. w step +
    window - 1``, and each of its levels is exactly what ``avar.<statistic>`` gives for those
    samples alone (the deviation, term count, noise exponent, EDF and bounds, TOTDEV with its
    bias removed), at the factors m = 1 .. window / 4 of the tau grid (Stable32's rule: the
    largest tau a quarter of the window). A window's sums come from prefix sums of the
    record's terms, O(N) per level for all windows together (TOTDEV: window by window); the
    noise identification runs on each window.
    {parameters}
    Returns
    -------
    DynamicDeviation
        ``times`` (the windows' centres, s), ``taus``, ``deviation`` (windows x taus), ``lci``,
        ``uci``, ``n_terms``, ``alpha``, ``edf``, ``record`` (the statistic of the whole record),
        ``summary()``, ``unstable()``, ``plot()``.

    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> y = np.random.default_rng(1).standard_normal(4000) * np.repeat([1.0, 3.0], 2000)
    >>> res = avar.dynamic("oadev", y, window=1000, step=500, taus=[1, 4])
    >>> res.deviation.shape, res.times.tolist()
    ((7, 2), [500.0, 1000.0, 1500.0, 2000.0, 2500.0, 3000.0, 3500.0])
    >>> (res.deviation[-1] / res.deviation[0]).round()   # the level tripled halfway
    array([3., 3.])
    """
    statistic = _check_statistic(statistic)
    rate = check_options(statistic, data, rate, data_type, confidence, nan_policy)
    drift_removed = statistic in HADAMARD and data_type == "freq"
    values, scanned = check_data(data, data_type, nan_policy, weigh=drift_removed)
    window, step = check_window(window, step, values.size)
    factors = window_factors(statistic, window, rate, taus)
    starts = np.arange(0, values.size - window + 1, step, dtype=np.int64)
    record = getattr(classic, statistic)(values, rate=rate, data_type=data_type, taus=factors / rate,
                                         confidence=confidence, nan_policy=nan_policy)
    values, scanned, exponent = scaled(values, scanned, drift_removed)
    variance, n_terms = window_levels(statistic, values, data_type, rate, scanned, factors, starts, window)
    alpha = window_noise(statistic, values, data_type, rate, factors, starts, window)
    if statistic == "totdev":  # as avar.totdev: TOTVAR's bias removed, T the window's length
        variance = variance / totvar_bias(alpha, factors[None, :], window)
    prefix = np.concatenate(([0], np.cumsum(np.isnan(values))))
    gaps = prefix[starts + window] - prefix[starts] > 0  # the windows with NaN
    edf = window_edf(statistic, alpha, factors, window, data_type, n_terms, gaps)
    # a stationary record's windows share its noise: the whole record identifies it far better than
    # a window does (few averages at long taus), so the bands of unstable() take the record's alpha
    stationary = np.broadcast_to(np.asarray(record.alpha), alpha.shape)
    band_edf = window_edf(statistic, stationary, factors, window, data_type, n_terms, gaps)
    with np.errstate(over="ignore", under="ignore"):
        deviation = np.ldexp(np.sqrt(variance), exponent)
        variance = np.ldexp(variance, 2 * exponent)
    lci = np.full(deviation.shape, np.nan)
    uci = np.full(deviation.shape, np.nan)
    finite = np.isfinite(deviation) & np.isfinite(edf)
    lci[finite], uci[finite] = chi2_bounds(deviation[finite], edf[finite], float(confidence),
                                           quantiles=CATALOGUE_QUANTILES)
    centre = window / 2 if data_type == "freq" else (window - 1) / 2
    return DynamicDeviation(
        times=(starts + centre) / rate, starts=starts, taus=factors / rate, averaging_factors=factors,
        deviation=deviation, variance=variance, n_terms=n_terms, alpha=alpha, edf=edf, lci=lci, uci=uci,
        band_edf=band_edf, record=record, estimator=statistic, data_type=data_type, rate=rate, window=window, step=step,
        n_samples=values.size, confidence=float(confidence),
    )


def dadev(data: Any, rate: float | None = None, data_type: str = "freq", window: int | None = None,
          step: int | None = None, taus: Any = "octave", confidence: float = DEFAULT_CONFIDENCE,
          nan_policy: str = "raise") -> DynamicDeviation:
    """Dynamic Allan deviation: :func:`avar.oadev` in every window (:func:`dynamic` of ``"oadev"``).

    Each window's row equals ``avar.oadev`` of its samples; taus up to a quarter of the window.
    {parameters}
    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> res = avar.dadev(np.random.default_rng(0).standard_normal(2000), window=400, step=200)
    >>> res.deviation.shape, res.averaging_factors.tolist()
    ((9, 7), [1, 2, 4, 8, 16, 32, 64])
    """
    return dynamic("oadev", data, rate, data_type, window, step, taus, confidence, nan_policy)


def dhdev(data: Any, rate: float | None = None, data_type: str = "freq", window: int | None = None,
          step: int | None = None, taus: Any = "octave", confidence: float = DEFAULT_CONFIDENCE,
          nan_policy: str = "raise") -> DynamicDeviation:
    """Dynamic Hadamard deviation: :func:`avar.ohdev` in every window (:func:`dynamic` of ``"ohdev"``).

    Each window's row equals ``avar.ohdev`` of its samples (blind to each window's linear
    frequency drift); taus up to a quarter of the window.
    {parameters}
    Examples
    --------
    >>> import numpy as np
    >>> import avar
    >>> y = np.random.default_rng(0).standard_normal(2000)
    >>> plain = avar.dhdev(y, window=400, step=200)
    >>> drifted = avar.dhdev(y + 1e-3 * np.arange(2000), window=400, step=200)   # a linear frequency drift
    >>> plain.deviation.shape, bool(np.allclose(drifted.deviation, plain.deviation, rtol=1e-9))
    ((9, 7), True)
    """
    return dynamic("ohdev", data, rate, data_type, window, step, taus, confidence, nan_policy)


#: What :func:`dadev` and :func:`dhdev` return, and where the statistic comes from.
_RETURNS_AND_REFERENCES = """    Returns
    -------
    DynamicDeviation
        As :func:`dynamic`.

    References
    ----------
    L. Galleani and P. Tavella, "The dynamic Allan variance", IEEE Trans. UFFC 56, 2009.
    W. J. Riley, Stable32 User Manual (Dynamic stability), 2008.

"""

_WINDOW_PARAMETERS = """    window : int, optional
        Samples per window (frequency values or phase points, as ``data``); default a tenth of
        the record (at least 4). The taus reach a quarter of it.
    step : int, optional
        Samples from one window's start to the next; default a tenth of the window (at least 1).
"""


def _fill(function: Any, first: str = "", after: str = "") -> None:
    """Put the family's parameters (``first`` before ``data``; ``window`` and ``step`` before
    ``taus``; no ``Returns``), then ``after``, in the docstring."""
    parameters = PARAMETERS.split("\n\n    Returns")[0]
    data, taus = parameters.index("    data :"), parameters.index("    taus :")
    text = parameters[:data] + first + parameters[data:taus] + _WINDOW_PARAMETERS + parameters[taus:] + "\n\n" + after
    function.__doc__ = function.__doc__.replace("    {parameters}\n", text)


_fill(dynamic, """    statistic : str
        One of the classic family (:data:`DYNAMIC_STATISTICS`): ``"adev"``, ``"oadev"``, ``"mdev"``,
        ``"tdev"``, ``"hdev"``, ``"ohdev"``, ``"totdev"``, ``"mhdev"``, ``"htdev"``.
""")
_fill(dadev, after=_RETURNS_AND_REFERENCES)
_fill(dhdev, after=_RETURNS_AND_REFERENCES)
