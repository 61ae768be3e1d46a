"""The NumPy twins of the lag-1 noise identification's kernels (:mod:`avar.stability.uncertainty.lag1`)."""

from __future__ import annotations

import numpy as np
import pytest

from avar._kernels.runtime.paths import forced
from avar._kernels.uncertainty.lag1 import lag1_alpha_decimated
from avar._kernels.uncertainty.noise_id import running_sum
from avar.stability.uncertainty.lag1 import decimated_alpha, lag1_alphas, running_sums


def series(kind: str, n: int, seed: int) -> np.ndarray:
    w = np.random.default_rng(seed).standard_normal(n)
    drift = 1e3 + 0.5 * np.arange(n)  # a phase and a frequency offset
    return {"white pm": w, "white fm": np.cumsum(w), "rw fm": np.cumsum(np.cumsum(w))}[kind] + drift


@pytest.mark.parametrize("kind", ["white pm", "white fm", "rw fm"])
@pytest.mark.parametrize("dmax", [2, 3])
def test_the_twin_equals_the_kernel(kind, dmax):
    for seed in range(4):
        x = series(kind, 5000, seed)
        detrended = x - 0.5 * np.arange(5000)
        for m in (1, 2, 3, 7, 16, 64, 150):
            assert decimated_alpha(x, m, dmax, np.nan) == lag1_alpha_decimated(x, m, dmax, np.nan), (seed, m)
            # phase data: the line the caller removed comes back, only the mean goes
            assert decimated_alpha(detrended, m, dmax, 0.5) == lag1_alpha_decimated(detrended, m, dmax, 0.5)


def test_a_large_frequency_offset_keeps_its_digits_and_a_constant_gives_nan():
    for seed in range(4):
        w = np.random.default_rng(seed).standard_normal(3000)
        for noise, alpha in ((w, 2.0), (np.cumsum(w), 0.0)):
            assert decimated_alpha(noise, 1, 2, 1e12) == alpha
    assert np.isnan(decimated_alpha(np.full(100, 3.5), 1, 2, np.nan))
    assert np.isnan(decimated_alpha(np.full(100, 3.5), 1, 2, 0.0))


def test_both_paths_of_every_level_agree():
    x = series("white fm", 20_000, 1)
    factors = np.array([1, 2, 4, 8, 16, 32, 64, 128, 256], dtype=np.int64)
    for line in (np.nan, 0.0, -0.5):
        with forced("numpy"):
            twin = lag1_alphas(x, factors, 2, line)
        with forced("compiled"):
            kernel = lag1_alphas(x, factors, 2, line)
        np.testing.assert_array_equal(twin, kernel)


@pytest.mark.parametrize("step", [1, 3, 64])
def test_running_sums_equal_the_kernel(step):
    x = np.random.default_rng(2).standard_normal(1001)
    for drift in (0.0, 1e-3):
        with forced("numpy"):
            twin = running_sums(x, drift, step)
        kernel = np.empty(x.size // step + 1)
        running_sum(x, drift, step, kernel)
        np.testing.assert_allclose(twin, kernel, rtol=1e-12, atol=1e-12)
