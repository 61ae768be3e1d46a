"""Flicker (1/f, bias instability) noise: :class:`FN`, exact simulation and exact Allan variance.

Per sample, flicker noise is the fractionally integrated white noise of
Kasdin (1995) with exponent alpha = 1 (fractional difference d = 1/2)::

    x_t = (1 - B)^(-1/2) w_t,    w_t i.i.d. N(0, b2),

whose spectral density b2 / |2 sin(pi nu)| is b2 / (2 pi nu) at low
frequencies nu (cycles per sample). The process is not stationary, but its
increments u_t = x_t - x_{t-1} = (1 - B)^(1/2) w_t are: a fractionally
differenced process with d = -1/2 and autocovariance::

    gamma(0) = 4 b2 / pi,   gamma(h) = -gamma(0) / (4 h^2 - 1)   (h >= 1)

(Hosking 1981 with Gamma(h - 1/2) / Gamma(h + 3/2) = 1 / ((h - 1/2)(h + 1/2))).
The Allan variance depends on x only through its increments, so it is exact
and free of start-up transients:

* **Simulation** draws u_1..u_n exactly by circulant embedding (Davies and
  Harte 1987; Wood and Chan 1994) with one FFT per pair of series, then
  x_t = u_1 + ... + u_t. Every gamma(h), h >= 1, is negative, which makes the
  embedding non-negative definite at any size (Craigmile 2003), so the
  simulated series have exactly the stated covariance.
* **Theory**: with the structure function D(k) = Var(x_{t+k} - x_t) =
  (4 b2 / pi) sum_{j=1}^{k} 1 / (2 j - 1) and m(ybar_{t+m} - ybar_t) =
  sum_{i<m} (x_{t+m+i} - x_{t+i})::

      AV(m) = (1 / (2 m^2)) sum_{|h|<m} (m - |h|) (D(m + h) - D(|h|)),

  which tends to (2 ln 2 / pi) b2 = (0.664 B)^2 with B = sqrt(b2): the flat
  Allan deviation of IEEE Std 952 bias instability. Flicker is scale-free:
  B is the same per sample and per second, at any rate.

References
----------
N. J. Kasdin, "Discrete simulation of colored noise and stochastic processes
and 1/f^alpha power law noise generation", Proc. IEEE 83(5), 1995.
J. R. M. Hosking, "Fractional differencing", Biometrika 68(1), 1981.
P. F. Craigmile, "Simulating a class of stationary Gaussian processes using
the Davies-Harte algorithm", J. Time Ser. Anal. 24(5), 2003.
IEEE Std 952-1997, Annex C (bias instability).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from avar._validation import check_freq, check_real
from avar.models.base import Process

__all__ = ["FN", "FLICKER_AV_FACTOR", "flicker_increment_autocovariance", "flicker_structure_function", "av_fn",
           "flicker_unit_av"]

#: AV plateau of flicker per unit b2: 2 ln 2 / pi (AD = 0.664 B).
FLICKER_AV_FACTOR = 2.0 * math.log(2.0) / math.pi
#: Largest factor at which :func:`flicker_unit_av` sums the flicker AV exactly; beyond, its expansion in 1 / m^2.
FLICKER_EXACT = 4096


def flicker_increment_autocovariance(b2: float, lags: np.ndarray) -> np.ndarray:
    """Autocovariance of the increments of flicker noise: gamma(h) = (4 b2 / pi) / (1 - 4 h^2).

    >>> flicker_increment_autocovariance(np.pi / 4, np.arange(3))
    array([ 1.        , -0.33333333, -0.06666667])
    """
    h = np.asarray(lags, dtype=np.float64)
    return (4.0 * b2 / math.pi) / (1.0 - 4.0 * h * h)


def flicker_structure_function(b2: float, k_max: int) -> np.ndarray:
    """D(k) = Var(x_{t+k} - x_t) = (4 b2 / pi) sum_{j<=k} 1 / (2 j - 1) for k = 0..k_max (extended precision).

    >>> flicker_structure_function(np.pi / 4, 2).astype(float)
    array([0.        , 1.        , 1.33333333])
    """
    odd = 2.0 * np.arange(1, k_max + 1, dtype=np.longdouble) - 1.0
    structure = np.zeros(k_max + 1, dtype=np.longdouble)
    structure[1:] = np.cumsum(1.0 / odd)
    return structure * np.longdouble(4.0 * b2 / math.pi)


def av_fn(b2: float, m: np.ndarray) -> np.ndarray:
    """Exact Allan variance of per-sample flicker noise ``FN(b2)`` at averaging factors m (>= 1).

    AV(m) = (T1 - T2) / (2 m^2) with T1 = sum_{k=1}^{2m-1} (m - |k - m|) D(k)
    and T2 = 2 sum_{k=1}^{m-1} (m - k) D(k), evaluated in O(1) per m from
    cumulative sums of D and k D in extended precision.

    >>> bool(abs(av_fn(1.0, np.array([2**20]))[0] / FLICKER_AV_FACTOR - 1) < 1e-5)
    True
    """
    factors = np.asarray(m, dtype=np.int64)
    if factors.size == 0:
        return np.zeros(factors.shape)
    top = int(factors.max())
    structure = flicker_structure_function(1.0, 2 * top)
    k = np.arange(2 * top + 1, dtype=np.longdouble)
    s0 = np.cumsum(structure)  # s0[k] = sum_{j<=k} D(j)
    s1 = np.cumsum(k * structure)  # s1[k] = sum_{j<=k} j D(j)
    mm = factors.astype(np.longdouble)
    t1 = s1[factors] + 2 * mm * (s0[2 * factors - 1] - s0[factors]) - (s1[2 * factors - 1] - s1[factors])
    t2 = 2 * (mm * s0[factors - 1] - s1[factors - 1])
    return (b2 * ((t1 - t2) / (2 * mm * mm))).astype(np.float64)


@functools.lru_cache(maxsize=1)
def _flicker_head() -> tuple[np.ndarray, float]:
    exact = av_fn(1.0, np.arange(1, FLICKER_EXACT + 1))
    # AV(m) / (2 ln 2 / pi) - 1 = (c0 + (3/16) log2 m) / m^2 + O(log m / m^4): c0 from the last exact value
    c0 = (exact[-1] / FLICKER_AV_FACTOR - 1.0) * FLICKER_EXACT**2 - 0.1875 * math.log2(FLICKER_EXACT)
    return exact, c0


def flicker_unit_av(m: np.ndarray) -> np.ndarray:
    """Allan variance of unit flicker FN(b2=1) at factors m: exact up to 4096, then its expansion (1e-14).

    >>> bool(abs(flicker_unit_av(np.array([2.0**20]))[0] / av_fn(1.0, np.array([2**20]))[0] - 1) < 1e-13)
    True
    """
    m = np.asarray(m, dtype=np.float64)
    exact, c0 = _flicker_head()
    small = m <= FLICKER_EXACT
    out = np.empty(m.shape)
    out[small] = exact[m[small].astype(np.int64) - 1]
    big = m[~small]
    out[~small] = FLICKER_AV_FACTOR * (1.0 + (c0 + 0.1875 * np.log2(big)) / big**2)
    return out


def _embedding_roots(n: int) -> np.ndarray:
    """sqrt(eigenvalues / M) of the circulant embedding of unit-b2 increments, size M >= 2 (n - 1)."""
    from scipy.fft import next_fast_len, rfft

    size = next_fast_len(max(2 * (n - 1), 2))
    size += size % 2
    lags = np.arange(size // 2 + 1)
    row = flicker_increment_autocovariance(1.0, lags)
    circulant = np.concatenate([row, row[-2:0:-1]])
    eigenvalues = rfft(circulant).real
    # non-negative in exact arithmetic (Craigmile 2003); clip rounding only
    np.clip(eigenvalues, 0.0, None, out=eigenvalues)
    full = np.concatenate([eigenvalues, eigenvalues[-2:0:-1]])
    return np.sqrt(full / size)


@dataclass(frozen=True, repr=False)
class FN(Process):
    """Flicker noise (bias instability): x_t = (1 - B)^(-1/2) w_t, w_t i.i.d. N(0, b2).

    AV(m) is exact at every m (see the module docstring): 2 / pi b2 at m = 1,
    tending to (2 ln 2 / pi) b2, i.e. a flat Allan deviation 0.664 sqrt(b2).
    Simulation is exact (circulant embedding of the stationary increments).

    Parameters
    ----------
    b2 : float
        Variance of the driving white noise, >= 0; B = sqrt(b2) is the IEEE
        952 bias-instability coefficient in data units, at any sampling rate.

    Examples
    --------
    >>> FN(b2=1).theoretical_av([1, 2])
    array([0.63661977, 0.50929582])
    >>> x = FN(b2=1e-4).simulate(1000, seed=1)
    >>> x.shape
    (1000,)
    """

    b2: float
    name: ClassVar[str] = "FN"
    scale_field: ClassVar[str] = "b2"
    slope: ClassVar[float] = 0.0
    ad_coefficient: ClassVar[float] = math.sqrt(FLICKER_AV_FACTOR)
    coefficient_label: ClassVar[str] = "B [u]"

    def __post_init__(self) -> None:
        object.__setattr__(self, "b2", check_real(self.b2, "b2", minimum=0.0))

    @classmethod
    def from_continuous(cls, B: float, freq: float) -> FN:
        """Flicker noise of bias-instability coefficient ``B`` (data units) sampled at ``freq`` Hz.

        The spectral density b2 / (2 pi nu) per sample is B^2 / (2 pi f) per
        Hz at any rate (1/f noise is scale-free), so ``b2 = B^2`` and the
        Allan deviation plateau is sqrt(2 ln 2 / pi) B = 0.664 B (IEEE 952).

        >>> FN.from_continuous(0.5, 200.0)
        FN(b2=0.25)
        """
        check_freq(freq)
        return cls(b2=check_real(B, "B") ** 2)

    @property
    def B(self) -> float:
        """Bias-instability coefficient sqrt(b2), in data units."""
        return math.sqrt(self.b2)

    def _fill(self, out: np.ndarray, rng: np.random.Generator) -> None:
        from scipy.fft import fft

        replicates, n = out.shape
        if n == 1:
            rng.standard_normal(out=out)
            out *= math.sqrt(4.0 * self.b2 / math.pi)
            return
        roots = _embedding_roots(n)
        for row in range(0, replicates, 2):
            noise = rng.standard_normal((2, roots.size))
            series = fft(roots * (noise[0] + 1j * noise[1]))[:n]
            out[row] = series.real
            if row + 1 < replicates:
                out[row + 1] = series.imag
        np.cumsum(out, axis=1, out=out)
        out *= math.sqrt(self.b2)

    def _av(self, m: np.ndarray) -> np.ndarray:
        flat = np.asarray(m, dtype=np.int64).reshape(-1)
        return av_fn(self.b2, flat).reshape(np.shape(m))

    @staticmethod
    def unit_av(m: np.ndarray, shape: float | None = None) -> np.ndarray:
        """:func:`flicker_unit_av`."""
        return flicker_unit_av(m)

    @staticmethod
    def ieee_av(tau: np.ndarray) -> np.ndarray:
        """2 ln 2 / pi at every tau: AD = 0.664 B."""
        return np.full_like(tau, FLICKER_AV_FACTOR)

    @classmethod
    def coefficient(cls, scale: float, freq: float) -> float:
        """B = sqrt(b2), in u, at any rate."""
        return math.sqrt(scale)
