"""Clocks measured in pairs: :func:`three_cornered_hat` and the Groslambert codeviation :func:`gcodev`.

Three clocks A, B, C compared in pairs give the series AB, BC and CA; with
independent clocks the variances add, sigma_AB**2 = sigma_A**2 + sigma_B**2,
so each clock's variance is half a signed sum of the pairs' (Gray and Allan
1974; Riley, NIST SP 1065 section 8.3). The Groslambert codeviation of two
pairs sharing a clock estimates that clock's variance directly from their
Allan covariance, free of the instruments' independent noise (Lantz et al.
2019).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from avar.stability.shared.deviation import Deviation
from avar.stability.shared.grids import grid_factors
from avar.stability.shared.inputs import DEFAULT_CONFIDENCE, check_data, check_options
from avar.stability.shared.noise_types import check_alpha
from avar.stability.time_error.deviations import level_kernel, level_noise, prepared_phase
from avar.stability.uncertainty.chi2 import CATALOGUE_QUANTILES, chi2_bounds

#: Statistics the three-cornered hat accepts (variances of one clock that add over independent clocks).
HAT_STATISTICS = ("adev", "oadev", "mdev", "tdev", "hdev", "ohdev", "totdev", "pdev")


class ThreeCorneredHat(NamedTuple):
    """The deviation of each of three clocks (:class:`avar.Deviation`, one per clock).

    ``variance`` holds the separated variance, negative where the pairs'
    variances contradict independence (reported, not hidden); there
    ``deviation``, ``edf``, ``lci`` and ``uci`` are NaN.
    """

    a: Deviation
    b: Deviation
    c: Deviation


def _statistic(name: Any):
    from avar.stability.classic import deviations
    from avar.stability.time_error import deviations as time_error

    if not isinstance(name, str) or name not in HAT_STATISTICS:
        raise ValueError(f"statistic must be one of {HAT_STATISTICS}, got {name!r}")
    return getattr(time_error if name == "pdev" else deviations, name)


def three_cornered_hat(ab: Any, bc: Any, ca: Any, rate: float | None = None, data_type: str = "phase",
                       taus: Any = "octave", statistic: str = "oadev",
                       confidence: float = DEFAULT_CONFIDENCE) -> ThreeCorneredHat:
    """Separate the deviations of three clocks measured in pairs (the three-cornered hat)::

        sigma_A**2 = (sigma_AB**2 + sigma_CA**2 - sigma_BC**2) / 2,

    and cyclically for B (AB, BC less CA) and C (BC, CA less AB), at every
    level of ``statistic`` (``"oadev"`` by default). The band of each clock
    is chi-squared with Satterthwaite's EDF of that signed sum of independent
    chi-squared estimates: with v_i the pairs' variances and nu_i their EDF,
    edf_A = 4 sigma_A**4 / sum_i (v_i**2 / nu_i) (clipped at 1).

    Parameters
    ----------
    ab, bc, ca : array_like
        The three pair series (clock A against B, B against C, C against A), of one length.
    rate, data_type, taus, confidence
        As :func:`avar.oadev` (``data_type`` defaults to ``"phase"``, as pair
        measurements of time-interval counters).
    statistic : str
        One of :data:`HAT_STATISTICS`.

    Returns
    -------
    ThreeCorneredHat
        ``(a, b, c)``: each a :class:`avar.Deviation` whose ``n`` and
        ``alpha`` are those of the pair AB, BC and CA respectively.

    References
    ----------
    J. E. Gray and D. W. Allan, "A method for estimating the frequency
    stability of an individual oscillator", Proc. 28th Frequency Control
    Symposium, 1974. W. J. Riley, NIST SP 1065, 2008, section 8.3.

    Examples
    --------
    >>> import numpy as np, avar
    >>> rng = np.random.default_rng(0)
    >>> a, b, c = (s * rng.standard_normal(20001) for s in (1.0, 2.0, 3.0))  # white FM clocks
    >>> hat = avar.three_cornered_hat(a - b, b - c, c - a, data_type="freq", taus=[1.0])
    >>> [round(float(clock.deviation[0]), 1) for clock in hat]
    [1.0, 2.0, 3.0]
    """
    function = _statistic(statistic)
    lengths = {len(np.asarray(series)) for series in (ab, bc, ca)}
    if len(lengths) != 1:
        raise ValueError(f"ab, bc and ca must have one length (synchronous pair measurements), got {sorted(lengths)}")
    pairs = [function(series, rate=rate, data_type=data_type, taus=taus, confidence=confidence)
             for series in (ab, bc, ca)]
    v_ab, v_bc, v_ca = (pair.variance for pair in pairs)
    noise = sum(pair.variance**2 / pair.edf for pair in pairs)
    clocks = []
    for own, variance in zip(pairs, ((v_ab + v_ca - v_bc) / 2, (v_ab + v_bc - v_ca) / 2, (v_bc + v_ca - v_ab) / 2)):
        positive = variance > 0
        deviation = np.where(positive, np.sqrt(np.abs(variance)), np.nan)
        with np.errstate(divide="ignore", invalid="ignore"):
            edf = np.where(positive, np.maximum(4 * variance**2 / noise, 1.0), np.nan)
        lci, uci = np.full(variance.size, np.nan), np.full(variance.size, np.nan)
        if positive.any():
            lci[positive], uci[positive] = chi2_bounds(deviation[positive], edf[positive], float(confidence), quantiles=CATALOGUE_QUANTILES)
        clocks.append(Deviation(
            taus=own.taus, averaging_factors=own.averaging_factors, deviation=deviation, variance=variance,
            n=own.n, alpha=own.alpha, edf=edf, lci=lci, uci=uci, estimator=own.estimator, data_type=own.data_type,
            rate=own.rate, n_samples=own.n_samples, confidence=own.confidence))
    return ThreeCorneredHat(*clocks)


def _named_check(data: Any, name: str, data_type: str, nan_policy: str) -> np.ndarray:
    """:func:`avar.stability.shared.inputs.check_data` with the argument's own name in its messages."""
    try:
        return check_data(data, data_type, nan_policy, statistic="gcodev")[0]
    except (TypeError, ValueError) as error:
        raise type(error)(str(error).replace("data", name, 1)) from None


def gcodev(data_1: Any, data_2: Any, rate: float | None = None, data_type: str = "freq", taus: Any = "octave",
           confidence: float = DEFAULT_CONFIDENCE, nan_policy: str = "raise", alpha: int | None = None) -> Deviation:
    """Groslambert codeviation (the overlapping Allan covariance) of two pair series::

        GCOV(tau) = sum_{i=0}^{N-2m-1} (x1_{i+2m} - 2 x1_{i+m} + x1_i)(x2_{i+2m} - 2 x2_{i+m} + x2_i) / (2 tau**2 (N - 2m)),

    n = N - 2m terms, m = 1 .. (N - 1) / 2. With x1 the phase of A against B
    and x2 that of B against C (or C against B: the sign flips), GCOV
    estimates -sigma_B**2 (+sigma_B**2), free of the two measurements'
    independent noise. ``variance`` is GCOV, signed; ``deviation`` is
    sign(GCOV) sqrt(``|GCOV|``) (``allantools.gcodev`` returns sqrt(``|GCOV|``)).
    No chi-squared bounds (``edf``, ``lci``, ``uci`` are NaN); ``alpha`` is
    that of ``data_1`` (or the one given).

    Parameters
    ----------
    data_1, data_2 : array_like
        The two series, of one length; NaN in either removes the terms touching it.
    rate, data_type, taus, confidence, nan_policy
        As :func:`avar.oadev`.
    alpha : int or None
        Fixed noise exponent of every level (None: identified on ``data_1``).

    Returns
    -------
    Deviation

    References
    ----------
    F. Vernotte, E. Lantz et al., "Three-cornered hat and Groslambert
    covariance: a first attempt to assess the uncertainty domains", IEEE
    Trans. UFFC 2016; E. Lantz, A. Stock, V. Giordano, F. Vernotte et al.,
    "The Groslambert covariance", arXiv:1904.05849, 2019.

    Examples
    --------
    >>> import numpy as np, avar
    >>> rng = np.random.default_rng(1)
    >>> a, b, c = (rng.standard_normal(40001) for _ in range(3))
    >>> res = avar.gcodev(a - b, c - b, taus=[1.0])  # B shared, same sign: + sigma_B**2 (= 1 per tau0)
    >>> round(float(res.variance[0]), 1)
    1.0
    """
    rate = check_options("gcodev", data_1, rate, data_type, confidence, nan_policy)
    fixed = check_alpha(alpha)
    first, second = (_named_check(data, name, data_type, nan_policy)
                     for data, name in ((data_1, "data_1"), (data_2, "data_2")))
    if first.size != second.size:
        raise ValueError(f"data_1 and data_2 must have one length, got {first.size} and {second.size}")
    missing = np.isnan(first) | np.isnan(second)
    if missing.all():
        raise ValueError("data_1 and data_2 have no sample where both are present")
    first, second = np.where(missing, np.nan, first), np.where(missing, np.nan, second)
    n_phase = first.size + (data_type == "freq")
    if n_phase < 3:
        raise ValueError(f"data_1 has {first.size} sample(s); gcodev needs at least {3 - (data_type == 'freq')}")
    largest = (n_phase - 1) // 2
    factors = grid_factors(taus, rate, largest, first_octave=0,
                           context=f"of gcodev (averaging factors 1..{largest} at rate = {rate:g} Hz "
                                   f"with {n_phase} phase points)")
    x1, gaps, extra = prepared_phase(first, data_type, rate)
    x2, _, _ = prepared_phase(second, data_type, rate)
    sums, n = level_kernel("gcodev", x1, factors)(x1, x2, factors, gaps, extra)
    keep = n > 0
    if not keep.any():
        raise ValueError("no gcodev term avoids the NaN values of data_1 and data_2 at these taus")
    factors, sums, n = factors[keep], sums[keep], n[keep]
    variance = sums / (2.0 * n * (factors / rate) ** 2)
    deviation = np.sign(variance) * np.sqrt(np.abs(variance))
    alpha_levels = level_noise(fixed, first, x1, gaps, data_type, rate, factors)
    nan = np.full(factors.size, np.nan)
    return Deviation(
        taus=factors / rate, averaging_factors=factors, deviation=deviation, variance=variance, n=n,
        alpha=alpha_levels, edf=nan, lci=nan, uci=nan, estimator="gcodev", data_type=data_type, rate=rate,
        n_samples=first.size, confidence=float(confidence),
    )
