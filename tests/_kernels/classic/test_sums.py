"""The numba kernels against a plain NumPy twin of the same computation."""

from __future__ import annotations

import numpy as np
import pytest

from avar import _kernels
from avar.stability.allan.columns import allan_variance_columns
from avar.stability.shared.grids import averaging_factors
from avar.stability.shared.term_counts import n_differences


def numpy_twin(data: np.ndarray, factors: np.ndarray, type: str) -> np.ndarray:
    """Same algorithm in plain NumPy: cumulative sums, second differences."""
    out = []
    for column in data.T:
        cumulative = np.concatenate(([0.0], np.cumsum(column - column.mean())))
        row = []
        for m in factors:
            b = np.arange(n_differences(column.size, np.array([m]), type)[0]) * (m if type == "to" else 1)
            d = cumulative[b + 2 * m] - 2 * cumulative[b + m] + cumulative[b]
            row.append(np.mean(d**2) / (2 * m * m))
        out.append(row)
    return np.array(out)


def cumsums(data, centre, scale, block=_kernels.CUMSUM_BLOCK):
    hi = np.empty((data.shape[1], data.shape[0] + 1))
    lo = np.empty((data.shape[1], data.shape[0] + 1), dtype=np.float32)
    _kernels.centred_cumsum(data, centre, scale, hi, lo, block)
    return hi, lo


@pytest.mark.parametrize("type", ["mo", "to"])
def test_columns_match_numpy_twin(type):
    rng = np.random.default_rng(10)
    data = rng.standard_normal((5000, 4)) * [1.0, 10.0, 0.01, 3.0]
    factors = averaging_factors(5000, taus="decade")
    np.testing.assert_allclose(allan_variance_columns(data, factors, type), numpy_twin(data, factors, type), rtol=1e-12)


def test_compensated_cumsum_is_exact_pair():
    rng = np.random.default_rng(11)
    x = 1e8 + rng.standard_normal((300_000, 1))
    hi, lo = cumsums(x, np.array([1e8 + 0.3]), np.array([0.5]), block=1000)
    exact = np.concatenate(([0.0], np.cumsum((x[:, 0] - (1e8 + 0.3)) * 0.5)))  # reference to ~1e-7
    assert np.max(np.abs(hi[0] + lo[0] - exact)) < 1e-6
    # The block split changes only O(eps**2) terms.
    hi2, lo2 = cumsums(x, np.array([1e8 + 0.3]), np.array([0.5]), block=1 << 20)
    assert np.max(np.abs((hi[0] - hi2[0]) + (lo[0].astype(float) - lo2[0]))) < 1e-9


def test_fused_and_level_wise_paths_agree():
    rng = np.random.default_rng(12)
    data = np.cumsum(rng.standard_normal((20_000, 2)), axis=0)
    hi, lo = cumsums(data, data.mean(axis=0), np.ones(2))
    factors = averaging_factors(20_000)
    counts = n_differences(20_000, factors, "mo")
    fused = _kernels.fused_overlapping_sums(hi, lo, factors, counts).sum(axis=1)
    for chunk in (7, 1000, 1 << 15):
        n_levels = factors.size
        sums = _kernels.task_sums(
            hi,
            lo,
            np.repeat(np.arange(2), n_levels),
            np.tile(factors, 2),
            np.ones(2 * n_levels, dtype=np.int64),
            np.zeros(2 * n_levels, dtype=np.int64),
            np.tile(counts, 2),
        ).reshape(2, n_levels)
        np.testing.assert_allclose(sums, fused, rtol=1e-13)
        split = _kernels.squared_difference_sums(hi, lo, factors, np.full_like(factors, 1), counts, chunk=chunk)
        np.testing.assert_allclose(split, fused, rtol=1e-13)


def test_many_levels_use_level_wise_path_with_same_values():
    x = np.random.default_rng(13).standard_normal((600, 1))
    every = averaging_factors(600, taus="all")  # more than FUSED_MAX_LEVELS levels
    assert every.size > _kernels.FUSED_MAX_LEVELS
    np.testing.assert_allclose(allan_variance_columns(x, every, "mo"), numpy_twin(x, every, "mo"), rtol=1e-12)
