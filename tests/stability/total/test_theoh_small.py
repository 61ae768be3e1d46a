"""ThêoH's bias factor kf by its NumPy twin (:mod:`avar.stability.total.small_theobr`) against the compiled kernels."""

import numpy as np
import pytest

import avar
from avar._kernels.runtime.paths import forced
from avar._kernels.total.theo1 import SplitSums
from avar._kernels.total.theobr import oavar_sums
from avar._kernels.total.windows import theo1_sum
from avar.stability.total import small_theobr, theobr

RNG = np.random.default_rng(3939)
N = 3001
WHITE = RNG.standard_normal(N)
FREQ = np.fft.rfftfreq(2 * N)
FREQ[0] = 1.0
FLICKER = np.fft.irfft((RNG.standard_normal(FREQ.size) + 1j * RNG.standard_normal(FREQ.size)) / np.sqrt(FREQ))[:N]
#: Frequency data (theoh's default data_type) of each noise.
FREQUENCY = {"white PM": np.diff(WHITE), "white FM": WHITE, "flicker FM": FLICKER,
             "random-walk FM": np.cumsum(WHITE), "offset": WHITE * 1e-3 + 5e9}


def _detrended(x: np.ndarray) -> np.ndarray:
    t = np.arange(x.size)
    return x - np.polyval(np.polyfit(t, x, 1), t)


@pytest.mark.parametrize("name", sorted(FREQUENCY))
@pytest.mark.parametrize("size", [N - 1, N - 2, 18, 19, 24, 101])
def test_theoh_numpy_equals_compiled(name, size):
    """Both paths on the same data (N even and odd, down to MIN_THEOBR_POINTS phase points)."""
    y = FREQUENCY[name][:size]
    taus = "all" if size < 200 else "octave"
    with forced("numpy"):
        twin = avar.theoh(y, taus=taus)
    with forced("compiled"):
        kernel = avar.theoh(y, taus=taus)
    assert twin.averaging_factors.tolist() == kernel.averaging_factors.tolist()
    np.testing.assert_allclose(twin.deviation, kernel.deviation, rtol=1e-9, atol=0)


@pytest.mark.parametrize("name", sorted(FREQUENCY))
def test_kf_twin_equals_kernels_and_definition(name):
    """kf's terms by the twin, by the kernels, and (every 37th) by the direct sums."""
    x = _detrended(np.concatenate(([0.0], np.cumsum(FREQUENCY[name]))))
    terms = theobr.twin_terms(x)
    assert terms is not None  # these records are well-conditioned: the twin answers
    kernel, n = theobr.theobr_terms(x)
    assert n == theobr.theobr_count(x.size) == terms.size - 1
    np.testing.assert_allclose(terms, kernel, rtol=1e-8, atol=0)
    with forced("numpy"):
        kf_twin = theobr.theobr_factor(x)
    with forced("compiled"):
        kf_kernel = theobr.theobr_factor(x)
    assert kf_twin.n == kf_kernel.n == n
    assert kf_twin.kf == pytest.approx(kf_kernel.kf, rel=theobr.KF_TOLERANCE)
    no_gaps = np.zeros(0, dtype=np.int64)
    for i in range(0, n + 1, 37):
        m_avar, m_theo = 9 + 3 * i, 12 + 4 * i
        avar_i = oavar_sums(x, np.array([m_avar]))[0] / (2.0 * m_avar**2 * (x.size - 2 * m_avar))
        theo_i = theo1_sum(x, m_theo, no_gaps, 0).total / (0.75 * (x.size - m_theo) * m_theo**2)
        assert terms[i] == pytest.approx(avar_i / theo_i, rel=1e-9)


def test_ill_conditioned_kf_sums_directly_or_falls_back_to_the_kernels(monkeypatch):
    """A phase far from zero: the expanded sums cancel. The twin redoes the levels that need it,
    by the split expansion (its loops' twins) and then directly while that is cheap (its terms
    then match the definition); when direct terms remain beyond its budget it declines, and the
    kernels' kf is used."""
    x = np.cumsum(WHITE[:600]) + 1e9
    terms = theobr.twin_terms(x)
    no_gaps = np.zeros(0, dtype=np.int64)
    for i in range(terms.size):
        m_avar, m_theo = 9 + 3 * i, 12 + 4 * i
        avar_i = oavar_sums(x, np.array([m_avar]))[0] / (2.0 * m_avar**2 * (x.size - 2 * m_avar))
        theo_i = theo1_sum(x, m_theo, no_gaps, 0).total / (0.75 * (x.size - m_theo) * m_theo**2)
        assert terms[i] == pytest.approx(avar_i / theo_i, rel=1e-9)
    with forced("compiled"):
        kf_kernel = theobr.theobr_factor(x)
    with forced("numpy"):
        assert theobr.theobr_factor(x).kf == pytest.approx(kf_kernel.kf, rel=theobr.KF_TOLERANCE)

    def no_help(x, factors, reach, allan=None, every=None):  # a split that conditions nothing
        allan = np.zeros(0) if allan is None else allan
        return SplitSums(np.zeros(len(factors)), np.full(len(factors), np.inf), np.zeros(len(allan)),
                         np.full(len(allan), np.inf))

    monkeypatch.setattr(theobr, "split_sums", no_help)
    monkeypatch.setattr(small_theobr, "TWIN_DIRECT_TERMS", 0)
    with forced("compiled"):
        kf_kernel = theobr.theobr_factor(x)
    with forced("numpy"):
        assert theobr.twin_terms(x) is None
        assert theobr.theobr_factor(x) == kf_kernel


def test_kf_of_random_walk_fm_takes_the_split_cold():
    """Random-walk FM at 6e4 points: about 70 Theo1 levels are too ill-conditioned for the expansion
    and too many terms to sum directly; the twin splits them (the split's loops' twins) as the
    kernels do, within kf's tolerance of the kernels' kf."""
    x = _detrended(np.cumsum(np.cumsum(np.random.default_rng(7).standard_normal(60_000))))
    terms = theobr.twin_terms(x)
    assert terms is not None
    kernel, _ = theobr.theobr_terms(x)
    # each path redoes a sum only as far as kf, their mean, needs: the smallest levels' terms keep
    # ~1e-7 of the expansion's error in both (measured against the direct sums), kf ~1e-11
    np.testing.assert_allclose(terms, kernel, rtol=1e-6, atol=0)
    assert terms.mean() == pytest.approx(kernel.mean(), rel=theobr.KF_TOLERANCE)
    with forced("numpy"):
        kf_twin = theobr.theobr_factor(x)
    with forced("compiled"):
        kf_kernel = theobr.theobr_factor(x)
    assert kf_twin.kf == pytest.approx(kf_kernel.kf, rel=theobr.KF_TOLERANCE)


def test_triangle_products_follow_their_definitions():
    """The FFT recursions with NumPy leaves against plain loops (several leaf levels)."""
    y, f, g = RNG.standard_normal((3, 700))
    kappa = RNG.standard_normal(1400)
    count = 600
    hankel = [sum(y[i] * kappa[k + i] for i in range(k)) for k in range(count)]
    np.testing.assert_allclose(small_theobr.hankel_lower(y, kappa, count), hankel, rtol=1e-10, atol=1e-11)
    half = [sum(f[a] * g[m - a] for a in range(0, m // 2 + 1) if m - a < 700) for m in range(count)]
    np.testing.assert_allclose(small_theobr.half_convolution(f, g, count), half, rtol=1e-10, atol=1e-11)


@pytest.mark.parametrize("t", [1e-7, 0.004, 0.3, 3.0, 41.0])
def test_decayed_sums_follow_the_recurrence(t):
    """y[m + 1] = exp(-t) (y[m] + u[m]) by a plain loop, in one block and in many (t n > SPAN)."""
    u = RNG.standard_normal((2, 3000))
    loop = np.zeros_like(u)
    state = np.zeros(2)
    for m in range(u.shape[1]):
        loop[:, m] = state
        state = np.exp(-t) * (state + u[:, m])
    np.testing.assert_allclose(small_theobr.decayed_sums(u, t), loop, rtol=0, atol=1e-13 * np.abs(loop).max())


def test_running_sums_follow_their_definitions():
    """The five rows of the kernel's running sums, each from its definition by plain loops (N = 61)."""
    from avar._kernels.total.theobr import exp_sum

    x = RNG.standard_normal(61)
    reverse = x[::-1].copy()
    n = x.size
    count = 41
    autocorr = np.array([x[: n - k] @ x[k:] for k in range(n)])
    squares = np.concatenate(([0.0], np.cumsum(x * x)))
    rest = squares[n - np.arange(count)] - squares[np.arange(count)]
    lag = [np.array([z[:a] @ z[a : 2 * a] for a in range(count // 2 + 1)]) for z in (x, reverse)]
    t, w = exp_sum(count - 1)
    rows = small_theobr.running_sums(x, reverse, autocorr, rest, lag[0], lag[1], count, t, w)

    def half(f, m):  # sum_{a<=m/2} f[m - a] / a
        return sum(f[m - a] / a for a in range(1, m // 2 + 1))

    expected = np.zeros((5, count))
    for m in range(count):
        expected[0, m] = half(autocorr, m)
        expected[1, m] = half(rest, m)
        for z in (x, reverse):
            expected[2, m] += sum(z[q] * half(z, q) for q in range(m))
            expected[3, m] += sum(z[p] * z[p + l] / (m - l) for l in range((m + 1) // 2, m) for p in range(m - l))
            if m % 2 == 0:
                expected[4, m] += sum(2.0 * z[p] * z[q] / (m - q + p) for q in range(m // 2)
                                      for p in range(q % 2, q + 1, 2))
    np.testing.assert_allclose(rows, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())


def test_a_cold_first_call_at_1e5_takes_the_twins(monkeypatch):
    """N = 1e5 while the kernels are cold, as in a fresh process without numba's cache: kf and the
    displayed Allan levels come from their NumPy twins (nothing compiles), until the twin has spent
    its budget; the values are the compiled path's."""
    from avar._kernels.runtime import paths
    from avar.stability.total import small

    y = np.random.default_rng(39).standard_normal(100_000)
    with forced("compiled"):
        kernel = avar.theoh(y)
    x = _detrended(np.concatenate(([0.0], np.cumsum(y))))
    with forced("numpy"):
        kf_twin = theobr.theobr_factor(x)
    with forced("compiled"):
        kf_kernel = theobr.theobr_factor(x)
    assert kf_twin.kf == pytest.approx(kf_kernel.kf, rel=theobr.KF_TOLERANCE)
    calls = []
    monkeypatch.setattr(paths, "compiled", lambda *a, **k: False)
    monkeypatch.setattr(paths, "_WARM_ROUTES", set())
    monkeypatch.setattr(paths, "_SPENT", {})
    for name in ("twin_terms", "theobr_terms"):
        real = getattr(theobr, name)
        monkeypatch.setattr(theobr, name, lambda *a, real=real, name=name: calls.append(name) or real(*a))
    real_allan = small.oavar_sums
    monkeypatch.setattr(small, "oavar_sums", lambda *a: calls.append("allan twin") or real_allan(*a))
    with forced("auto"):
        cold = avar.theoh(y)
        assert sorted(calls) == ["allan twin", "twin_terms"]
        np.testing.assert_allclose(cold.deviation, kernel.deviation, rtol=1e-9, atol=0)
        # ski rental: each call charges what the twin loses to the warm kernels; spent, it compiles
        per_call = y.size * small_theobr.THEOBR_UNITS + paths.CALL_WORK
        taken = [theobr.twin_path(y.size) for _ in range(4)]
        left = (paths.HOT_WORK - per_call) // per_call  # the twin calls left after the one above
        assert taken == [True] * left + [False] * (4 - left)
        assert not theobr.twin_path(small_theobr.THEOBR_TWIN_LIMIT + 1)
