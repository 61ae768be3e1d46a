"""The computational core of the deviation family: variances and term counts per level.

:func:`deviation_levels` turns clean float64 data (NaN marks a gap) into the
variance and the number of terms of every level, through the kernels of
:mod:`avar._kernels.classic.levels` (ADEV and HDEV of gap-free frequency data at
the octave factors m = 1, 2, 4, ...: the Haar pyramid of
:mod:`avar._kernels.classic.pyramid`, one read of the data).
:func:`deviation_levels_and_phase` also hands back what the noise
identification needs without another pass over the data: the detrended phase
it built, or, from the pyramid, an :class:`OctaveMoments`. It validates
nothing: the public functions of :mod:`avar.stability.classic.deviations` do, once.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from avar._kernels.allan.columns import run_sweep, sweep_kernels
from avar._kernels.classic.levels import detrended_phase, level_kernels, level_sums, scan
from avar._kernels.classic.phase import PHASE_KERNELS, centred_moment
from avar._kernels.classic.pyramid import MOMENTS, OCTAVE_KERNELS, SUM_COLUMN, TAIL, octave_moments
from avar._kernels.runtime.paths import compiled, numpy_path, path_mode
from avar._kernels.uncertainty.noise_id import lag1_alpha_from_moments, rn_clusters
from avar.stability.classic.small import level_sums as small_level_sums
from avar.stability.shared.registry import KERNEL_CODES
from avar.stability.shared.term_counts import term_counts, term_ranges

#: Denominator constant of every estimator: sigma^2 = sum / (K m^2 tau0^2 n) (MDEV, MHDEV: K m^4 tau0^2 n).
_K = {"adev": 2.0, "oadev": 2.0, "mdev": 2.0, "tdev": 2.0, "hdev": 6.0, "ohdev": 6.0, "totdev": 2.0,
      "mhdev": 6.0, "htdev": 6.0}
#: The estimators blind to a linear frequency drift (the phase parts remove it), and those summed
#: as differences of the phase's running sum (the modified ones).
HADAMARD = ("hdev", "ohdev", "mhdev", "htdev")
MODIFIED = ("mdev", "tdev", "mhdev", "htdev")
#: The time deviations: tau^2 / TIME_FACTOR times their modified variance (TDEV: 3, HTDEV: 10 / 3).
TIME_FACTOR = {"tdev": 3.0, "htdev": 10.0 / 3.0}


_NO_LO = np.zeros(1, dtype=np.float32)
#: Gap-free records of at most NUMPY_SAMPLES points whose levels hold at most NUMPY_TERMS terms
#: in all (plus one per phase point) take the NumPy path while the kernels are cold
#: (:func:`numpy_levels`): well under the compilation's seconds (0.05 s for the octave levels
#: of 2**18 points, 0.6 s for TOTDEV's 1e4 levels of 1e4 points); longer records compile, as before.
NUMPY_SAMPLES = 1 << 18
NUMPY_TERMS = 1 << 27
#: Gap-free frequency data of at least this many values at the octave factors: OADEV's levels by
#: the "mo" Allan variance's sweep (:func:`oadev_by_sweep`), which never builds the phase, once its
#: kernels are compiled (see :func:`_sweeps`).
SWEEP_SAMPLES = 1 << 16


def _filled(data: np.ndarray, is_phase: bool, n_missing: int) -> tuple[np.ndarray, np.ndarray | None]:
    """Data with NaN filled (any finite value keeps the terms exact) and the prefix count of gaps."""
    if n_missing == 0:
        return data, None
    missing = np.isnan(data)
    bad = np.concatenate(([0], np.cumsum(missing, dtype=np.int64)))
    good = np.flatnonzero(~missing)
    filled = data.copy()
    if is_phase:  # linear interpolation keeps the increments small
        filled[missing] = np.interp(np.flatnonzero(missing), good, data[good])
    else:
        filled[missing] = data[good].mean()
    return filled, bad


def _drift(data: np.ndarray, is_phase: bool, moment: float = np.nan) -> float:
    """Least-squares slope of the increments (the frequency, or the phase's differences)
    against their index, rounded so that ``slope * i`` is exact for every index (the
    Hadamard family removes it). ``moment``: their centred moment if already known (NaN
    if not: :func:`scan` finds it for gap-free frequency data)."""
    count = data.shape[0] - int(is_phase)
    if count < 3:
        return 0.0
    if np.isnan(moment):
        moment = centred_moment(data, int(is_phase))
    slope = moment / (count * (count * count - 1.0) / 12.0)
    if slope == 0.0 or not np.isfinite(slope):
        return 0.0
    _, exponent = np.frexp(slope)
    bits = 52 - int(count).bit_length()
    return float(np.ldexp(np.round(np.ldexp(slope, bits - int(exponent))), int(exponent) - bits))


def _kept_drift(slope: float, count: int, low: float, high: float) -> float:
    """``slope``, or 0.0 where removing it conditions nothing: its excursion of the phase over
    the ``count`` frequency values, at most ``|slope| count**2 / 8`` about its line, within
    what their spread less the drift's own, ``high - low - |slope| (count - 1)``, makes a
    noise-like phase wander over (times sqrt(count)). The Hadamard family is blind to the
    drift and the noise identification sees it either way (it gets a removed drift back), so
    this saves one TwoSum per value, not a digit.

    >>> _kept_drift(1e-22, 10**6, -5e-11, 5e-11), _kept_drift(1e3, 48, 0.0, 4.7e4)
    (0.0, 1000.0)
    """
    spread = (high - low) - abs(slope) * (count - 1.0)
    if slope == 0.0 or not (spread > 0.0 and abs(slope) * (count * float(count)) / 8.0 <= spread * np.sqrt(count)):
        return slope
    return 0.0


def _scale(low: float, high: float, origin: float) -> float:
    """A power of two that brings the data's span about ``origin`` near 1 (no overflow, exact)."""
    with np.errstate(over="ignore"):
        span = max(high - origin, origin - low)
    _, exponent = np.frexp(span if np.isfinite(span) and span > 0 else 1.0)
    return float(np.ldexp(1.0, -int(np.clip(exponent, -1000, 1000))))


class PhaseParts(NamedTuple):
    """The compensated, detrended, scaled phase of the data and what the kernels need (:func:`phase_parts`)."""

    hi: np.ndarray
    lo: np.ndarray
    scale: float
    mode: int
    bad: np.ndarray | None
    phase: np.ndarray
    drift: float
    line: float | None


class DeviationLevels(NamedTuple):
    """Variances and term counts of every level (:func:`deviation_levels`)."""

    variance: np.ndarray
    n_terms: np.ndarray


class LevelsAndPhase(NamedTuple):
    """Variances and term counts of every level, and what the noise identification needs
    (:func:`deviation_levels_and_phase`)."""

    variance: np.ndarray
    n_terms: np.ndarray
    phase: np.ndarray | OctaveMoments
    drift: float
    line: float | None


class OctaveMoments(NamedTuple):
    """What the noise identification of the pyramid's levels needs (see :mod:`avar._kernels.classic.pyramid`).

    ``stats``: the moments of every level (columns ``MOMENTS``); ``tails``:
    the cluster sums of the levels with at most ``TAIL`` clusters;
    ``phase()``: builds the detrended phase (one O(N) pass), for the rare
    level the moments cannot decide; ``clusters(step)``: the phase at every
    ``step``-th point and its running sum there, for R(n).
    """

    stats: np.ndarray
    tails: np.ndarray
    phase: Callable[[], np.ndarray]
    clusters: Callable[[int], tuple[np.ndarray, np.ndarray]]


def octave_sums(estimator: str, data: np.ndarray, factors: np.ndarray, scanned: tuple):
    """ADEV/HDEV of gap-free frequency data at m = 1, 2, 4, ... by the Haar pyramid
    (:mod:`avar._kernels.classic.pyramid`): ``sums, counts, scale, moments, drift``."""
    _, total, low, high, moment = scanned
    count = data.shape[0]
    slope = _kept_drift(_drift(data, False, moment), count, low, high) if estimator == "hdev" else 0.0
    centre = total / count - slope * (count - 1) / 2
    scale = _scale(low, high, centre)
    stats = np.zeros((factors.size, len(MOMENTS)))
    tails = np.zeros((factors.size, TAIL))
    order = 1 if estimator == "adev" else 2
    octave_moments(data, float(centre), slope, scale, order, factors.size, stats, tails)
    sums = np.ascontiguousarray(stats[:, SUM_COLUMN[order]])

    def phase() -> np.ndarray:
        return phase_parts(data, "freq", estimator, scanned, True).phase

    def clusters(step: int) -> tuple[np.ndarray, np.ndarray]:
        z = np.empty(count // step + 1)
        running = np.empty((count + 1) // step + 1)
        rn_clusters(data, float(centre), slope, scale, step, z, running)
        return z, running

    moments = OctaveMoments(stats, tails, phase, clusters)
    return sums, term_counts(estimator, count + 1, factors), scale, moments, slope * scale


def _is_octave(factors: np.ndarray) -> bool:
    return bool(factors.size) and bool(np.array_equal(factors, 2 ** np.arange(factors.size, dtype=np.int64)))


class PhaseLine(NamedTuple):
    """What the detrended phase of the data removes, and its scale (:func:`phase_line`)."""

    filled: np.ndarray
    bad: np.ndarray | None
    count: int
    centre: float
    slope: float
    scale: float


def phase_line(data: np.ndarray, data_type: str, estimator: str, scanned: tuple | None = None,
               small_drift: bool = False) -> PhaseLine:
    """The data with their gaps filled, the prefix count of gaps (None: no gap), the number of
    phase increments, and the line ``centre + slope i`` the increments lose (their mean and, for
    the Hadamard family, their linear drift) before they are scaled by the power of two ``scale``
    (see :func:`phase_parts`). ``small_drift``: frequency data keep a drift too small to matter
    (:func:`_kept_drift`; slope 0)."""
    is_phase = data_type == "phase"
    n_missing, total, low, high, moment = scan(data) if scanned is None else scanned
    filled, bad = _filled(data, is_phase, n_missing)
    count = filled.shape[0] - 1 if is_phase else filled.shape[0]
    slope = 0.0
    if estimator in HADAMARD:
        slope = _drift(filled, is_phase, np.nan if is_phase else moment)
        if small_drift and not is_phase:
            slope = _kept_drift(slope, count, low, high)
    if is_phase:
        centre = (filled[-1] - filled[0]) / count - slope * (count - 1) / 2
        origin = filled[0]
    else:
        centre = total / (count - n_missing) - slope * (count - 1) / 2
        origin = centre
    return PhaseLine(filled, bad, count, float(centre), slope, _scale(low, high, origin))


def phase_parts(data: np.ndarray, data_type: str, estimator: str, scanned: tuple | None = None,
                small_drift: bool = False) -> PhaseParts:
    """The compensated, detrended, scaled phase of ``data`` and what the kernels need.

    Returns ``hi, lo, scale, mode, bad``: the phase ``(hi + lo) / scale`` (in
    the data's units for phase data, in frequency units times samples for
    frequency data) with its mean frequency (and, for HDEV and OHDEV, its
    linear frequency drift) removed, the gap mode and the prefix count of
    gaps (see :mod:`avar._kernels.classic.levels`); then ``phase``, the
    detrended phase ``hi`` itself (for MDEV and MHDEV, before its running sum),
    ``drift``: ``phase`` lacks ``drift * k (k - 1) / 2`` (the Hadamard family's
    removed linear frequency drift), and ``line``: for phase data, ``phase``
    lacks ``line * k`` too (their frequency offset, which Stable32's noise
    identification sees); None for frequency data. ``scanned``: :func:`scan`
    of ``data`` if already known; ``small_drift`` as in :func:`phase_line`.
    """
    is_phase = data_type == "phase"
    filled, bad, count, centre, slope, scale = phase_line(data, data_type, estimator, scanned, small_drift)
    hi = np.empty(count + 1)
    lo = np.empty(count + 1, dtype=np.float32)
    detrended_phase(filled, _NO_LO, int(is_phase), float(centre), slope, scale, hi, lo)
    phase = hi
    if estimator in MODIFIED:  # MDEV's (MHDEV's) terms are third (fourth) differences of the running sum
        running_hi = np.empty(count + 2)
        running_lo = np.empty(count + 2, dtype=np.float32)
        detrended_phase(hi, lo, 2, float(np.mean(hi)), 0.0, 1.0, running_hi, running_lo)
        hi, lo = running_hi, running_lo
    mode = 0 if bad is None else (1 if is_phase else 2)
    return PhaseParts(hi, lo, scale, mode, bad, phase, slope * scale, (centre * scale if is_phase else None))


def deviation_levels(
    estimator: str, data: np.ndarray, factors: np.ndarray, data_type: str = "phase", rate: float = 1.0
) -> DeviationLevels:
    """Variance and number of terms of one estimator at every averaging factor.

    Parameters
    ----------
    estimator : {"adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev", "mhdev", "htdev"}
    data : float64 ndarray
        Phase (s) or fractional frequency; NaN marks a gap, and the terms
        that touch one are skipped (see :mod:`avar._kernels.classic.levels`).
    factors : int64 ndarray
        Averaging factors m, each within the estimator's range.
    data_type : {"phase", "freq"}
    rate : float
        Sampling rate (Hz).

    Returns
    -------
    DeviationLevels
        ``variance`` (float64 ndarray): the estimator's variance (TDEV: s^2; the others
        dimensionless), NaN where no term is left; ``n_terms`` (int64 ndarray): terms
        averaged at every level.

    Examples
    --------
    >>> import numpy as np
    >>> y = np.array([0.0, 1.0, 0.0, 1.0, 0.0])
    >>> levels = deviation_levels("oadev", y, np.array([1, 2]), data_type="freq")
    >>> levels.variance.tolist(), levels.n_terms.tolist()
    ([0.5, 0.0], [4, 2])
    """
    levels = deviation_levels_and_phase(estimator, data, factors, data_type, rate)
    return DeviationLevels(levels.variance, levels.n_terms)


def deviation_levels_and_phase(estimator: str, data: np.ndarray, factors: np.ndarray, data_type: str = "phase",
                               rate: float = 1.0, scanned: tuple | None = None) -> LevelsAndPhase:
    """:func:`deviation_levels` and what the noise identification needs.

    Returns ``variance, n, phase, drift, line``: ``phase`` the detrended phase it
    used (scaled by a power of two, as in :func:`phase_parts`) or, on the
    pyramid's path (frequency data), an :class:`OctaveMoments`; ``drift`` and
    ``line`` as in :func:`phase_parts`.
    """
    factors = np.asarray(factors, dtype=np.int64)
    n_phase = data.shape[0] + (data_type == "freq")
    scanned = scan(data) if scanned is None else scanned
    small = numpy_levels(estimator, data, factors, data_type, scanned)
    if small is not None:  # a short gap-free record, certified: nothing compiled
        sums, counts, scale, phase, drift, line = small
    elif estimator in ("adev", "hdev") and data_type == "freq" and scanned[0] == 0 and _is_octave(factors):
        sums, counts, scale, phase, drift = octave_sums(estimator, data, factors, scanned)
        line = None
    elif _sweeps(estimator, data, factors, data_type, scanned):
        return oadev_by_sweep(data, factors, scanned)
    else:
        hi, lo, scale, mode, bad, phase, drift, line = phase_parts(data, data_type, estimator, scanned, True)
        strides, first, last = term_ranges(estimator, n_phase, factors)
        sums, counts = level_sums(hi, lo, KERNEL_CODES[estimator], factors, strides, first, last, mode, bad)
    variance = variance_of_sums(estimator, sums, counts, factors, scale, data_type, rate)
    return LevelsAndPhase(variance, counts, phase, drift, line)


def _sweeps(estimator: str, data: np.ndarray, factors: np.ndarray, data_type: str, scanned: tuple) -> bool:
    """Whether OADEV takes :func:`oadev_by_sweep`: gap-free frequency data of at least
    :data:`SWEEP_SAMPLES` values at the octave factors, once the sweep's and the pyramid's kernels
    are compiled (``avar warmup``, a long ``avar()`` call, numba's cache) or the compiled path is
    forced. Before, the phase path runs: its kernels compile in about half the time (a first
    call on 2e6 values, empty cache: 8.5-9 s against 13-15 s, loaded machine), the same values."""
    if not (estimator == "oadev" and data_type == "freq" and scanned[0] == 0 and data.shape[0] >= SWEEP_SAMPLES
            and _is_octave(factors)):
        return False
    return path_mode() == "compiled" or compiled((*sweep_kernels(data[:, None]), *OCTAVE_KERNELS))


def oadev_by_sweep(data: np.ndarray, factors: np.ndarray, scanned: tuple) -> LevelsAndPhase:
    """OADEV of gap-free frequency data at the octave factors without its phase: the variances are
    the "mo" Allan variance of the data (the same sums of squared differences of m-point sums,
    N + 1 - 2m of them), by its sweep of moving sums by pairs (:func:`avar._kernels.allan.columns.run_sweep`,
    certified, compensated where a level needs it; about half the work of the phase and its
    levels), and the noise identification reads the moments of ADEV's Haar pyramid (the same
    decimated phase x_0, x_m, x_2m, ...), as ADEV's does."""
    counts = term_counts("oadev", data.shape[0] + 1, factors)
    variance = run_sweep(data[:, None], factors, counts)[0]
    _, _, _, moments, _ = octave_sums("adev", data, factors, scanned)
    return LevelsAndPhase(np.where(counts == 0, np.nan, variance), counts, moments, 0.0, None)


class NumpyLevels(NamedTuple):
    """The sums of a short record's levels by :mod:`avar.stability.classic.small` (:func:`numpy_levels`)."""

    sums: np.ndarray
    counts: np.ndarray
    scale: float
    phase: np.ndarray
    drift: float
    line: float | None


def numpy_levels(estimator: str, data: np.ndarray, factors: np.ndarray, data_type: str,
                 scanned: tuple) -> NumpyLevels | None:
    """The sums of squared terms of every level in NumPy (:mod:`avar.stability.classic.small`:
    nothing to compile) for gap-free data of at most :data:`NUMPY_SAMPLES` points whose levels hold
    at most :data:`NUMPY_TERMS` terms in all while the kernels this call would run are not
    compiled yet (or when
    :mod:`avar._kernels.runtime.paths` forces NumPy); None otherwise, or where the NumPy path
    cannot certify its error (the compiled kernels then run). ``scale``, ``phase``, ``drift``
    and ``line`` as in :func:`phase_parts`."""
    n_phase = data.shape[0] + (data_type == "freq")
    strides, first, last = term_ranges(estimator, n_phase, factors)
    counts = last - first

    def kernels() -> tuple:  # the compiled route this call would take
        if estimator in ("adev", "hdev") and data_type == "freq" and _is_octave(factors):
            return (lag1_alpha_from_moments,)  # the pyramid's (its noise identification, compiled with it)
        if _sweeps(estimator, data, factors, data_type, scanned):  # and ADEV's pyramid
            return (*sweep_kernels(data[:, None]), lag1_alpha_from_moments)
        return PHASE_KERNELS + level_kernels(KERNEL_CODES[estimator], strides)

    if scanned[0] != 0 or not numpy_path(lambda: int(np.maximum(counts, 0).sum()) + n_phase, NUMPY_TERMS, kernels,
                                         fits=n_phase <= NUMPY_SAMPLES):
        return None
    is_phase = data_type == "phase"
    _, _, _, centre, slope, scale = phase_line(data, data_type, estimator, scanned)
    levels = small_level_sums(data, int(is_phase), centre, slope, scale, KERNEL_CODES[estimator], factors, strides,
                              counts)
    if levels is None:
        return None
    return NumpyLevels(levels.sums, levels.counts, scale, levels.phase, levels.slope * scale,
                       levels.centre * scale if is_phase else None)


def variance_of_sums(estimator: str, sums: np.ndarray, counts: np.ndarray, factors: np.ndarray, scale: float,
                     data_type: str, rate: float) -> np.ndarray:
    """The variances of the levels from their sums of squared terms and term counts (NaN where
    no term is left): sum / (K m^2 counts) (modified: K m^4), in the units of the data once
    ``scale`` (the phase's power of two) is undone; TDEV and HTDEV times tau^2 / 3 and
    tau^2 / (10 / 3).

    >>> variance_of_sums("oadev", np.array([8.0]), np.array([4]), np.array([1]), 1.0, "freq", 1.0).tolist()
    [1.0]
    """
    m = np.asarray(factors).astype(np.float64)
    denominator = _K[estimator] * m * m * (m * m if estimator in MODIFIED else 1.0)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        variance = sums / (denominator * counts) / scale / scale
        if data_type == "phase":
            variance = variance * rate * rate
        if estimator in TIME_FACTOR:
            tau = m / rate
            variance = variance * tau * tau / TIME_FACTOR[estimator]
    variance = np.where(np.asarray(counts) == 0, np.nan, variance)
    return variance
