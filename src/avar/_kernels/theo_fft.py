"""Theo1 at one even factor in O(N log N + m log^2 m) (NumPy FFT and a numba leaf).

With a = m/2 - d, w_a = 1 / a, h = m / 2 and n = N - m, Theo1's double sum is
S = sum_{i<n} sum_{a=1}^{h} w_a (A - B + C - D)^2 with A = x_i, B = x_{i+a},
C = x_{i+m}, D = x_{i+m-a}. Expanded: the squares are running sums of x^2;
AC is one dot product; AB + AD and BC + CD are one correlation and one
convolution of x with the kernel k_t = w_t (t = 1..h) + w_{m-t} (t = h..m-1);
BD = sum_u w_{h-u} sum_c x_{c-u} x_{c+u} (c = h .. h + n - 1) is the record's
autocorrelation at even lags 2u < m less two triangles, {p + q < m} at each
end, of products weighted by a function of q - p: those are summed by halving
(a square by FFT, two half-size triangles recursively). The expansion loses
digits when the terms are much smaller than the data (strongly correlated
phase at small m): :func:`theo1_expanded` reports the ratio and the caller
keeps the direct sum where it is large.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Triangles at most this wide are summed directly.
LEAF = 256


@njit(cache=True)
def _triangle_direct(x: np.ndarray, p0: int, q0: int, s: int, g: np.ndarray, g0: int) -> float:
    """sum_{p, q >= 0, p + q < s} g[g0 + (q0 + q) - (p0 + p)] x[p0 + p] x[q0 + q]."""
    total = 0.0
    for p in range(s):
        acc = 0.0
        base = g0 + q0 - p0 - p
        for q in range(s - p):
            acc += g[base + q] * x[q0 + q]
        total += acc * x[p0 + p]
    return total


def _square(x: np.ndarray, p0: int, q0: int, t: int, g: np.ndarray, g0: int) -> float:
    """sum_{p, q < t} g[g0 + q0 + q - p0 - p] x[p0 + p] x[q0 + q], by one FFT correlation."""
    a = x[p0 : p0 + t]
    b = x[q0 : q0 + t]
    d = q0 - p0
    kernel = g[g0 + d - (t - 1) : g0 + d + t][::-1]  # kernel[j] = g(d + t - 1 - j)
    size = 1 << int(2 * t - 1).bit_length()
    full = np.fft.irfft(np.fft.rfft(b, size) * np.fft.rfft(kernel, size), size)
    return float(a @ full[t - 1 : 2 * t - 1])


def triangle_sum(x: np.ndarray, p0: int, q0: int, s: int, g: np.ndarray, g0: int) -> float:
    """sum_{p, q >= 0, p + q < s} g(q0 + q - p0 - p) x[p0 + p] x[q0 + q], g(d) = g[g0 + d],
    in O(s log^2 s): the square p, q < s // 2 by FFT, then the two triangles beyond it."""
    if s <= LEAF:
        return _triangle_direct(x, p0, q0, s, g, g0)
    t = s // 2
    total = _square(x, p0, q0, t, g, g0)
    total += triangle_sum(x, p0 + t, q0, s - t, g, g0)
    total += triangle_sum(x, p0, q0 + t, s - t, g, g0)
    if s % 2:  # the point (t, t) lies in both triangles
        total -= g[g0 + q0 - p0] * x[p0 + t] * x[q0 + t]
    return total


def autocorrelation(x: np.ndarray) -> np.ndarray:
    """F[L] = sum_{p=0}^{N-1-L} x_p x_{p+L}, L = 0 .. N - 1, by FFT."""
    n = x.shape[0]
    size = 1 << int(2 * n).bit_length()
    spectrum = np.fft.rfft(x, size)
    return np.fft.irfft(spectrum * np.conj(spectrum), size)[:n]


def theo1_expanded(x: np.ndarray, m: int, squares: np.ndarray, autocorr: np.ndarray,
                   reverse: np.ndarray) -> tuple[float, float]:
    """Theo1's double sum at even m (see the module) and the size of its largest parts
    (the square terms, or the whole record's energy times sum w_a) relative to it: the
    result has about ``eps * ratio`` relative error. ``squares``: running sum of x^2 (length N + 1); ``autocorr``:
    :func:`autocorrelation`; ``reverse``: x reversed. Costs O(m log^2 m)."""
    n_points = x.shape[0]
    n = n_points - m
    h = m // 2
    a = np.arange(1, h + 1)
    w = 1.0 / a
    weight = float(w.sum())
    square_terms = (weight * (squares[n] + squares[n_points] - squares[m])
                    + float(w @ (squares[a + n] - squares[a])) + float(w @ (squares[m - a + n] - squares[m - a])))
    kernel = np.zeros(2 * m + 1)  # k(d) at kernel[m + d], d = -m .. m; zero for d <= 0
    kernel[m + 1 : m + h + 1] += w
    kernel[m + h : 2 * m] += w[m - np.arange(h, m) - 1]
    # AB + AD = sum_t k_t F[t] less the pairs past the end; BC + CD = the same less those before m
    ends = _square(x, 0, 0, m, kernel, m) + _square(reverse, 0, 0, m, kernel, m)
    cross = 2.0 * float(kernel[m + 1 : 2 * m] @ autocorr[1:m]) - ends
    u = np.arange(h)
    band = float(w[h - u - 1] @ autocorr[2 * u])
    g = np.zeros(2 * m + 1)  # g(d), d = -m .. m: w_{h - |d|/2} / 2 for even d != 0, w_h at 0
    even = np.arange(-(m - 2), m - 1, 2)
    g[m + even] = w[h - np.abs(even) // 2 - 1] / 2.0
    g[m] = w[h - 1]
    corners = triangle_sum(x, 0, 0, m, g, m) + triangle_sum(reverse, 0, 0, m, g, m)
    total = square_terms + 2.0 * weight * autocorr[m] - 2.0 * cross + 2.0 * (band - corners)
    # the FFT autocorrelation errs by about eps * sum(x^2) at every lag: weigh the whole record
    ratio = max(square_terms, weight * squares[n_points]) / total if total > 0 else np.inf
    return total, ratio


#: Levels with fewer inner terms than this are summed directly (cheaper than the FFTs).
DIRECT_TERMS = 1 << 22
#: Above this ratio of its square terms to the result the expansion may have lost more than
#: about 1e-11 (relative): the level is summed directly instead.
MAX_RATIO = 1e4


def theo1_sums(x: np.ndarray, factors: np.ndarray, direct) -> tuple[np.ndarray, int]:
    """Theo1's double sums of gap-free ``x`` at the even ``factors``: directly (``direct(x, m)``)
    where that is cheap or the expansion ill-conditioned, else by :func:`theo1_expanded`.
    Returns the sums and how many levels took the expansion."""
    n_points = x.shape[0]
    sums = np.empty(factors.shape[0])
    prepared = None
    expanded = 0
    for level, m in enumerate(factors.tolist()):
        if (n_points - m) * (m // 2) > DIRECT_TERMS:
            if prepared is None:
                prepared = (np.concatenate(([0.0], np.cumsum(x * x))), autocorrelation(x),
                            np.ascontiguousarray(x[::-1]))
            total, ratio = theo1_expanded(x, m, *prepared)
            if ratio <= MAX_RATIO:
                sums[level] = total
                expanded += 1
                continue
        sums[level] = direct(x, m)
    return sums, expanded
