"""The Haar pyramid of ADEV and HDEV (octave factors, frequency data) against exact arithmetic
and against the general kernels."""

from __future__ import annotations

import numpy as np
import pytest

from avar._kernels.deviation_phase import scan
from avar._kernels.deviations import level_sums
from avar.stability.deviation_core import _octave_sums, detrended_phase_of, deviation_levels
from avar.stability.deviation_grids import KERNEL_CODES, deviation_factors, term_ranges
from tests.deviation_reference import exact_variance


def adversarial(seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [
        1e9 + 1e-6 * rng.standard_normal(257),  # offset over noise
        1e9 + 1e3 * np.arange(130.0) + 1e-6 * rng.standard_normal(130),  # and a drift
        rng.standard_normal(100) * 1e-11,
    ]


@pytest.mark.parametrize("estimator", ["adev", "hdev"])
def test_pyramid_is_exact(estimator):
    for y in adversarial(7):
        factors = deviation_factors(estimator, y.size + 1)
        variance, n = deviation_levels(estimator, y, factors, "freq")
        for m, v, count in zip(factors, variance, n):
            expected, terms = exact_variance(estimator, y, int(m), "freq")
            assert count == terms
            assert v == pytest.approx(float(expected), rel=1e-12)


@pytest.mark.parametrize("estimator", ["adev", "hdev"])
@pytest.mark.parametrize("n", [3, 4, 5, 1000, 4097])
def test_pyramid_equals_the_general_kernels(estimator, n):
    y = np.random.default_rng(n).standard_normal(n) + 3.0
    if n < 4 and estimator == "hdev":
        return
    factors = deviation_factors(estimator, n + 1)
    sums, counts, scale, phase, _ = _octave_sums(estimator, y, factors, scan(y))
    hi, lo, scale2, _, _ = detrended_phase_of(y, "freq", estimator)
    strides, first, last = term_ranges(estimator, n + 1, factors)
    general, general_counts = level_sums(hi, lo, KERNEL_CODES[estimator], factors, strides, first, last)
    np.testing.assert_array_equal(counts, general_counts)
    np.testing.assert_allclose(sums / scale**2, general / scale2**2, rtol=1e-12)
    np.testing.assert_allclose(phase / scale, hi / scale2, rtol=1e-9, atol=1e-9 * np.abs(hi / scale2).max())
