"""MTIE, TIE rms, PDEV and GCODEV's NumPy twins (:mod:`avar.stability.time_error.small`) against the kernels."""

import numpy as np
import pytest

import avar
from avar._kernels import time_error as kernels
from avar._kernels.runtime.paths import forced
from avar.stability.time_error import small

RNG = np.random.default_rng(39)
N = 3000
WHITE = RNG.standard_normal(N)
PHASES = {"white PM": WHITE, "white FM": np.cumsum(WHITE), "random-walk FM": np.cumsum(np.cumsum(WHITE)),
          "offset": np.cumsum(WHITE) * 1e3 + 5e9}
OTHER = np.cumsum(RNG.standard_normal(N))
FACTORS = np.array([1, 2, 3, 4, 5, 7, 8, 16, 33, 64, 128, 500, 1000, 1499, 2000, 2999], dtype=np.int64)
GAPPED = [3, 100, 101, 1500, 2990]


def _gaps(extra, gapped):
    missing = np.zeros(N - 1 + extra, dtype=bool)
    if gapped:
        missing[GAPPED] = True
    return np.concatenate(([0], np.cumsum(missing, dtype=np.int64)))


def _line_free(x):
    index = np.arange(x.size) - (x.size - 1) / 2
    slope, intercept = np.polyfit(index, x, 1)
    return x - intercept - slope * index


@pytest.mark.parametrize("name", sorted(PHASES))
@pytest.mark.parametrize("extra", [0, 1])
@pytest.mark.parametrize("gapped", [False, True])
def test_twins_equal_the_kernels(name, extra, gapped):
    x, gaps = PHASES[name], _gaps(extra, gapped)
    twin, kernel = small.mtie_levels(x, FACTORS, gaps, extra), kernels.mtie_levels(x, FACTORS, gaps, extra)
    assert np.array_equal(twin.ranges, kernel.ranges, equal_nan=True)  # a max - min rounds nothing
    assert twin.n_terms.tolist() == kernel.n_terms.tolist()
    twin, kernel = small.tierms_levels(x, FACTORS, gaps, extra), kernels.tierms_levels(x, FACTORS, gaps, extra)
    assert twin.n_terms.tolist() == kernel.n_terms.tolist()
    np.testing.assert_allclose(twin.sums, kernel.sums, rtol=1e-12, atol=0)
    pairs = FACTORS[2 * FACTORS < N]
    line_free = _line_free(x)
    twin, kernel = small.pdev_levels(line_free, pairs, gaps, extra), kernels.pdev_levels(line_free, pairs, gaps, extra)
    assert twin.n_terms.tolist() == kernel.n_terms.tolist()
    assert gapped or twin.n_terms.min() > 0
    np.testing.assert_allclose(twin.sums, kernel.sums, rtol=1e-12, atol=0)
    twin, kernel = small.codev_levels(x, OTHER, pairs, gaps, extra), kernels.codev_levels(x, OTHER, pairs, gaps, extra)
    assert twin.n_terms.tolist() == kernel.n_terms.tolist()
    np.testing.assert_allclose(twin.sums, kernel.sums, rtol=1e-12, atol=0)


def test_counts_and_sums_equal_plain_loops():
    """Every window and term by a plain loop over the definitions (small N, exact counts, gaps)."""
    x = np.cumsum(RNG.standard_normal(40))
    missing = np.zeros(40, dtype=bool)
    missing[[5, 22]] = True
    gaps = np.concatenate(([0], np.cumsum(missing, dtype=np.int64)))
    m = np.array([1, 2, 3, 6, 8, 13], dtype=np.int64)
    mtie, tie, pdev, codev = (small.mtie_levels(x, m, gaps, 1), small.tierms_levels(x, m, gaps, 1),
                              small.pdev_levels(x, m, gaps, 1), small.codev_levels(x, x[::-1].copy(), m, gaps, 1))
    for level, k in enumerate(m.tolist()):
        ranges = [np.ptp(x[i : i + k + 1]) for i in range(40 - k) if not missing[i : i + k + 1].any()]
        assert mtie.ranges[level] == max(ranges) and mtie.n_terms[level] == len(ranges)
        squares = [(x[i + k] - x[i]) ** 2 for i in range(40 - k) if not missing[i] | missing[i + k]]
        assert tie.sums[level] == pytest.approx(sum(squares), rel=1e-13) and tie.n_terms[level] == len(squares)
        weights = np.full(1, 1.0) if k == 1 else (k - 1) / 2 - np.arange(k)
        terms = [(x[i + 2] - 2 * x[i + 1] + x[i]) if k == 1 else weights @ (x[i : i + k] - x[i + k : i + 2 * k])
                 for i in range(40 - 2 * k) if not missing[i : i + 2 * k + (k == 1)].any()]
        assert pdev.sums[level] == pytest.approx(sum(t * t for t in terms), rel=1e-13) and pdev.n_terms[level] == len(terms)
        y = x[::-1]
        products = [(x[i + 2 * k] - 2 * x[i + k] + x[i]) * (y[i + 2 * k] - 2 * y[i + k] + y[i])
                    for i in range(40 - 2 * k) if not missing[[i, i + k, i + 2 * k]].any()]
        assert codev.sums[level] == pytest.approx(sum(products), rel=1e-12, abs=1e-12) and codev.n_terms[level] == len(products)


@pytest.mark.parametrize("data_type", ["freq", "phase"])
@pytest.mark.parametrize("nan", [False, True])
def test_public_functions_give_the_same_on_each_path(data_type, nan):
    data = WHITE.copy() if data_type == "freq" else np.cumsum(WHITE)
    if nan:
        data[[10, 700, 701]] = np.nan
    policy = "omit" if nan else "raise"
    for function in (avar.mtie, avar.tierms, avar.pdev):
        with forced("numpy"):
            twin = function(data, data_type=data_type, taus="all" if function is avar.mtie else "octave",
                            nan_policy=policy)
        with forced("compiled"):
            kernel = function(data, data_type=data_type, taus="all" if function is avar.mtie else "octave",
                              nan_policy=policy)
        assert twin.n.tolist() == kernel.n.tolist() and twin.alpha.tolist() == kernel.alpha.tolist()
        if function is avar.mtie:
            assert np.array_equal(twin.deviation, kernel.deviation)
        else:
            np.testing.assert_allclose(twin.deviation, kernel.deviation, rtol=1e-12, atol=0)
            np.testing.assert_allclose(twin.lci, kernel.lci, rtol=1e-12, atol=0)
    with forced("numpy"):
        twin = avar.gcodev(data, data[::-1].copy(), data_type=data_type, nan_policy=policy)
    with forced("compiled"):
        kernel = avar.gcodev(data, data[::-1].copy(), data_type=data_type, nan_policy=policy)
    assert twin.n.tolist() == kernel.n.tolist()
    np.testing.assert_allclose(twin.variance, kernel.variance, rtol=1e-12, atol=0)
