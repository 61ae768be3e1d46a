"""Levels, EDF and bias of the total and Theo statistics: MTOTDEV, TTOTDEV, HTOTDEV, Theo1, ThêoH.

N is the number of phase points (frequency data of M values give N = M + 1)
and m the averaging factor. Term counts, as NIST SP 1065 (Riley 2008):

=========  ======================  =========================  =====================
name       terms n(m)              factors                    tau
=========  ======================  =========================  =====================
mtotdev    N - 3m + 1              1 .. floor(N / 3)          m tau0
ttotdev    N - 3m + 1              1 .. floor(N / 3)          m tau0
htotdev    N - 3m (m = 1: OHDEV)   1 .. floor((N - 1) / 3)    m tau0
theo1      (N - m) m / 2           even, 2 .. N - 1           0.75 m tau0
=========  ======================  =========================  =====================

Theo1's count is that of its inner terms, as Stable32's ``Thêo1 #`` and
``allantools`` (which reports the tau as m tau0; the statistic is the same).
"""

from __future__ import annotations

import numpy as np

from avar.stability.uncertainty.edf import estimator_edf, stable32_simple_edf

#: NIST SP 1065 Table 8: MTOTVAR (and TTOTVAR) EDF = b N / m - c.
MTOT_EDF = {2: (1.90, 2.10), 1: (1.20, 1.40), 0: (1.10, 1.20), -1: (0.85, 0.50), -2: (0.75, 0.31)}
#: Stable32's MTOTVAR (and TTOTVAR) EDF from m = 10 where it differs from Table 8: b (N - 1) / m - c
#: at white FM, flicker PM and flicker FM, N the number of points given. No source states it; these
#: are least-squares fits to the degrees of freedom its printed one-sigma bounds imply on two records
#: (N = 1001 and 1253, given as phase and as frequency; 36, 7 and 8 rows), which they reproduce to
#: 6.9e-5, 6.2e-5 and 5.5e-5 (3 units of the 5th printed digit at most). Flicker FM rests on one record.
STABLE32_MTOT_EDF = {0: (1.3313, 1.8927), 1: (1.7319, 2.9896), -1: (0.9204, 0.7596)}
#: Below this factor MTOTDEV's (and TTOTDEV's) EDF is the modified Allan variance's, as
#: Stable32's bounds show (PHASE.DAT: MDEV's EDF at m = 1 .. 8, a b N / m - c law from m = 10).
MTOT_EDF_FROM = 10
#: NIST SP 1065 (Howe et al. 2000): HTOTVAR EDF = (N / m) / (b0 + b1 m / N), for m >= 16.
HTOT_EDF = {0: (0.559, 1.004), -1: (0.868, 1.140), -2: (0.938, 1.696)}
#: Below this factor HTOTDEV's EDF is NIST SP 1065 Table 5's simple approximation plus 2 (Stable32
#: switches here; its printed bounds below m = 16 follow that, not the Greenhall EDFs).
HTOT_EDF_FROM = 16
#: Howe et al. 2000: E[HTOTVAR] / HVAR = 1 + a (m > 1); Stable32 divides by it.
HTOT_BIAS = {0: -0.005, -1: -0.149, -2: -0.229}
#: Howe and Tasset 2004, Table 1: AVAR / Theo1 = a + b / r**c, r = 0.75 m.
THEO1_BIAS = {2: (0.09, 0.74, 0.40), 1: (0.14, 0.82, 0.30), 0: (1.0, 0.0, 0.0), -1: (1.87, -1.05, 0.79),
              -2: (2.70, -1.53, 0.85)}


def total_edf(estimator: str, alpha: np.ndarray, factors: np.ndarray, n_phase: int,
              n_given: int | None = None) -> np.ndarray:
    """EDF of a total or Theo statistic at every level, floored at 1.

    ``n_given``: the number of data points given (frequency data: N - 1), which
    Stable32's MTOTVAR and HTOTVAR rules take for their N; default ``n_phase``.

    * MTOTDEV, TTOTDEV: the modified Allan variance's (Greenhall) below m = 10,
      as Stable32; from m = 10 Stable32's b (N - 1) / m - c with (b, c) =
      (1.3313, 1.8927) at white FM, (1.7319, 2.9896) at flicker PM and
      (0.9204, 0.7596) at flicker FM (:data:`STABLE32_MTOT_EDF`), NIST SP 1065
      Table 8's b N / m - c at white PM and random-walk FM. Stable32's law is
      published nowhere; fitted to the bounds it prints for two records of
      different length (N = 1001 and 1253), it reproduces them to 7e-5, with
      N the number of points given (its frequency and phase tables of one
      record differ so). Simulated records have 20 to 50 % fewer degrees of
      freedom (``benchmarks/total_edf_simulation.py``: white FM, N = 1001,
      m = 16: 64 against Stable32's 81.3 and Table 8's 67.6), so these bounds,
      as Stable32's, are narrower than the data warrant there by up to about
      10 %; ``MTOT_EDF`` holds Table 8's coefficients for all five noises.
    * HTOTDEV: from m = 16 (Stable32) (N / m) / (b0 + b1 m / N) with (b0, b1)
      = (0.559, 1.004), (0.868, 1.140), (0.938, 1.696) for alpha = 0, -1, -2
      (NIST SP 1065); below m = 16 and at white and flicker PM Stable32's
      simple approximations of NIST SP 1065 Table 5 plus 2
      (:func:`avar.stability.uncertainty.edf.stable32_simple_edf`), which its bounds on
      two records (N = 1001, 1253; flicker PM, white, flicker and random-walk
      FM) imply to +-0.02 degrees of freedom, where the overlapping Hadamard
      variance's Greenhall EDF is 10 to 36 % lower. Simulated records have
      more than either (597, 385, 208 at m = 2, 4, 8, white FM, N = 1001;
      Table 5 + 2: 572, 348, 184).
    * Theo1 (Howe and Tasset 2004; NIST SP 1065, Table 11), r = 0.75 m:
      alpha = 2: 0.86 (N + 1)(N - 4r/3) / (N - r) * r / (r + 1.14);
      1: (4.798 N**2 - 6.374 N r + 12.387 r) / (sqrt(r + 36.6) (N - r)) * r / (r + 0.3);
      0: ((4.1 N + 0.8) / r - (3.1 N + 6.5) / N) * r**1.5 / (r**1.5 + 5.2);
      -1: (2 N**2 - 1.3 N r - 3.5 r) / (N r) * r**3 / (r**3 + 2.3);
      -2: (4.4 N - 2) / (2.9 r) * ((4.4 N - 1)**2 - 8.6 r (4.4 N - 1) + 11.4 r**2) / (4.4 N - 3)**2.

    Examples
    --------
    >>> total_edf("mtotdev", np.array([0, -2]), np.array([10, 10]), 1001).round(3).tolist()
    [131.237, 74.765]
    >>> total_edf("theo1", np.array([0]), np.array([100]), 1001).round(3).tolist()
    [51.215]
    """
    alpha = np.asarray(alpha, dtype=np.int64)
    m = np.asarray(factors, dtype=np.float64)
    n = float(n_phase)
    edf = np.ones(m.shape)
    for a in np.unique(alpha):
        at = alpha == a
        mm = m[at]
        if estimator in ("mtotdev", "ttotdev"):
            if int(a) in STABLE32_MTOT_EDF:
                b, c = STABLE32_MTOT_EDF[int(a)]
                value = b * (float(n_phase if n_given is None else n_given) - 1.0) / mm - c
            else:
                b, c = MTOT_EDF[int(a)]
                value = b * n / mm - c
            small = mm < MTOT_EDF_FROM
            if small.any():
                value[small] = estimator_edf("mdev", np.full(int(small.sum()), a), mm[small].astype(np.int64),
                                             int(n_phase))
            edf[at] = value
        elif estimator == "htotdev":  # N: the count given, as Stable32 (its frequency tables)
            given = float(n_phase if n_given is None else n_given)
            value = stable32_simple_edf(given, mm, np.full(mm.shape, a))
            if int(a) in HTOT_EDF:
                b0, b1 = HTOT_EDF[int(a)]
                value = np.where(mm >= HTOT_EDF_FROM, (given / mm) / (b0 + b1 * mm / given), value)
            edf[at] = value
        else:
            edf[at] = _theo1_edf(int(a), n, 0.75 * mm)
    return np.where(np.isfinite(edf) & (edf >= 1.0), edf, 1.0)


def _theo1_edf(alpha: int, n: float, r: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        if alpha == 2:
            return 0.86 * (n + 1) * (n - 4 * r / 3) / (n - r) * r / (r + 1.14)
        if alpha == 1:
            return (4.798 * n * n - 6.374 * n * r + 12.387 * r) / (np.sqrt(r + 36.6) * (n - r)) * r / (r + 0.3)
        if alpha == 0:
            return ((4.1 * n + 0.8) / r - (3.1 * n + 6.5) / n) * r**1.5 / (r**1.5 + 5.2)
        if alpha == -1:
            return (2 * n * n - 1.3 * n * r - 3.5 * r) / (n * r) * r**3 / (r**3 + 2.3)
        return (4.4 * n - 2) / (2.9 * r) * ((4.4 * n - 1) ** 2 - 8.6 * r * (4.4 * n - 1) + 11.4 * r * r) / (4.4 * n - 3) ** 2


def htot_bias(alpha: np.ndarray, factors: np.ndarray) -> np.ndarray:
    """E[HTOTVAR] / HVAR per level: 1 + a(alpha) for m > 1 (alpha = 0, -1, -2), else 1.

    >>> htot_bias(np.array([0, -1, -2, -1]), np.array([2, 2, 2, 1])).tolist()
    [0.995, 0.851, 0.771, 1.0]
    """
    a = np.array([HTOT_BIAS.get(int(v), 0.0) for v in np.asarray(alpha).ravel()])
    return np.where(np.asarray(factors) > 1, 1.0 + a, 1.0)


#: Howe 1999 (Table 1), NIST SP 1065 section 5.2.11: E[TOTVAR] / AVAR = 1 - a m / N for flicker
#: and random-walk FM, a = 1 / (3 ln 2) and 3 / 4 (none for white FM and the PM noises).
TOTVAR_BIAS = {-1: 1.0 / (3.0 * np.log(2.0)), -2: 0.75}


def totvar_bias(alpha: np.ndarray, factors: np.ndarray, n_points: int) -> np.ndarray:
    """E[TOTVAR] / AVAR per level: 1 - a m / N (alpha = -1, -2), else 1.

    Stable32 divides the total variance by it, with N the number of data points given (phase
    or frequency): its TOTDEV tables of a flicker FM record (10,000 frequency points) and of a
    clock (1253 phase points, and the same record as 1252 frequency points) print the raw
    statistic over the square root of this, to their 5 digits.

    >>> totvar_bias(np.array([0, -1, -2]), np.array([100, 100, 100]), 1001).round(5).tolist()
    [1.0, 0.95196, 0.92507]
    """
    alpha = np.asarray(alpha, dtype=np.int64)
    a = np.select([alpha == key for key in TOTVAR_BIAS], list(TOTVAR_BIAS.values()), 0.0)
    return 1.0 - a * np.asarray(factors, dtype=np.float64) / float(n_points)


def theo1_bias(alpha: np.ndarray, factors: np.ndarray) -> np.ndarray:
    """AVAR / Theo1 per level: a + b / r**c with r = 0.75 m (Howe and Tasset 2004, Table 1).

    >>> theo1_bias(np.array([2, 0, -2]), np.array([10, 10, 10])).round(4).tolist()
    [0.4205, 1.0, 2.424]
    """
    r = 0.75 * np.asarray(factors, dtype=np.float64)
    out = np.empty(r.shape)
    for i, a in enumerate(np.asarray(alpha).ravel()):
        a0, b, c = THEO1_BIAS[int(a)]
        out[i] = a0 + b / r[i] ** c
    return out
