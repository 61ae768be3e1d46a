"""Power-law coefficients ``h_alpha`` and Kalman diffusion coefficients q from per-sample processes.

GMWM fits processes of the fractional frequency y sampled at ``rate`` (tau0 = 1 / rate), each
with its per-sample variance; S_y(f) = ``h_alpha`` f**alpha and the clock models' q follow exactly:

=======  ====================  =============================  =======================================
alpha    process (parameter)   ``h_alpha``                    Allan variance (NIST SP 1065, Table 3)
=======  ====================  =============================  =======================================
2        QN (q2): white PM,    8 pi**2 q2 / rate**3           3 q2 / m**2 (= 3 sigma_x**2 / tau**2,
         sigma_x**2 = q2 / rate**2                            sigma_x the time error's per-sample sd)
0        WN (sigma2)           2 sigma2 / rate                ``h_0`` / (2 tau)
-1       FN (b2)               b2 / pi                        2 ln 2 ``h_-1``
-2       RW (gamma2)           gamma2 rate / (2 pi**2)        (2 pi)**2 tau ``h_-2`` / 6
=======  ====================  =============================  =======================================

A linear frequency drift D (1/s) is DR (omega): D = omega rate.

The two-state clock model (time error x, frequency y; Zucca and Tavella 2005) is
dx = y dt + sqrt(q1) dW1, dy = sqrt(q2) dW2 (+ D dt with the third state), whose Allan variance is
q1 / tau + q2 tau / 3: so q1 = ``h_0`` / 2 (s) and q2 = 2 pi**2 ``h_-2`` (1/s); white PM is measurement
noise of variance r = sigma_x**2 (s**2). Flicker FM has no finite-state Markov form and is
reported as ``h_-1`` only.

References
----------
W. J. Riley, NIST SP 1065 (2008), Tables 2 and 3; C. Zucca, P. Tavella, "The clock model and its
relationship with the Allan and related variances", IEEE Trans. UFFC 52(2), 2005.
"""

from __future__ import annotations

import math
from typing import NamedTuple

__all__ = ["H_OF_PROCESS", "KalmanQ", "PowerLaw", "h_coefficient", "kalman_q"]


class PowerLaw(NamedTuple):
    """One power-law term S_y(f) = h f**alpha."""

    alpha: int
    h: float


class KalmanQ(NamedTuple):
    """Diffusion coefficients of the two-state clock model: q1 (s, white FM), q2 (1/s, random-walk FM)."""

    q1: float
    q2: float

#: alpha and ``h_alpha`` per unit of each process's parameter, as functions of the rate (Hz).
H_OF_PROCESS = {
    "QN": (2, lambda rate: 8.0 * math.pi**2 / rate**3),
    "WN": (0, lambda rate: 2.0 / rate),
    "FN": (-1, lambda rate: 1.0 / math.pi),
    "RW": (-2, lambda rate: rate / (2.0 * math.pi**2)),
}


def h_coefficient(process: str, value: float, rate: float) -> PowerLaw:
    """(alpha, ``h_alpha``) of one fitted process's parameter at ``rate`` Hz.

    >>> h_coefficient("WN", 1e-22, 1.0)   # white FM: S_y = 2 sigma2 / rate
    PowerLaw(alpha=0, h=2e-22)
    """
    alpha, unit = H_OF_PROCESS[process]
    return PowerLaw(alpha, value * unit(rate))


def kalman_q(h0: float, h_minus2: float) -> KalmanQ:
    """(q1, q2) of the two-state clock model from ``h_0`` and ``h_-2``: q1 = ``h_0`` / 2 (s), q2 = 2 pi**2 ``h_-2`` (1/s).

    >>> q1, q2 = kalman_q(2e-22, 1e-30)
    >>> q1, round(q2 / 1e-30, 6)
    (1e-22, 19.739209)
    """
    return KalmanQ(h0 / 2.0, 2.0 * math.pi**2 * h_minus2)
