"""ThêoH: the overlapping Allan deviation at short taus joined with bias-removed Theo1 (TheoBR) at long ones.

Howe's hybrid (Howe 2006; Howe, Taylor and Tasset 2006), as Stable32 and
NIST describe it: Theo1 reaches taus up to 0.75 (N - 1) tau0, 50 % beyond the
Allan variance, but is biased against it by a factor that depends on the
noise; TheoBR removes the bias with the data's own ratio of the two.
"""

from __future__ import annotations

import numbers
from typing import Any

import numpy as np

from avar._kernels.runtime.paths import numpy_path
from avar._kernels.runtime.tasks import run_concurrently
from avar._kernels.total.fft import HANKEL_KERNELS, autocorrelation
from avar._kernels.total.theo1 import THEO1_KERNELS, theo1_sums
from avar._kernels.total.theobr import oavar_sums
from avar._kernels.total.windows import THEO1_DIRECT_KERNELS
from avar.stability.classic.deviations import noise_exponents
from avar.stability.shared.deviation import Deviation
from avar.stability.shared.grids import deviation_factors, total_factors
from avar.stability.shared.inputs import DEFAULT_CONFIDENCE
from avar.stability.shared.noise_types import check_alpha
from avar.stability.total import small
from avar.stability.total.deviations import prepared_phase
from avar.stability.total.theobr import MIN_THEOBR_POINTS, theobr_factor
from avar.stability.uncertainty.chi2 import CATALOGUE_QUANTILES
from avar.stability.uncertainty.edf import chi2_bounds, estimator_edf
from avar.stability.uncertainty.total_edf import total_edf

#: The route of :func:`avar._kernels.runtime.paths.numpy_path` for the displayed levels.
_ROUTE = "total.theoh"
#: Stable32's ThêoH table: OADEV at its own factors (m <= N / 4) and Theo1 from m = floor(N / THEO_FROM).
THEO_FROM = 5


def _levels(n_phase: int, rate: float, taus: Any, k: float | None) -> tuple[np.ndarray, np.ndarray]:
    """OADEV's factors below ``k`` samples and Theo1's (even m) at 0.75 m >= ``k``; with ``k`` None
    Stable32's table: OADEV at its factors up to N / 4, Theo1 at its even m from floor(N / 5) (the
    two overlap between N / 5 and N / 4)."""
    if isinstance(taus, str):
        allan = deviation_factors("oadev", n_phase, rate, taus, statistic="theoh")
        theo = total_factors("theo1", n_phase, rate, taus, statistic="theoh")
        if k is None:
            return allan[allan <= n_phase // 4], theo[theo >= n_phase // THEO_FROM]
        return allan[allan < k], theo[0.75 * theo >= k]
    try:
        requested = np.atleast_1d(np.asarray(taus, dtype=np.float64))
    except (TypeError, ValueError):
        requested = np.zeros((0, 0))
    if requested.ndim != 1 or requested.size == 0:
        raise TypeError(f"taus must be 'octave', 'decade', 'all' or a non-empty 1-D array of averaging times (s), "
                        f"got {taus!r}")
    m = requested * rate
    if k is None:  # an OADEV factor where the tau is one (a whole m up to N / 4), else Theo1's
        short = (np.abs(m - np.round(m)) <= 1e-9 * np.maximum(m, 1.0)) & (np.round(m) <= n_phase // 4)
    else:
        short = m < k
    allan = (deviation_factors("oadev", n_phase, rate, requested[short], statistic="theoh") if short.any()
             else np.zeros(0, np.int64))
    theo = (total_factors("theo1", n_phase, rate, requested[~short], statistic="theoh") if (~short).any()
            else np.zeros(0, np.int64))
    return allan, theo


#: The route of :func:`avar._kernels.runtime.paths.numpy_path` for the displayed Allan levels alone.
_ALLAN_ROUTE = "total.theoh.allan"
#: Largest work (points x levels) whose Allan sums :func:`_allan_sums` leaves to NumPy while the
#: kernel is cold (one pass per level: ~0.1 s; the kernel compiles in ~0.3 s).
ALLAN_LIMIT = 1 << 24


def _allan_sums(x: np.ndarray, factors: np.ndarray) -> np.ndarray:
    """The displayed OADEV levels' sums (:func:`avar._kernels.total.theobr.oavar_sums`), by its
    NumPy twin (:func:`avar.stability.total.small.oavar_sums`, the same terms) while the kernel is cold."""
    if numpy_path(x.shape[0] * factors.shape[0], ALLAN_LIMIT, (oavar_sums,), route=_ALLAN_ROUTE):
        return small.oavar_sums(x, factors)
    return oavar_sums(x, factors)


def theoh(data: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
          confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None,
          switch: float | None = None) -> Deviation:
    """ThêoH deviation: OADEV at short taus, TheoBR at long ones::

        ThêoH^2(tau) = sigma_y^2(tau)  (overlapping AVAR, tau = m tau0)
                     = kf Theo1(m)     (tau = 0.75 m tau0, m even <= N - 1)
        kf = 1 / (n + 1) sum_{i=0}^{n} AVAR(m = 9 + 3i) / Theo1(m = 12 + 4i),  n = floor(N / 6) - 3,

    N phase points. kf removes Theo1's bias against the Allan variance for any
    noise mix without identifying it (TheoBR, Howe and Tasset 2004; Taylor
    and Howe 2010 compute it decimated; this one is exact to 1e-8). n is
    Stable32's (:func:`theobr_count`; Howe, Taylor and Tasset's fast TheoBR
    stops at floor(N / 30) - 3). The levels come
    from the tau grid of each part: OADEV's factors m (``taus`` as
    :func:`avar.oadev`) below k, Theo1's even m (``taus`` as
    :func:`avar.theo1`, tau = 0.75 m tau0) from k. Each level's noise is
    identified by the OADEV rules (at 0.75 m for Theo1 levels) or fixed by
    ``alpha``; EDF: Greenhall's OADEV EDF, then Theo1's. kf needs Theo1 at every m = 2 .. 2N / 3
    and OAVAR at N / 6 factors, all at once from FFT autocorrelations in O(N log N)
    (:func:`avar._kernels.total.theobr.theo1_every`). Where that expansion is ill-conditioned
    (wandering phase: random-walk FM) the sums come from the same expansion of the record
    less a broken line (:mod:`avar._kernels.total.split`, O(N log N) per group of factors):
    every displayed Theo1 level and OAVAR sum whose whole-record expansion may err by more
    than about 1e-10, and of kf's Theo1 sums the worst-conditioned until kf itself is good
    to 1e-8; a sum still ill-conditioned then is summed directly (O(N m)). ``n``: N - 2m
    (OADEV), (N - m) m / 2 (Theo1, as Stable32). Dimensionless.

    Parameters
    ----------
    data, rate, data_type, taus, confidence, alpha
        As :func:`avar.theo1`.
    nan_policy : {"raise", "omit"}
        ThêoH needs gap-free data: NaN raises ``ValueError`` either way.
    switch : float or None
        None (default): the levels of Stable32's ThêoH table, OADEV at its own
        factors (m <= N / 4 on the grids) and Theo1 at its even m from
        floor(N / 5): the two overlap between N / 5 and N / 4, where both are
        given (Allan levels first, then Theo1's; Stable32's tables of a
        1253-point record show exactly these rows). A fraction of the record
        in (0, 0.5] gives Howe's hybrid instead: OADEV for tau < k, TheoBR for
        tau >= k, k = ``switch`` x N tau0 (Howe uses 0.1).

    Returns
    -------
    Deviation
        ``estimator="theoh"``.

    References
    ----------
    D. A. Howe, "ThêoH: a hybrid, high-confidence statistic that improves on
    the Allan deviation", Metrologia 43, S322, 2006. D. A. Howe, J. A. Taylor
    and T. N. Tasset, "ThêoH bias-removal method", Proc. 2006 IEEE FCS.
    W. J. Riley, NIST SP 1065, 2008, section 5.2.15.

    Examples
    --------
    >>> import numpy as np, avar
    >>> y = np.random.default_rng(0).standard_normal(1000)  # white FM
    >>> res = avar.theoh(y)  # OADEV to m = N / 4, Theo1 from m = N / 5 (N = 1001)
    >>> res.taus.tolist()
    [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 192.0, 384.0]
    >>> res.n.tolist()[6:]  # N - 2m (OADEV), then (N - m) m / 2 (Theo1)
    [873, 745, 95360, 125184]
    >>> avar.theoh(y, switch=0.1).taus.tolist()  # Howe's hybrid: OADEV below 0.1 N tau0
    [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 192.0, 384.0]
    """
    alpha = check_alpha(alpha)
    if switch is not None and (isinstance(switch, (bool, np.bool_)) or not isinstance(switch, numbers.Real)
                               or not 0.0 < switch <= 0.5):
        raise ValueError(f"switch must be None or a fraction of the record in (0, 0.5], e.g. 0.1, got {switch!r}")
    values, rate, x, bad, _, scale, n_phase = prepared_phase("theoh", data, rate, data_type, confidence, nan_policy)
    if bad.size:
        missing = np.flatnonzero(np.isnan(values))
        raise ValueError(f"data has {missing.size} NaN value(s), the first at index {missing[0]}; theoh needs "
                         "gap-free data (fill or cut them, or use theo1/oadev with nan_policy='omit')")
    if n_phase < MIN_THEOBR_POINTS:
        raise ValueError(f"data has {values.size} sample(s); theoh needs at least {MIN_THEOBR_POINTS} phase points "
                         f"(TheoBR averages AVAR/Theo1 over floor(N / 6) - 2 taus)")
    autocorr = autocorrelation(x)  # shared by kf and the displayed Theo1 levels
    k = None if switch is None else float(switch) * n_phase  # in samples
    allan, theo = _levels(n_phase, rate, taus, k)
    unit = rate * rate if data_type == "phase" else 1.0
    no_gaps = np.zeros(0, dtype=np.int64)
    if numpy_path(lambda: small.theo1_work(n_phase, theo) // small.THEO1_UNITS + n_phase * allan.size,
                  small.THEO1_LIMIT, THEO1_KERNELS + HANKEL_KERNELS + THEO1_DIRECT_KERNELS + (oavar_sums,),
                  route=_ROUTE):
        # cold kernels: the displayed levels by the NumPy twins (kf too, where its twin certifies it)
        kf = theobr_factor(x, autocorr).kf
        sums = small.theo1_level_sums(x, theo, no_gaps, 0).sums
        allan_sums = small.oavar_sums(x, allan)
    else:
        (kf, _), sums, allan_sums = run_concurrently(  # kf and the displayed levels at the same time
            lambda: theobr_factor(x, autocorr),
            lambda: theo1_sums(x, theo, small.theo1_direct(no_gaps, 0), autocorr).sums,
            lambda: _allan_sums(x, allan))
    counts = n_phase - theo
    with np.errstate(over="ignore"):  # an overflow is an error below
        avar = allan_sums / (2.0 * allan * allan * (n_phase - 2 * allan)) / scale / scale * unit
        theobr = kf * sums / (0.75 * counts * theo * theo) / scale / scale * unit
    factors = np.concatenate((allan, theo))
    variance = np.concatenate((avar, theobr))
    if not np.all(np.isfinite(variance)):
        raise ValueError("theoh overflows float64; rescale the data, e.g. to other units")
    if alpha is None:
        ident = np.concatenate((allan, np.maximum(1, np.round(0.75 * theo)).astype(np.int64)))
        alphas = noise_exponents("oadev", values, data_type, rate, ident)
    else:
        alphas = np.full(factors.size, alpha, dtype=np.int64)
    edf = np.concatenate((estimator_edf("oadev", alphas[: allan.size], allan, n_phase),
                          total_edf("theo1", alphas[allan.size :], theo, n_phase)))
    deviation = np.sqrt(variance)
    lci, uci = chi2_bounds(deviation, edf, float(confidence), quantiles=CATALOGUE_QUANTILES)
    return Deviation(taus=np.concatenate((allan, 0.75 * theo)) / rate, averaging_factors=factors, deviation=deviation,
                     variance=variance, n=np.concatenate((n_phase - 2 * allan, counts * (theo // 2))), alpha=alphas, edf=edf,
                     lci=lci, uci=uci, estimator="theoh", data_type=data_type, rate=rate, n_samples=values.size,
                     confidence=float(confidence))
