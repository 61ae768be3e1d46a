"""TheoBR's bias factor kf: the mean ratio of the overlapping Allan variance to Theo1 over a range of taus.

Howe and Tasset 2004, Taylor and Howe 2010; the range as Stable32 (:func:`theobr_count`). ThêoH
scales its Theo1 levels by kf, and Stable32 scales Theo1 by it when the noise is fixed to other
than white FM.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from avar._kernels.runtime.paths import numpy_path
from avar._kernels.total.fft import autocorrelation
from avar._kernels.total.theo1 import split_sums
from avar._kernels.total.theobr import THEO1_EVERY_KERNELS, lag_diagonals, oavar_expanded, oavar_sums, theo1_every
from avar._kernels.total.windows import theo1_sum
from avar.stability.total import small, small_theobr

#: Fewest phase points: the average needs n = floor(N / 6) - 3 >= 0 and Allan terms at m = 9 + 3n.
MIN_THEOBR_POINTS = 19
#: Relative error of an expanded Theo1 sum per unit of its conditioning ratio (measured:
#: at most 6.7e-15 over the levels of random-walk FM, N = 2e4, against the direct sums).
ERROR_PER_RATIO = 1e-14
#: Relative error allowed in TheoBR's kf from the expanded Theo1 sums of its average (kf is
#: an estimate whose own statistical uncertainty is of order 1e-2; ThêoH prints 5 digits).
KF_TOLERANCE = 1e-8
#: The split groups of kf's ill-conditioned Theo1 sums reach down to 1 / KF_REACH of their knot
#: spacing (ratio up to about 1e4 on random-walk FM: 1e-10, far below kf's tolerance).
KF_REACH = 16
#: The same for kf's ill-conditioned overlapping Allan sums (with N / 30 of them, reaching 1 / 16
#: left about 200 of random-walk FM's 33,331 at N = 1e6 to be summed directly; 1 / 8 none, for the
#: same cost of splits).
KF_ALLAN_REACH = 8
#: No gaps (the phase of kf is gap-free).
NO_GAPS = np.zeros(0, dtype=np.int64)


class TheoBRFactor(NamedTuple):
    """TheoBR's bias factor kf and the n it averages over."""

    kf: float
    n: int


def theobr_factor(x: np.ndarray, autocorr: np.ndarray | None = None) -> TheoBRFactor:
    """TheoBR's bias factor kf = 1 / (n + 1) sum_{i=0}^{n} AVAR(9 + 3i) / Theo1(12 + 4i),
    n = floor(N / 6) - 3 (both at tau = (9 + 3i) tau0; AVAR overlapping), and n (:func:`theobr_count`).

    ``x``: gap-free phase, N >= 19 points; ``autocorr``: its FFT autocorrelation, if at hand.
    The units cancel in the ratio.
    """
    if twin_path(x.shape[0]):
        terms = twin_terms(x, autocorr)  # cold kernels: NumPy, unless a sum needs summing again
        if terms is not None:
            return TheoBRFactor(float(np.mean(terms)), theobr_count(x.shape[0]))
    terms, n = theobr_terms(x, autocorr)
    return TheoBRFactor(float(np.mean(terms)), n)


#: The route of :func:`avar._kernels.runtime.paths.numpy_path` for kf's NumPy twin.
_TWIN_ROUTE = "theobr-factor"


def twin_path(n_points: int) -> bool:
    """Whether kf of ``n_points`` phase points goes to its NumPy twin
    (:func:`avar._kernels.runtime.paths.numpy_path`): while the kernels its compiled path would
    compile (:data:`avar._kernels.total.theobr.THEO1_EVERY_KERNELS`, ~2 s) are cold, for up to
    :data:`~avar.stability.total.small_theobr.THEOBR_TWIN_LIMIT` points, each call charged what
    the twin loses to the warm kernels (:data:`~avar.stability.total.small_theobr.THEOBR_UNITS`
    per point).

    >>> from avar._kernels.runtime.paths import forced
    >>> with forced("compiled"):
    ...     twin_path(100_000)
    False
    """
    limit = small_theobr.THEOBR_TWIN_LIMIT
    return n_points <= limit and numpy_path(n_points * small_theobr.THEOBR_UNITS, limit * small_theobr.THEOBR_UNITS,
                                            THEO1_EVERY_KERNELS, route=_TWIN_ROUTE)


def twin_terms(x: np.ndarray, autocorr: np.ndarray | None = None) -> np.ndarray | None:
    """:func:`theobr_terms`' terms by the NumPy twin (:mod:`avar.stability.total.small_theobr`), or
    None where the twin declines (:func:`_kf_terms`)."""
    return _kf_terms(x, autocorr, twin=True)


def theobr_count(n_points: int) -> int:
    """The last index n of TheoBR's average: floor(N / 6) - 3, as Stable32 computes ThêoH and Theo1's
    bias removal (the Allan factors 9 + 3i then reach N / 2). Where N is a multiple of 6 the last
    factor would leave no Allan term, and the average stops one short.

    Howe, Taylor and Tasset's fast TheoBR averages to n = floor(0.1 N / 3) - 3 instead; on
    Stable32's tables of two records only floor(N / 6) - 3 reproduces the printed values (to
    their 5 digits: kf = 0.602787 at N = 1001, 1.349115 at N = 1253; the other count gives
    1.0857 and 1.3171).

    >>> theobr_count(1001), theobr_count(1253), theobr_count(1002)
    (163, 205, 163)
    """
    n = int(n_points) // 6 - 3
    return n - 1 if int(n_points) % 6 == 0 else n


def theobr_terms(x: np.ndarray, autocorr: np.ndarray | None = None) -> tuple[np.ndarray, int]:
    """The n + 1 terms AVAR(9 + 3i) / Theo1(12 + 4i) of :func:`theobr_factor`'s mean, and n, by the
    compiled kernels (:func:`_kf_terms`)."""
    return _kf_terms(x, autocorr, twin=False), theobr_count(x.shape[0])


def _kf_terms(x: np.ndarray, autocorr: np.ndarray | None, twin: bool) -> np.ndarray | None:
    """kf's terms: OAVAR and Theo1 sums by FFT (:func:`avar._kernels.total.theobr.oavar_expanded`,
    :func:`~avar._kernels.total.theobr.theo1_every`); the ill-conditioned ones by the split expansion
    (:func:`avar._kernels.total.theo1.split_sums`), each kind as far as half of kf's tolerance needs
    (see :func:`_levels_to_redo`), and directly if that is not enough either.

    ``twin``: the NumPy twins throughout (:mod:`avar.stability.total.small_theobr`; the split's
    loops take theirs while cold), the direct sums in NumPy (:func:`avar.stability.total.small.oavar_sums`,
    :func:`~avar.stability.total.small.theo1_level_sums`) while their terms stay within
    :data:`~avar.stability.total.small_theobr.TWIN_DIRECT_TERMS`; beyond that the result is None
    and the kernels sum them again."""
    n_points = x.shape[0]
    n = theobr_count(n_points)
    i = np.arange(n + 1, dtype=np.int64)
    m_avar = 9 + 3 * i
    m_theo = 12 + 4 * i
    autocorr = autocorrelation(x) if autocorr is None else autocorr
    if twin:
        diagonals = small_theobr.lag_diagonals(x, int(m_avar[-1]) + 1)
    else:
        diagonals = lag_diagonals(x, np.ascontiguousarray(x[::-1]), int(m_avar[-1]) + 1)
    every_level = small_theobr.theo1_every if twin else theo1_every
    avar_sums, avar_ratio = oavar_expanded(x, m_avar, autocorr, diagonals)
    avar_norm = 2.0 * m_avar * m_avar * (n_points - 2 * m_avar)
    every = every_level(x, int(m_theo[-1]), autocorr, diagonals)
    theo_norm = 0.75 * (n_points - m_theo) * m_theo * m_theo
    sums, ratio = every.sums[m_theo], every.ratios[m_theo]
    # each of the two kinds of sums may bring half of kf's tolerance
    redo = _levels_to_redo(avar_sums / avar_norm * theo_norm / sums, avar_ratio, 0.5)
    if redo.size:  # by the split expansion, then directly
        again = split_sums(x, np.zeros(0), KF_ALLAN_REACH, m_avar[redo], every=every_level)
        _take_better(avar_sums, avar_ratio, redo, again.allan, again.allan_ratios)
        redo = redo[np.isin(redo, _levels_to_redo(avar_sums / avar_norm * theo_norm / sums, avar_ratio, 0.5))]
    work = n_points * redo.size
    if twin and work > small_theobr.TWIN_DIRECT_TERMS:
        return None
    if redo.size:
        avar_sums[redo] = (small.oavar_sums if twin else oavar_sums)(x, m_avar[redo])
    avar = avar_sums / avar_norm
    split = _levels_to_redo(avar * theo_norm / sums, ratio, 0.5)  # first by the split expansion
    if split.size:
        again = split_sums(x, m_theo[split], KF_REACH, every=every_level)
        _take_better(sums, ratio, split, again.theo1, again.theo1_ratios)
    theo = sums / theo_norm
    redo = _levels_to_redo(avar / theo, ratio, 0.5)
    if twin:
        if work + small.theo1_work(n_points, m_theo[redo]) > small_theobr.TWIN_DIRECT_TERMS:
            return None
        if redo.size:
            theo[redo] = small.theo1_level_sums(x, m_theo[redo], NO_GAPS, 0).sums / theo_norm[redo]
        return avar / theo
    for level in redo:
        theo[level] = theo1_sum(x, int(m_theo[level]), NO_GAPS, 0).total / theo_norm[level]
    return avar / theo


def _take_better(sums: np.ndarray, ratio: np.ndarray, levels: np.ndarray, new: np.ndarray,
                 new_ratio: np.ndarray) -> None:
    """Replace ``sums`` and ``ratio`` at ``levels`` by ``new`` where its ratio is lower."""
    better = new_ratio < ratio[levels]
    sums[levels[better]] = new[better]
    ratio[levels[better]] = new_ratio[better]


def _levels_to_redo(terms: np.ndarray, ratio: np.ndarray, share: float = 1.0) -> np.ndarray:
    """The levels of kf's average to sum again: the worst-conditioned first, until the error
    the others can bring to the mean of ``terms`` is below ``share`` x :data:`KF_TOLERANCE`.

    A level's expanded sum errs by about ERROR_PER_RATIO x its ratio (relative), which
    reaches its term of the mean; kf averages thousands of levels, so it needs far fewer
    direct sums than a per-level tolerance would (random-walk FM, N = 1e5: about 50 of 3332
    levels, the smallest m, instead of 1368). A non-finite term or ratio is always redone.
    """
    with np.errstate(invalid="ignore", over="ignore"):  # 0 x inf (a zero sum's ratio): redone as inf below
        error = np.abs(terms) * ERROR_PER_RATIO * ratio
    error[~np.isfinite(error)] = np.inf
    order = np.argsort(-error, kind="stable")
    remaining = np.cumsum(error[order][::-1])[::-1]  # error of the levels from this one on
    finite = np.abs(terms[np.isfinite(terms)])
    # the mean's scale from the median term, which a few ill-conditioned terms cannot inflate
    budget = share * KF_TOLERANCE * terms.size * (float(np.median(finite)) if finite.size else 0.0)
    count = int(np.count_nonzero(~(remaining <= budget)))
    return np.sort(order[:count])
