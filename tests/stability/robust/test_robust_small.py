"""The outlier search's NumPy twins (:mod:`avar.stability.robust.small`) against the kernels: equal bit for bit."""

import numpy as np
import pytest

import avar
from avar import _kernels
from avar._kernels.runtime.paths import forced
from avar.stability.robust import small

RNG = np.random.default_rng(39)


def _series(n):
    spiky = RNG.standard_normal(n)
    spiky[RNG.integers(0, n, max(1, n // 50))] += 30.0
    return {"spiky": spiky, "quantized": np.round(RNG.standard_normal(n))}  # the latter: many ties


@pytest.mark.parametrize("n", [1, 2, 3, 6, 11, 12, 2000])
def test_twins_equal_the_kernels(n):
    for name, x in _series(n).items():
        for half in (0, 1, 5, 8):
            twin, kernel = np.empty(n), np.empty(n)
            small.running_median(x, half, twin)
            _kernels.running_median(x, half, kernel)
            assert np.array_equal(twin, kernel), (name, half)
        for share in (0.0, 0.1, 0.6, 1.0):
            flagged = RNG.random(n) < share
            twin, kernel = np.empty(n), np.empty(n)
            small.interpolation_residuals(x, flagged, twin)
            _kernels.interpolation_residuals(x, flagged, kernel)
            assert np.array_equal(twin, kernel), (name, share)
            twin_flags, kernel_flags = flagged.copy(), flagged.copy()
            passes = (small.release_candidates(x, twin_flags, twin, 1.5, 50),
                      _kernels.release_candidates(x, kernel_flags, kernel, 1.5, 50))
            assert passes[0] == passes[1] and np.array_equal(twin_flags, kernel_flags) and np.array_equal(twin, kernel)


@pytest.mark.parametrize("n", [2, 3, 9, 5000])
def test_intact_squares_equal_the_kernel(n):
    x = np.cumsum(RNG.standard_normal(n))  # a random walk: large D_t, as the kernel meets them
    for share in (0.0, 0.01, 0.3):
        flagged = RNG.random(n) < share
        for m in sorted({m for m in (1, 2, 3, n // 7, n // 2) if 1 <= m <= n // 2}):  # the kernel's range
            twin, kernel = small.intact_squares(x, flagged, m), _kernels.intact_squares(x, flagged, m)
            assert twin == kernel, (share, m)  # the same roundings in the same order
            plain = [np.sum(x[t + m : t + 2 * m] - x[t : t + m]) ** 2 for t in range(n - 2 * m + 1)
                     if not flagged[t : t + 2 * m].any()]
            assert twin.n_terms == len(plain) and twin.total == pytest.approx(sum(plain), rel=1e-9)


def test_running_median_is_the_plain_median_of_the_mirrored_window():
    x = RNG.standard_normal(30)
    out = np.empty(30)
    small.running_median(x, 5, out)
    mirrored = np.concatenate((x[5:0:-1], x, x[-2:-7:-1]))  # x[-k] = x[k], x[n - 1 + k] = x[n - 1 - k]
    assert out.tolist() == [float(np.median(mirrored[t : t + 11])) for t in range(30)]


@pytest.mark.parametrize("every", [50, 20])
def test_robust_avar_gives_the_same_on_each_path(every):
    x = RNG.standard_normal(5000)
    x[::every] += 40.0  # 2 and 5 % of spikes: the short levels are summed clear of them (intact)
    with forced("numpy"):
        twin = avar.robust_avar(x, rate=100.0)
    with forced("compiled"):
        kernel = avar.robust_avar(x, rate=100.0)
    assert twin.intact.tolist() == kernel.intact.tolist() and twin.intact.any()
    assert twin.outliers.count == kernel.outliers.count > 0
    assert twin.outliers.indices.tolist() == kernel.outliers.indices.tolist()
    assert twin.outliers.scale == kernel.outliers.scale
    np.testing.assert_allclose(twin.allan, kernel.allan, rtol=1e-12, atol=0)
