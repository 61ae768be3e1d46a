"""Power-law noise identification per averaging factor: :func:`identify_noise`.

The dominant power-law noise S_y(f) ~ f**alpha at each level, as Stable32
does it: the lag-1 autocorrelation of the decimated and differenced phase
(Riley and Greenhall 2004) where at least 30 frequency averages remain,
Barnes's B1 ratio (with the R(n) ratio to split white from flicker PM) where
fewer remain, and the previous level's alpha where too few remain for B1
(Stable32's thresholds, per estimator). Each level costs O(N / m) after one
pass over the data.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from avar._validation import short_repr
from avar.stability.shared.term_counts import term_counts
from avar.stability.shared.term_counts import term_counts as total_term_counts
from avar.stability.uncertainty.lag1 import lag1_alphas, running_sums

#: The lag-1 autocorrelation is used where at least this many frequency averages K = (N - 1) // m remain
#: (Stable32 switches to B1 at K = 29: its MDEV table of an OCXO's 19,982 readings, m = 659 -> 672).
MIN_ACF_POINTS = 30
#: The B1 ratio needs at least this many averages (with 2, B1 = 1 for every noise).
MIN_B1_POINTS = 3
#: Stable32 reads B1 only where at least this many frequency averages K remain (ADEV and
#: HDEV 10, TOTDEV 4, MTOTDEV, TTOTDEV and HTOTDEV 6, the others 8); at a level with fewer,
#: alpha is the previous level's (its tables of PHASE.DAT, of a 10,000-point flicker FM
#: record and of a 1253-point clock record).
MIN_B1_AVERAGES = {"adev": 10, "hdev": 10, "totdev": 4, "mtotdev": 6, "ttotdev": 6, "htotdev": 6}
#: The total statistics, identified by TOTDEV's lag-1 rule (dmax = 2) and B1 with their own term count.
TOTALS = ("mtotdev", "ttotdev", "htotdev")
DEFAULT_B1_AVERAGES = 8


class NoiseRule(int):
    """The largest number of differences of the lag-1 method (an ``int``: 2, or 3 for the
    Hadamard family) that also names its estimator, whose term count sets the B1 rule."""

    estimator: str

    def __new__(cls, dmax: int, estimator: str) -> NoiseRule:
        rule = super().__new__(cls, dmax)
        rule.estimator = estimator
        return rule


#: Estimator -> its :class:`NoiseRule` (the lag-1 method's dmax, and the estimator).
NOISE_ID_ESTIMATORS = {name: NoiseRule(dmax, name) for name, dmax in
                       {"adev": 2, "oadev": 2, "mdev": 2, "tdev": 2, "totdev": 2, "hdev": 3, "ohdev": 3,
                        "mhdev": 3, "htdev": 3,
                        **dict.fromkeys(TOTALS, 2)}.items()}


def b1_rule(estimator: str | None, n: int, m: int, k: int) -> tuple[bool, int]:
    """Whether B1 decides at factor ``m`` (``k`` frequency averages of N = ``n`` phase
    points), and the sample size its theoretical values take: the estimator's term count
    n (Stable32's "#": K - 1 for ADEV, about N for the overlapping estimators), as Stable32.

    Without an estimator (a plain dmax): B1 of the K averages wherever K >= 3.

    >>> b1_rule("adev", 1001, 100, 10), b1_rule("adev", 1001, 101, 9), b1_rule("oadev", 1001, 113, 8)
    ((True, 9), (False, 8), (True, 775))
    """
    if estimator is None:
        return k >= MIN_B1_POINTS, k
    counts = total_term_counts if estimator in TOTALS else term_counts
    terms = int(counts(estimator, n, np.array([m], dtype=np.int64))[0])
    enough = k >= MIN_B1_AVERAGES.get(estimator, DEFAULT_B1_AVERAGES)
    return enough and k >= MIN_B1_POINTS, terms
#: Offsets per cluster at which R(n)'s modified Allan variance is sampled (O(N / m) per level).
RN_SUBSAMPLES = 64


def identify_noise(phase: Any, factors: Any, estimator: str, *, from_frequency: bool = False) -> np.ndarray:
    """Dominant power-law noise exponent alpha (S_y(f) ~ f**alpha) at every averaging factor.

    For each m, with N phase points:

    1. The phase is decimated to x[0], x[m], x[2m], ..., whose differences
       are the non-overlapping frequency averages of m samples (Riley and
       Greenhall 2004), for every estimator, modified ones included, as
       ``allantools.autocorr_noise_id`` does, and as Stable32 does (its MDEV
       and OADEV tables of the flicker FM record print the same alpha at
       every m; block means of the phase would miss 59 of MDEV's 113 lag-1
       rows). Averaging the phase also misidentifies flicker FM: in the
       continuous limit its twice-differenced block means have rho = -0.04
       (Greenhall's s_z with F = 1), read as random-walk FM.
    2. If at least K = floor((N - 1) / m) = 30 frequency averages remain (compiled:
       :func:`avar._kernels.uncertainty.lag1.lag1_alpha_decimated`): remove the
       mean of the decimated phase (phase data, as they are) or its line
       (``from_frequency``: the mean frequency); not a drift, as Stable32.
       Stable32's tables of a 556,990-point caesium phase record show the
       phase data's line kept: removing it misreads white FM as white PM
       where 30 to 77 averages remain (31 rows of each of its all-tau tables).
       Then with r1 the lag-1 autocorrelation of the n points left, as Stable32 forms it,
       r1 = (sum (z_i - zbar)(z_{i+1} - zbar) / n) / (sum (z_i - zbar)**2 / (n - 1)), and
       rho = r1 / (1 + r1), difference z until rho < 0.25 or d = dmax
       differences were taken (dmax = 2; 3 for the Hadamard estimators), and
       alpha = 2 - round(2 rho) - 2 d (``numpy.round``, as ``allantools``).
    3. Otherwise Barnes's B1 ratio of the K frequency averages,
       B1 = (their sample variance) / (their Allan variance), is compared
       with its values for random-walk, flicker and white FM and PM,
       B1(n, mu) (mu = 1, 0, -1, -2), at the geometric means of
       neighbours, where n is the estimator's term count (Stable32's "#"):
       K - 1 for ADEV, about N for the overlapping estimators (so that, as in
       Stable32, B1 of few averages does not reach random-walk FM there).
       For PM, R(n) = MVAR / AVAR against the geometric mean of its values
       1 / m (white PM) and that of flicker PM splits alpha = 2 from 1 (NIST
       SP 1065 section 5.6; MVAR is sampled at 64 offsets per cluster).
    4. Stable32 reads B1 only while K >= 10 averages remain for ADEV and
       HDEV, K >= 4 for TOTDEV, K >= 6 for MTOTDEV, TTOTDEV and HTOTDEV
       (which otherwise follow TOTDEV's rules, dmax = 2) and K >= 8 for the
       other estimators; beyond
       (or for a constant series) alpha is that of the nearest smaller m
       identified (or larger; 0 if none is). These rules reproduce the noise
       column of 2,415 of the 2,416 rows of Stable32's all-tau tables of ADEV,
       OADEV, MDEV, TDEV, HDEV, OHDEV and TOTDEV of its PHASE.DAT (phase
       data) and of a 10,000-point flicker FM record (frequency data).

    The result is clipped to -2 .. 2. No frequency drift is removed (as
    Stable32): remove it first if the data have one.

    Parameters
    ----------
    phase : array_like of float
        Phase (time error) data x_1..x_N, gap-free; frequency data y convert
        as x = (0, cumsum(y)) tau0.
    factors : array_like of int
        Averaging factors m, 1 <= m < N.
    estimator : str
        One of "adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "mhdev", "htdev", "totdev",
        "mtotdev", "ttotdev", "htotdev": the deviation whose levels these are (it sets dmax, B1's sample
        size and where B1 stops).
    from_frequency : bool, optional
        The phase was integrated from frequency data: the lag-1 method removes
        its line (their mean), as Stable32 removes the mean of frequency data.
        Default False: phase data, whose line (a frequency offset) the method
        sees, as Stable32.

    Returns
    -------
    ndarray of int64
        alpha per level: 2 white PM, 1 flicker PM, 0 white FM, -1 flicker FM,
        -2 random-walk FM.

    References
    ----------
    W. J. Riley and C. A. Greenhall, "Power law noise identification using
    the lag 1 autocorrelation", Proc. 18th European Frequency and Time Forum,
    2004. J. A. Barnes, "Tables of bias functions, B1 and B2, for variances
    based on finite samples of processes with power law spectral densities",
    NBS Technical Note 375, 1969. W. J. Riley, NIST SP 1065, 2008, section 5.6.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(1)
    >>> white_pm = rng.standard_normal(4096)
    >>> identify_noise(white_pm, [1, 4, 16], "oadev")
    array([2, 2, 2])
    >>> white_fm = np.cumsum(np.random.default_rng(0).standard_normal(4096))
    >>> identify_noise(white_fm, [1, 4, 16, 256], "adev")  # 256: 15 averages, by B1
    array([0, 0, 0, 0])
    """
    x = np.asarray(phase)
    if x.ndim != 1 or x.dtype.kind not in "iuf" or isinstance(phase, (bool, np.bool_)):
        raise TypeError(f"phase must be a 1-D array of real numbers, got {short_repr(phase)}")
    x = x.astype(np.float64)
    n = x.size
    if n < 4:
        raise ValueError(f"phase must hold at least 4 points, got {n}")
    if not np.isfinite(x).all():
        raise ValueError(f"phase must be finite and gap-free; first bad value at index {int(np.flatnonzero(~np.isfinite(x))[0])}")
    m = np.asarray(factors)
    if m.dtype.kind == "f" and np.isfinite(m).all() and (m == np.round(m)).all():
        m = m.astype(np.int64)
    if m.ndim != 1 or m.dtype.kind not in "iu":
        raise TypeError(f"factors must be a 1-D array of integer averaging factors, got {short_repr(factors)}")
    m = m.astype(np.int64)
    if ((m < 1) | (m >= n)).any():
        raise ValueError(f"factors must be in 1 .. {n - 1} (N = {n} phase points), got {short_repr(m.tolist())}")
    if not isinstance(estimator, str) or estimator.lower() not in NOISE_ID_ESTIMATORS:
        raise ValueError(f"estimator must be one of {list(NOISE_ID_ESTIMATORS)}, got {short_repr(estimator)}")
    if not isinstance(from_frequency, (bool, np.bool_)):
        raise TypeError(f"from_frequency must be True or False, got {short_repr(from_frequency)}")
    return phase_noise(np.ascontiguousarray(x), m, NOISE_ID_ESTIMATORS[estimator.lower()],
                       line=None if from_frequency else 0.0)


def phase_noise(x: np.ndarray, m: np.ndarray, dmax: int, drift: float = 0.0, line_free: bool = False,
                line: float | None = None) -> np.ndarray:
    """:func:`identify_noise` without validation: ``x`` contiguous finite float64 phase, ``m`` int64 in 1 .. N - 1.

    ``drift``: ``x`` is the phase less ``drift * k (k - 1) / 2`` (a removed
    linear frequency drift); every method gets it back (Stable32 identifies the
    noise of the data as they are). ``line_free``: ``x`` has no large line (its
    mean frequency was removed), so R(n)'s running sum needs no conditioning.
    ``line``: None for phase integrated from frequency data (the lag-1 method
    removes a line); for phase data, ``x`` lacks ``line * k``, which the lag-1
    method gets back (0.0: ``x`` is the phase as given).
    """
    return _fill(_raw_phase_noise(x, m, dmax, drift, line_free, line), m)


def octave_noise(stats: np.ndarray, tails: np.ndarray, m: np.ndarray, dmax: int, drift: float,
                 phase: Callable[[], np.ndarray],
                 clusters: Callable[[int], tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """:func:`phase_noise` at the octave factors ``m`` = 1, 2, 4, ... from the pyramid's moments.

    ``stats``, ``tails``: per level, the moments and the small levels'
    cluster sums of :func:`avar._kernels.classic.pyramid.octave_moments` (the phase
    is never built for them). Where B1 says PM, R(n) splits white from
    flicker from ``clusters(step)``: the phase at every ``step``-th point and
    its running sum there (:func:`avar._kernels.uncertainty.noise_id.rn_clusters`, one
    plain pass over the data). ``phase()`` builds the detrended phase, called
    only for a level whose moments lost too many digits to cancellation (a
    frequency drift far above the noise in ADEV).
    """
    from avar._kernels.uncertainty.noise_id import ILL_CONDITIONED, lag1_alpha_from_moments, moments_with_drift

    alpha = np.full(m.size, np.nan)
    undecided = []
    n = int(stats[0, 0]) + 1  # phase points
    finest = None  # (step, z, running) of the finest R(n) stride computed so far
    for i, factor in enumerate(m.tolist()):
        count = int(stats[i, 0])
        if count >= MIN_ACF_POINTS:
            # the moments are those of the phase less its drift, which the lag-1 rule sees
            row = moments_with_drift(stats[i], drift, factor) if drift else stats[i]
            alpha[i] = lag1_alpha_from_moments(row, int(dmax))
            if alpha[i] == ILL_CONDITIONED:
                undecided.append(i)
        elif (rule := b1_rule(getattr(dmax, "estimator", None), n, factor, count))[0]:
            index = np.arange(count + 1) * factor
            points = np.concatenate(([0.0], np.cumsum(tails[i, :count])))
            alpha[i] = _b1_ratio_alpha(points + drift * _triangular(index.astype(np.float64)) if drift else points,
                                       factor, rule[1])
            if np.isinf(alpha[i]):  # PM: R(n) at the stride it samples (a power of two here)
                step = max(1, factor // RN_SUBSAMPLES)
                if finest is None or step % finest[0]:  # one pass serves every coarser stride
                    finest = (step, *clusters(step))
                every = step // finest[0]
                z, running = finest[1][::every], finest[2][::every]

                def points_at(index: np.ndarray, z=z, step=step) -> np.ndarray:
                    return z[index // step] + drift * _triangular(index.astype(np.float64)) if drift else z[index // step]

                def running_at(wanted: int, running=running, step=step) -> np.ndarray:
                    assert wanted == step
                    if not drift:
                        return running
                    q = np.arange(running.size, dtype=np.float64) * step  # + drift * sum_{i < q} i (i - 1) / 2
                    return running + drift * q * (q - 1.0) * (q - 2.0) / 6.0

                alpha[i] = _rn_alpha(points_at, n, running_at, factor)
    if undecided:  # frequency data only: the lag-1 method removes the line
        alpha[undecided] = _raw_phase_noise(phase(), m[undecided], dmax, drift, line_free=True, line=None)
    return _fill(alpha, m)


def _raw_phase_noise(x: np.ndarray, m: np.ndarray, dmax: int, drift: float, line_free: bool,
                     line: float | None) -> np.ndarray:
    """:func:`phase_noise` before the levels without an estimate are filled (NaN there)."""
    n = x.size
    acf = (n - 1) // m >= MIN_ACF_POINTS
    alpha = np.full(m.size, np.nan)
    if acf.any():
        # the drift is data: the kernels add it back point by point
        alpha[acf] = lag1_alphas(x, m[acf], int(dmax), np.nan if line is None else float(line), float(drift))
    if not acf.all():
        lazy: dict[int, np.ndarray] = {}

        def points(index: np.ndarray) -> np.ndarray:  # the phase, with its drift, at these indices
            return x[index] + drift * _triangular(index.astype(np.float64)) if drift else x[index]

        def running(step: int) -> np.ndarray:  # R(n)'s running sum at every step-th index, built when needed
            if step not in lazy:
                if line_free:  # no large line to condition away: one pass, block sums
                    lazy[step] = running_sums(x, drift, step)
                else:
                    line_free_phase = _remove_line(points(np.arange(n)))
                    lazy[step] = np.concatenate(([0.0], np.cumsum(line_free_phase)))[::step]
            return lazy[step]

        for i in np.flatnonzero(~acf).tolist():
            factor = int(m[i])
            k = (n - 1) // factor
            enough, size = b1_rule(getattr(dmax, "estimator", None), n, factor, k)
            if not enough:
                continue
            alpha[i] = _b1_ratio_alpha(points(np.arange(0, k * factor + 1, factor)), factor, size)
            if np.isinf(alpha[i]):  # PM: R(n) splits white from flicker
                alpha[i] = _rn_alpha(points, n, running, factor)
    return alpha


def _triangular(k: np.ndarray) -> np.ndarray:
    return k * (k - 1.0) / 2.0


def lag1_alpha(z: np.ndarray, dmax: int) -> float:
    """alpha of phase points z by the lag-1 autocorrelation (Riley and Greenhall 2004), their mean removed.

    NaN for a constant series.

    >>> lag1_alpha(np.random.default_rng(0).standard_normal(1000), 2)
    2.0
    """
    d = 0
    while True:
        centred = z - z.mean()
        power = float(np.dot(centred, centred))
        if power == 0.0:
            return np.nan
        r1 = float(np.dot(centred[:-1], centred[1:])) / power * (z.size - 1) / z.size
        rho = r1 / (1.0 + r1)
        if rho < 0.25 or d >= dmax:
            return float(2 - np.round(2.0 * rho) - 2 * d)
        z = np.diff(z)
        d += 1


def b1_theory(k: int, mu: int) -> float:
    """Barnes's B1(K, r = 1, mu): expected sample variance / Allan variance of K averages.

    >>> round(b1_theory(10, 1), 3), round(b1_theory(10, 0), 3), b1_theory(10, -1), round(b1_theory(10, -2), 3)
    (5.0, 1.846, 1.0, 0.733)
    """
    if mu == 1:
        return k / 2.0
    if mu == 0:
        return float(k * np.log(k) / (2.0 * (k - 1.0) * np.log(2.0)))
    if mu == -1:
        return 1.0
    return (k * k - 1.0) / (1.5 * k * (k - 1.0))


def rn_boundary(m: int) -> float:
    """Geometric mean of R(n) = MVAR / AVAR for white PM (1 / m) and for flicker PM (f_h = 1 / (2 tau0))."""
    flicker = (3.0 * np.log(256.0 / 27.0) / 8.0) / ((1.038 + 3.0 * np.log(np.pi * m)) / 4.0)
    return float(np.sqrt(flicker / m))


def b1_alpha(x: np.ndarray, cumsum: Any, m: int) -> float:
    """alpha at averaging factor m by the B1 ratio and, for PM, R(n); NaN with < 3 averages.

    ``cumsum``: the running sum of ``x`` (from 0), or a callable returning it
    (called only when R(n) is needed).
    """
    k = (x.size - 1) // m
    if k < MIN_B1_POINTS:
        return np.nan
    alpha = _b1_ratio_alpha(x[: k * m + 1 : m], m)
    if np.isinf(alpha):
        table = cumsum() if callable(cumsum) else cumsum
        alpha = _rn_alpha(x.__getitem__, x.size, lambda step: table[::step], m)
    return alpha


def _b1_ratio_alpha(points: np.ndarray, m: int, size: int | None = None) -> float:
    """alpha -2, -1 or 0 by B1 of the K averages between the K + 1 decimated phase ``points``,
    against B1's theoretical values for ``size`` samples (default K); NaN when their Allan
    variance is 0; inf for PM (R(n) decides)."""
    k = points.size - 1 if size is None else size
    means = np.diff(points) / m
    allan = float(np.mean(np.diff(means) ** 2)) / 2.0
    if not allan > 0:
        return np.nan
    b1 = float(np.var(means, ddof=1)) / allan
    theory = [b1_theory(k, mu) for mu in (1, 0, -1, -2)]
    for alpha, (high, low) in zip((-2, -1, 0), zip(theory[:-1], theory[1:])):
        if b1 > np.sqrt(high * low):
            return float(alpha)
    return np.inf


def _rn_alpha(points: Any, n: int, running: Any, m: int) -> float:
    """PM: R(n), the modified over the Allan variance, at stride ~ m / 64 (both from the same phase).

    ``points(index)``: the N phase values at these indices; ``running(step)``:
    their running sum (from 0, N + 1 values) at every step-th index.
    """
    stride = max(1, m // RN_SUBSAMPLES)
    step = stride if m % stride == 0 else 1  # every index used is then a multiple of step
    start = np.arange(0, n - 3 * m + 1, stride)
    sums = running(step)[(start[:, None] + np.arange(4) * m) // step]
    block = np.diff(sums, axis=1)  # the sums of x over three consecutive blocks of m
    modified = float(np.mean((block[:, 2] - 2.0 * block[:, 1] + block[:, 0]) ** 2)) / m**2
    second = points(start + 2 * m) - 2.0 * points(start + m) + points(start)
    ratio = modified / float(np.mean(second**2))
    return 1.0 if ratio > rn_boundary(m) else 2.0


def _remove_line(x: np.ndarray) -> np.ndarray:
    """x less its least-squares line (closed form on the centred index: two passes, no linear system)."""
    t = np.arange(x.size, dtype=np.float64) - (x.size - 1) / 2.0
    slope = float(np.dot(t, x)) / float(np.dot(t, t))
    return x - (float(np.mean(x)) + slope * t)


def _fill(alpha: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Levels without an estimate take the nearest smaller m's (else larger; else 0); clip and round."""
    order = np.argsort(m, kind="stable")
    values = alpha[order]
    known = np.flatnonzero(~np.isnan(values))
    if known.size == 0:
        return np.zeros(m.size, dtype=np.int64)
    position = np.searchsorted(known, np.arange(values.size), side="right") - 1
    values = values[known[np.maximum(position, 0)]]
    out = np.empty(m.size, dtype=np.int64)
    out[order] = np.clip(values, -2, 2).astype(np.int64)
    return out
