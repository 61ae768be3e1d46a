"""The compiled Greenhall BasicSum against its plain NumPy twin (vectorized over lags)."""

from __future__ import annotations

from math import comb

import numpy as np
import pytest

from avar._kernels.uncertainty.edf import basic_sums, sz


def plain_sw(t: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """Greenhall's s_w(t) (eq. 7): the generalized autocovariance of power-law phase noise."""
    a = np.abs(t)
    with np.errstate(divide="ignore", invalid="ignore"):
        log = np.where(a > 0, np.log(np.where(a > 0, a, 1.0)), 0.0)
    return np.select(
        [alpha == 2, alpha == 1, alpha == 0, alpha == -1, alpha == -2, alpha == -3],
        [-a, t**2 * log, a**3, -(t**4) * log, -(a**5), t**6 * log],
        a**7,
    )


def plain_sz(t: np.ndarray, f: np.ndarray, alpha: np.ndarray, d: int) -> np.ndarray:
    """s_z(t) (eqs. 8-9): d-th difference of s_x, the filter F (inf: the unmodified limit)."""
    finite = np.isfinite(f)
    h = np.where(finite, 1.0 / np.where(finite, f, 1.0), 0.0)
    total = np.zeros(np.broadcast(t, f, alpha).shape)
    for k in range(-d, d + 1):
        s = t + k
        sx = np.where(finite, np.where(finite, f, 0.0) ** 2 * (2 * plain_sw(s, alpha) - plain_sw(s - h, alpha) - plain_sw(s + h, alpha)),
                      plain_sw(s, alpha + 2))
        total += (-1) ** k * comb(2 * d, d + k) * sx
    return total


def plain_basic_sum(j: np.ndarray, m: np.ndarray, s: np.ndarray, f: np.ndarray, alpha: np.ndarray, d: int) -> np.ndarray:
    """Greenhall's BasicSum(J, M, S, F) (eq. 10), one row per level, rows in blocks."""
    out = np.empty(j.shape)
    for first in range(0, j.size, 2048):
        rows = slice(first, first + 2048)
        lags = np.arange(int(j[rows].max()) + 1, dtype=np.float64)
        jj, mm = j[rows, None], m[rows, None]
        weights = np.where(lags == 0, 1.0, np.where(lags < jj, 2.0 * (1.0 - lags / mm),
                                                    np.where(lags == jj, 1.0 - jj / mm, 0.0)))
        sz = plain_sz(lags / s[rows, None], f[rows, None], alpha[rows, None], d)
        out[rows] = np.sum(weights * sz**2, axis=1)
    return out



@pytest.mark.parametrize("d", [1, 2, 3])
@pytest.mark.parametrize("modified", [False, True])
def test_basic_sums_equal_the_numpy_twin(d, modified):
    rng = np.random.default_rng(d)
    alpha = rng.integers(max(-3, 2 - 2 * d), 3, size=40)
    m = rng.integers(1, 60, size=40).astype(np.float64)
    s = m.copy()
    j = np.minimum(m * (d + 1), 100.0)
    big_m = j + rng.integers(0, 50, size=40)
    f = np.ones(40) if modified else np.where(rng.random(40) < 0.5, m, np.inf)
    norm = np.full(40, np.nan)
    denominator = big_m.copy()
    out = np.empty(40)
    basic_sums(j, big_m, s, f, alpha, d, norm, denominator, out)
    expected = plain_basic_sum(j, big_m, s, f, alpha, d) / (plain_sz(np.zeros(40), f, alpha, d) ** 2 * denominator)
    np.testing.assert_allclose(out, expected, rtol=1e-9)  # large powers cancel: the order of the sums shows at ~1e-12
    assert sz(0.0, 1.0, 0, d) == pytest.approx(float(plain_sz(np.zeros(1), np.ones(1), np.zeros(1, int), d)[0]))


@pytest.mark.parametrize("d", [1, 2, 3])
def test_greenhall_sums_in_numpy_equal_the_compiled_ones(d):
    """NumPy's sums (a cold process) and the compiled loops: the same values either way."""
    from avar._kernels.runtime.paths import forced
    from avar._kernels.uncertainty.edf import NUMPY_ROWS, greenhall_sums

    rng = np.random.default_rng(10 + d)
    rows = NUMPY_ROWS
    alpha = rng.integers(max(-3, 2 - 2 * d), 3, size=rows)
    m = rng.integers(1, 60, size=rows).astype(np.float64)
    j = np.minimum(m * (d + 1), 100.0)
    big_m = j + rng.integers(0, 50, size=rows)
    f = np.where(rng.random(rows) < 0.5, m, np.inf)
    norm = np.where(rng.random(rows) < 0.2, 2.0, np.nan)
    args = (j, big_m, m.copy(), f, alpha, d, norm, big_m.copy())
    compiled = np.empty(rows)
    basic_sums(*args, compiled)
    with forced("numpy"):
        np.testing.assert_allclose(greenhall_sums(*args), compiled, rtol=1e-9)
    many = [np.concatenate([a, a]) if isinstance(a, np.ndarray) else a for a in args]
    with forced("compiled"):  # (a cold process, or AVAR_KERNEL_PATH=numpy, would take NumPy's sums for these too)
        np.testing.assert_array_equal(greenhall_sums(*many), np.concatenate([compiled, compiled]))


@pytest.mark.parametrize("alpha", [2, 1, 0, -1, -2])
@pytest.mark.parametrize("f_kind", ["finite", "infinite"])
def test_greenhall_sums_of_one_noise_type_equal_the_compiled_ones(alpha, f_kind):
    """One noise exponent for every row (a long record's octave levels): NumPy computes only its power."""
    from avar._kernels.runtime.paths import forced
    from avar._kernels.uncertainty.edf import greenhall_sums

    d = 2
    m = 2.0 ** np.arange(12)
    j = np.minimum(m * (d + 1), 100.0)
    big_m = j + 7.0
    f = m.copy() if f_kind == "finite" else np.full(12, np.inf)
    args = (j, big_m, m.copy(), f, np.full(12, alpha), d, np.full(12, np.nan), big_m.copy())
    compiled = np.empty(12)
    basic_sums(*args, compiled)
    expected = plain_basic_sum(j, big_m, m, f, np.full(12, alpha), d) / (
        plain_sz(np.zeros(12), f, np.full(12, alpha), d) ** 2 * big_m)
    for path in ("numpy", "compiled"):
        with forced(path):
            np.testing.assert_allclose(greenhall_sums(*args), compiled, rtol=1e-9)
            np.testing.assert_allclose(greenhall_sums(*args), expected, rtol=1e-9)
