"""A sinusoid of random phase: :class:`SIN`, IEEE Std 952's sinusoidal term.

Real sensors pick up periodic disturbances (a pump, a fan, a temperature
controller cycling, the mains), which show in the Allan deviation as a bump
with a steep fall after it. Per sample::

    x_t = sqrt(2 a2) sin(2 pi f t + phase),   phase ~ U(0, 2 pi),

a stationary process of variance a2 (amplitude A = sqrt(2 a2)) and
frequency f in cycles per sample (0 < f < 1/2; f0 = f * rate in Hz). The
mean of m consecutive samples is a sinusoid of amplitude
A |sin(pi f m) / (m sin(pi f))|, and the difference of two adjacent means
multiplies it by 2 |sin(pi f m)|, so the Allan variance is exactly::

    AV(m) = A^2 sin^4(pi f m) / (m^2 sin^2(pi f)) = 2 a2 sin^4(pi f m) / (m sin(pi f))^2,

which for f m small is the continuous-time form of IEEE Std 952-1997, C.6,
A^2 sin^4(pi f0 tau) / (pi f0 tau)^2: zero at tau = 1 / f0, 2 / f0 ..., its
largest value near tau = 0.37 / f0, and a fall as tau^-2 (a slope of -1 in
deviation, steeper than white noise) beyond.

References
----------
IEEE Std 952-1997, Annex C.6 (sinusoidal noise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from avar._validation import check_freq, check_real
from avar.models.base import Process

__all__ = ["SIN", "av_sin"]


def av_sin(m: np.ndarray, a2: float, f: float) -> np.ndarray:
    """Allan variance at averaging factors ``m`` of a random-phase sinusoid of variance a2, f cycles/sample.

    >>> av_sin(np.array([1, 2, 4]), 0.5, 0.25).round(12)   # A = 1, a period of 4 samples
    array([0.5, 0.5, 0. ])
    """
    m = np.asarray(m, dtype=np.float64)
    return 2.0 * a2 * np.sin(np.pi * f * m) ** 4 / (m * math.sin(math.pi * f)) ** 2


@dataclass(frozen=True, repr=False)
class SIN(Process):
    """A sinusoid of random phase: x_t = sqrt(2 a2) sin(2 pi f t + phase).

    Parameters
    ----------
    a2 : float
        Variance of the sinusoid, >= 0 (amplitude sqrt(2 a2)), in data units squared.
    f : float
        Frequency in cycles per sample, 0 < f < 1/2 (f * rate in Hz).

    Examples
    --------
    >>> s = SIN.from_continuous(amplitude=2.0, frequency=1.5, freq=100.0)
    >>> round(s.a2, 12), round(s.f, 12), round(s.frequency(100.0), 12)
    (2.0, 0.015, 1.5)
    >>> float(s.theoretical_av(200))   # two whole periods per average: no trace left
    0.0
    """

    a2: float
    f: float
    name: ClassVar[str] = "SIN"
    scale_field: ClassVar[str] = "a2"
    shape_field: ClassVar[str] = "f"

    def __post_init__(self) -> None:
        object.__setattr__(self, "a2", check_real(self.a2, "a2", minimum=0.0))
        f = check_real(self.f, "f")
        if not 0.0 < f < 0.5:
            raise ValueError(f"f (cycles per sample) must be in (0, 0.5), below the Nyquist frequency; got {f!r}")
        object.__setattr__(self, "f", f)

    @classmethod
    def from_continuous(cls, amplitude: float, frequency: float, freq: float) -> SIN:
        """A sinusoid of ``amplitude`` (data units) and ``frequency`` (Hz) sampled at ``freq`` Hz."""
        rate = check_freq(freq)
        amplitude = check_real(amplitude, "amplitude", minimum=0.0)
        return cls(a2=amplitude**2 / 2.0, f=check_real(frequency, "frequency") / rate)

    @property
    def amplitude(self) -> float:
        """Peak amplitude sqrt(2 a2), in data units."""
        return math.sqrt(2.0 * self.a2)

    def frequency(self, freq: float) -> float:
        """Frequency in Hz at a sampling rate of ``freq`` Hz."""
        return self.f * check_freq(freq)

    def _fill(self, out: np.ndarray, rng: np.random.Generator) -> None:
        replicates, n = out.shape
        phase = rng.uniform(0.0, 2.0 * np.pi, size=(replicates, 1))
        out[:] = self.amplitude * np.sin(2.0 * np.pi * self.f * np.arange(1, n + 1) + phase)

    def _av(self, m: np.ndarray) -> np.ndarray:
        return av_sin(m, self.a2, self.f)

    @staticmethod
    def unit_av(m: np.ndarray, shape: float | None = None) -> np.ndarray:
        """:func:`av_sin` per unit a2 at f = ``shape``."""
        return av_sin(m, 1.0, shape)
