"""The total family's NumPy twins (:mod:`avar.stability.total.small`) against the compiled kernels."""

import numpy as np
import pytest

import avar
from avar._kernels.classic.phase import detrended_phase
from avar._kernels.runtime.paths import forced
from avar._kernels.total.blocks import BLOCK_KERNELS
from avar._kernels.total.windows import DIRECT_KERNELS, level_sums
from avar.stability.classic.core import phase_line, phase_parts
from avar.stability.total import small

RNG = np.random.default_rng(39)
N = 4000
WHITE = RNG.standard_normal(N)
FREQ = np.fft.rfftfreq(2 * N)
FREQ[0] = 1.0
FLICKER = np.fft.irfft((RNG.standard_normal(FREQ.size) + 1j * RNG.standard_normal(FREQ.size)) / np.sqrt(FREQ))[:N]
PHASES = {"white PM": WHITE, "flicker PM": FLICKER, "white FM": np.cumsum(WHITE), "flicker FM": np.cumsum(FLICKER),
          "random-walk FM": np.cumsum(np.cumsum(WHITE)), "offset": np.cumsum(np.cumsum(WHITE)) * 1e3 + 5e9}
FACTORS = np.array([1, 2, 3, 5, 8, 16, 33, 64, 128, 256, 512, 1000, 1333])
NO_GAPS = np.zeros(0, dtype=np.int64)


@pytest.mark.parametrize("name", sorted(PHASES))
@pytest.mark.parametrize("kind", [0, 1])
def test_level_sums_equal_the_kernels(name, kind):
    x = PHASES[name]
    twin = small.level_sums(kind, x, FACTORS, NO_GAPS, 0)
    kernel = level_sums(kind, x, FACTORS, NO_GAPS, 0)
    assert twin is not None
    assert twin.n_terms.tolist() == kernel.n_terms.tolist() == (N - kind - 3 * FACTORS + 1).tolist()
    np.testing.assert_allclose(twin.sums, kernel.sums, rtol=1e-12, atol=0)


def test_level_sum_equals_the_definition():
    """A 3m-point window, detrended by the line through its halves' means, reflected (rev w, w, rev w),
    and its 6m second differences of m-point sums, squared: a plain loop."""
    x = PHASES["white FM"][:60]

    def plain(m):
        total = 0.0
        for n in range(x.size - 3 * m + 1):
            w = x[n : n + 3 * m]
            half = 3 * m // 2
            slope = (w[3 * m - half :].mean() - w[:half].mean()) / (3 * m - half)
            w = w - slope * np.arange(3 * m)
            w = w - w.mean()
            e = np.concatenate((w[::-1], w, w[::-1]))
            sums = np.array([e[j : j + m].sum() for j in range(9 * m)])
            z = np.array([sums[j] - 2 * sums[j + m] + sums[j + 2 * m] for j in range(6 * m)])
            total += np.sum(z * z) / (6.0 * m**3)
        return total

    for m in (1, 2, 5, 13, 20):
        total, bound = small.level_sum(x, m)
        assert total == pytest.approx(plain(m), rel=1e-12)
        assert 0 < bound < small.TOL * total


@pytest.mark.parametrize("kind, shift", [(0, 0), (0, 1), (1, 1)])
def test_gaps_skip_the_same_windows(kind, shift):
    x = PHASES["flicker FM"]
    missing = np.zeros(N - shift, dtype=bool)
    missing[[7, 8, 900, 2500]] = True
    missing[3000:3400] = True
    bad = np.concatenate(([0], np.cumsum(missing))).astype(np.int64)
    twin = small.level_sums(kind, x, FACTORS[:-2], bad, shift)
    kernel = level_sums(kind, x, FACTORS[:-2], bad, shift)
    assert twin.n_terms.tolist() == kernel.n_terms.tolist()
    assert 0 < twin.n_terms[-1] < N - 3 * FACTORS[-3]
    np.testing.assert_allclose(twin.sums, kernel.sums, rtol=1e-12, atol=0)


@pytest.mark.parametrize("data_type", ["freq", "phase"])
@pytest.mark.parametrize("estimator", ["oadev", "ohdev"])
def test_twin_phase_is_the_kernels_bit_for_bit(data_type, estimator):
    data = np.cumsum(WHITE) * 1e-9 + 0.3 if data_type == "phase" else WHITE * 1e-11 + 2e-9 + 1e-15 * np.arange(N)
    data = data.copy()
    data[[10, 11, 2000]] = np.nan
    line = phase_line(data, data_type, estimator)
    twin = small.twin_phase(line.filled, int(data_type == "phase"), line.centre, line.slope, line.scale)
    assert np.array_equal(twin, phase_parts(data, data_type, estimator).hi)


@pytest.mark.parametrize("data_type", ["freq", "phase"])
def test_twin_phase_of_several_blocks_is_the_kernels_bit_for_bit(data_type):
    """Blocks of 1000 increments (the kernel's second pass starts each from the earlier blocks'
    total) and of the default size: the same bits as :func:`detrended_phase`."""
    data = np.cumsum(np.cumsum(WHITE)) * 1e-6 + 7.0 if data_type == "phase" else WHITE * 1e-11 + 2e-9
    kind = int(data_type == "phase")
    line = phase_line(data, data_type, "oadev")
    for block in (1000, 999, N):
        hi = np.empty(N + 1 - kind)
        lo = np.empty(N + 1 - kind, dtype=np.float32)
        detrended_phase(line.filled, np.zeros(1, dtype=np.float32), kind, float(line.centre), line.slope, line.scale,
                        hi, lo, block)
        twin = small.twin_phase(line.filled, kind, line.centre, line.slope, line.scale, block)
        assert np.array_equal(twin, hi)
    long = np.concatenate([WHITE] * 40)[: 3 * (1 << 16) + 17] * 1e-3 + 1.0  # four default blocks
    line = phase_line(long, "freq", "oadev")
    assert np.array_equal(small.twin_phase(line.filled, 0, line.centre, line.slope, line.scale),
                          phase_parts(long, "freq", "oadev").hi)


@pytest.mark.parametrize("name", ["mtotdev", "ttotdev", "htotdev", "mhtotdev", "theo1", "theoh"])
@pytest.mark.parametrize("data_type", ["freq", "phase"])
@pytest.mark.parametrize("gaps", [False, True])
def test_each_path_gives_the_same_deviation(name, data_type, gaps):
    data = (WHITE[:1500] if data_type == "freq" else np.cumsum(FLICKER[:1500])).copy()
    if gaps:
        if name == "theoh":
            return  # theoh refuses gaps on either path
        data[[3, 700, 701]] = np.nan
    results = []
    for mode in ("numpy", "compiled"):
        with forced(mode):
            results.append(getattr(avar, name)(data, data_type=data_type, nan_policy="omit" if gaps else "raise"))
    twin, kernel = results
    assert twin.n.tolist() == kernel.n.tolist() and twin.alpha.tolist() == kernel.alpha.tolist()
    np.testing.assert_allclose(twin.variance, kernel.variance, rtol=1e-12, atol=0)
    np.testing.assert_allclose(twin.edf, kernel.edf, rtol=1e-12, atol=0)


@pytest.mark.parametrize("name", ["white FM", "random-walk FM", "offset"])
@pytest.mark.parametrize("shift", [0, 1])
def test_theo1_sums_equal_the_direct_kernel(name, shift):
    x = PHASES[name]
    factors = np.array([2, 4, 10, 64, 500, 2000, 3998])
    for bad in (NO_GAPS, np.concatenate(([0], np.cumsum(np.isin(np.arange(N - shift), [5, 6, 1900])))).astype(np.int64)):
        twin = small.theo1_level_sums(x, factors, bad, shift)
        kernel = level_sums(2, x, factors, bad, shift)
        assert twin.n_terms.tolist() == kernel.n_terms.tolist()
        np.testing.assert_allclose(twin.sums, kernel.sums, rtol=1e-12, atol=0)
    assert small.theo1_work(N, factors) == sum((N - m) * (m // 2) for m in factors.tolist())


def test_oavar_sums_equal_the_kernel():
    from avar._kernels.total.theobr import oavar_sums

    x = PHASES["random-walk FM"]
    factors = np.array([1, 2, 7, 100, 1999])
    np.testing.assert_allclose(small.oavar_sums(x, factors), oavar_sums(x, factors), rtol=1e-13, atol=0)


def test_uncertified_levels_run_the_kernels(monkeypatch):
    x = PHASES["random-walk FM"]
    monkeypatch.setattr(small, "TOL", 1e-30)
    assert small.level_sums(0, x, FACTORS, NO_GAPS, 0) is None
    with forced("compiled"):
        kernel = avar.mtotdev(WHITE)
    with forced("numpy"):
        fallback = avar.mtotdev(WHITE)
    np.testing.assert_allclose(fallback.variance, kernel.variance, rtol=1e-13, atol=0)  # (the scan's twin may move the line)


def test_compiled_kernels_name_the_route():
    assert small.compiled_kernels(0, 10_000, np.array([1, 1024]), False) == BLOCK_KERNELS
    assert small.compiled_kernels(0, 300, np.array([1, 8]), False) == DIRECT_KERNELS
    assert small.compiled_kernels(0, 10_000, np.array([1, 3333]), False) == BLOCK_KERNELS + DIRECT_KERNELS
    assert small.compiled_kernels(0, 10_000, np.array([1]), True) == BLOCK_KERNELS + DIRECT_KERNELS


def test_auto_takes_the_twins_only_while_the_kernels_are_cold(monkeypatch):
    from avar._kernels.runtime import paths

    calls = []
    real = small.level_sums, small.theo1_level_sums
    monkeypatch.setattr(small, "level_sums", lambda *a: calls.append("levels") or real[0](*a))
    monkeypatch.setattr(small, "theo1_level_sums", lambda *a: calls.append("theo1") or real[1](*a))
    with forced("compiled"):  # compiled (or loaded from numba's cache) in this process
        kernel = avar.mtotdev(WHITE), avar.theo1(WHITE)
    with forced("auto"):
        warm = avar.mtotdev(WHITE), avar.theo1(WHITE)
        assert calls == []
        monkeypatch.setattr(paths, "compiled", lambda *a, **k: False)  # as in a fresh process
        monkeypatch.setattr(paths, "_WARM_ROUTES", set())
        monkeypatch.setattr(paths, "_SPENT", {})
        cold = avar.mtotdev(WHITE), avar.theo1(WHITE)
        assert calls == ["levels", "theo1"]
        avar.mtotdev(np.tile(WHITE, 60))  # 2.4e5 samples: beyond the twin's limit
        assert calls == ["levels", "theo1"]
    for a, b, c in zip(kernel, warm, cold):
        np.testing.assert_array_equal(a.variance, b.variance)
        np.testing.assert_allclose(c.variance, a.variance, rtol=1e-12, atol=0)
