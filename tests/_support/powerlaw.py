"""Exact power-law noise for the tests: Kasdin-Walter fractional-difference filtering.

Phase noise with S_x(f) ~ f**(alpha - 2) is white noise passed through the
filter (1 - B)**(-(2 - alpha) / 2), whose impulse response
h_0 = 1, h_k = h_{k-1} (k - 1 + beta / 2) / k (beta = 2 - alpha) is applied by
FFT convolution (Kasdin and Walter 1992; Kasdin 1995, Proc. IEEE 83(5)).
"""

from __future__ import annotations

import numpy as np


def powerlaw_phase(n: int, alpha: int, seed: int) -> np.ndarray:
    """``n`` phase points of power-law noise S_y(f) ~ f**alpha (alpha = 2 .. -2)."""
    beta = 2 - alpha  # S_x(f) ~ f**-beta
    k = np.arange(1, n)
    h = np.concatenate(([1.0], np.cumprod((k - 1 + beta / 2) / k)))
    w = np.random.default_rng(seed).standard_normal(n)
    size = 2 * n
    return np.fft.irfft(np.fft.rfft(h, size) * np.fft.rfft(w, size), size)[:n]
