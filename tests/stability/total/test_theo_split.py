"""The broken-line split of Theo1's and OAVAR's sums (avar._kernels.total.split) against plain loops and direct sums."""

from __future__ import annotations

import numpy as np
import pytest

from avar._kernels.total import split_numpy
from avar._kernels.total import theo1 as theo_levels
from avar._kernels.total.fft import autocorrelation, short_autocorrelation
from avar._kernels.total.split import crossing_terms, groups, knot_profile, split_record
from avar._kernels.total.theobr import oavar_sums
from avar._kernels.total.windows import theo1_sum
from avar.stability.total import theobr as theo

NO_GAPS = np.zeros(0, dtype=np.int64)


def detrended(x: np.ndarray) -> np.ndarray:
    t = np.arange(x.size)
    return x - np.polyval(np.polyfit(t, x, 1), t)


def noises(n: int, seed: int = 5) -> dict[str, np.ndarray]:
    """Detrended phase: white PM, flicker FM (1/f frequency by FFT), random-walk FM, and white PM
    on an offset and drift 1e12 and 1e15 x the noise."""
    rng = np.random.default_rng(seed)
    w = rng.standard_normal(n)
    f = np.fft.rfftfreq(n)
    f[0] = f[1]
    flicker = np.fft.irfft(np.fft.rfft(rng.standard_normal(n)) / np.sqrt(f), n)
    raw = {"white PM": w, "flicker FM": np.cumsum(flicker), "random-walk FM": np.cumsum(np.cumsum(w)),
           "offset and drift": w * 1e-9 + 1e3 + 1e-3 * np.arange(n)}
    return {name: detrended(x) for name, x in raw.items()}


def plain_theo1(x: np.ndarray, m: int) -> float:
    """sum_{a=1}^{m/2} (1/a) sum_{i<N-m} (x_i - x_{i+a} - x_{i+m-a} + x_{i+m})^2 (NumPy)."""
    n = x.size - m
    return sum(np.sum((x[:n] - x[a : a + n] - x[m - a : m - a + n] + x[m : m + n]) ** 2) / a
               for a in range(1, m // 2 + 1))


def plain_split(x: np.ndarray, spacing: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """r = x less its chords between the knots 0, K, ..., N - 1 (the last inner knot >= K from
    the end), the inner knots and the slope changes there."""
    n = x.size
    knots = list(range(0, n - spacing, spacing)) + [n - 1]
    slopes = np.diff(x[knots]) / np.diff(knots)
    g = np.interp(np.arange(n), knots, x[knots])
    return x - g, np.array(knots[1:-1]), np.diff(slopes)


def plain_crossing(r: np.ndarray, knots: np.ndarray, kinks: np.ndarray, m: int, allan: bool) -> tuple[float, float]:
    """X = sum_a w_a sum_i d_a^r(i) d_a^g(i) and G = sum_a w_a sum_i d_a^g(i)^2 by their definition, the
    kinks' d^g(i) = sum_k beta_k min(t_k - i, a, m - t_k + i)_+ summed over every i of a knot's span."""
    cross = square = 0.0
    for a in range(m // 2 if allan else 1, m // 2 + 1):
        w = 1.0 if allan else 1.0 / a
        for t, beta in zip(knots.tolist(), kinks.tolist()):
            i = t - np.arange(1, m)
            kink = beta * np.minimum(np.minimum(t - i, a), m - t + i)
            rest = r[i] - r[i + a] - r[i + m - a] + r[i + m]
            cross += w * np.sum(rest * kink)
            square += w * np.sum(kink * kink)
    return cross, square


def test_split_record_equals_its_twin():
    x = np.cumsum(np.random.default_rng(1).standard_normal(1003))
    for spacing in (1, 7, 100, 333, 501, 1002):
        r, knots, kinks = split_record(x, spacing)
        r_plain, knots_plain, kinks_plain = plain_split(x, spacing)
        np.testing.assert_allclose(r, r_plain, rtol=0, atol=1e-12 * np.abs(x).max())
        np.testing.assert_array_equal(knots, knots_plain)
        np.testing.assert_allclose(kinks, kinks_plain, rtol=1e-12, atol=1e-14)
        assert r[0] == 0.0 and r[-1] == 0.0 and np.all(r[knots] == 0.0)
        assert knots.size == 0 or (knots[0] == spacing and x.size - 1 - knots[-1] >= spacing)


@pytest.mark.parametrize("allan", [False, True])
def test_crossing_terms_equal_their_definition(allan):
    x = noises(901)["random-walk FM"]
    spacing = 60
    r, knots, kinks = split_record(x, spacing)
    profile = knot_profile(r, knots, kinks, spacing)
    np.testing.assert_allclose(profile, [kinks @ r[knots + v] for v in range(1 - spacing, spacing)], rtol=1e-13)
    factors = np.array([2, 4, 10, 30, 58, 60])
    cross, square, magnitude = crossing_terms(profile, spacing, float(kinks @ kinks), factors, allan)
    plain = np.array([plain_crossing(r, knots, kinks, int(m), allan) for m in factors])
    np.testing.assert_allclose(cross, plain[:, 0], rtol=1e-12)
    np.testing.assert_allclose(square, plain[:, 1], rtol=1e-13)
    assert np.all(magnitude >= np.abs(cross))


@pytest.mark.parametrize("name", ["white PM", "flicker FM", "random-walk FM", "offset and drift"])
def test_split_kernels_twins_are_the_kernels_bit_for_bit(name):
    """The NumPy twins a cold process takes (:mod:`avar._kernels.total.split_numpy`) give the
    kernels' bits: the rest and kinks, the knot profile, and X, G and the size of X's terms of
    Theo1 and of the overlapping Allan sums."""
    x = noises(2001)[name]
    for spacing in (2, 7, 64, 500, 1000):
        r, knots, kinks = split_record(x, spacing)
        twin = split_numpy.split_record(x, spacing)
        assert np.array_equal(twin.rest, r) and np.array_equal(twin.knots, knots) and np.array_equal(twin.kinks, kinks)
        profile = knot_profile(r, knots, kinks, spacing)
        assert np.array_equal(split_numpy.knot_profile(r, knots, kinks, spacing), profile)
        factors = np.unique([m for m in (2, 4, 6, spacing // 3 * 2, spacing - spacing % 2) if 2 <= m <= spacing])
        for allan in (False, True):
            want = crossing_terms(profile, spacing, float(kinks @ kinks), factors, allan)
            got = split_numpy.crossing_terms(profile, spacing, float(kinks @ kinks), factors, allan)
            for kernel, numpy_twin in zip(want, got):
                assert np.array_equal(numpy_twin, kernel), (spacing, allan)


def test_a_cold_theo1_of_random_walk_fm_sums_as_the_warm_one():
    """Random-walk FM: the long levels' expansion is ill-conditioned, so they take the split; cold,
    every split kernel's twin answers, to the warm path's bits, and both equal the direct sums."""
    from avar._kernels.runtime.paths import forced
    from avar.stability.total import small

    n = 20_000
    x = noises(n)["random-walk FM"]
    factors = np.array([2, 512, 640, 800, 4096])
    long = (n - factors) * (factors // 2) > theo_levels.DIRECT_TERMS
    prepared = theo_levels.prepare(x, int(factors.max()) // 2)
    whole = np.array([theo_levels.theo1_expanded(prepared, int(m)).ratio if far else 0.0
                      for m, far in zip(factors.tolist(), long)])
    retry = whole > theo_levels.MAX_RATIO  # the levels theo1_sums gives to the split
    split = theo_levels.split_sums(x, factors[retry], theo_levels.SPLIT_REACH)
    by_split = retry.copy()
    by_split[retry] = split.theo1_ratios <= theo_levels.MAX_RATIO
    assert by_split.sum() >= 2  # (the split does take some of these levels)
    with forced("numpy"):
        cold = theo_levels.theo1_sums(x, factors, small.theo1_direct(NO_GAPS, 0))
    with forced("compiled"):
        warm = theo_levels.theo1_sums(x, factors, small.theo1_direct(NO_GAPS, 0))
    assert np.array_equal(cold.sums[by_split], warm.sums[by_split])
    np.testing.assert_allclose(cold.sums, [theo1_sum(x, int(m), NO_GAPS, 0).total for m in factors], rtol=1e-9)


def test_the_split_is_exact():
    """S(x) = S(r) + 2 X + G with every part summed directly."""
    x = noises(700)["flicker FM"]
    for spacing, m in ((50, 50), (64, 16), (300, 140)):
        r, knots, kinks = split_record(x, spacing)
        cross, square = plain_crossing(r, knots, kinks, m, False)
        assert plain_theo1(r, m) + 2.0 * cross + square == pytest.approx(plain_theo1(x, m), rel=1e-12)
        assert theo1_sum(x, m, NO_GAPS, 0)[0] == pytest.approx(plain_theo1(x, m), rel=1e-12)


def test_short_autocorrelation_equals_the_full_one():
    x = np.random.default_rng(2).standard_normal(40_001) + 3.0
    full = autocorrelation(x)
    for count in (1, 2, 17, 1000, 6000, 40_001):
        np.testing.assert_allclose(short_autocorrelation(x, count), full[:count], rtol=0, atol=1e-12 * full[0])


def test_groups_cover_each_factor_once_within_reach():
    factors = np.array([2, 4, 8, 16, 64, 100, 200, 1000, 3000, 12])
    seen = []
    for spacing, members in groups(factors, 8):
        assert factors[members].max() == spacing and np.all(factors[members] * 8 > spacing)
        seen.extend(members.tolist())
    assert sorted(seen) == list(range(factors.size))


@pytest.mark.parametrize("name", ["white PM", "flicker FM", "random-walk FM", "offset and drift"])
def test_split_sums_equal_the_direct_sums(name):
    """Theo1 (per level, and at 64 levels or more by theo1_every) and OAVAR through the split: as
    exact as the ratio says, and well conditioned on every noise."""
    x = noises(20_000)[name]
    factors = np.array([2, 6, 40, 96, 500, 1000, 3000])
    allan = np.array([9, 30, 101, 500, 1500])
    sums, ratio, allan_sums, allan_ratio = theo_levels.split_sums(x, factors, 8, allan)
    direct = np.array([theo1_sum(x, int(m), NO_GAPS, 0)[0] for m in factors])
    allan_direct = oavar_sums(x, allan)
    assert np.all(ratio < 1e4) and np.all(allan_ratio < 1e4)  # MAX_RATIO
    np.testing.assert_allclose(sums, direct, rtol=1e-14 * ratio.max() + 1e-13)
    np.testing.assert_allclose(allan_sums, allan_direct, rtol=1e-14 * allan_ratio.max() + 1e-13)
    assert np.all(np.abs(sums / direct - 1.0) < 1e-14 * ratio + 1e-13)
    many = np.arange(2, 260, 2)  # >= EVERY_LEVELS in one group: theo1_every on r
    every, every_ratio = theo_levels.split_sums(x, many, 200)[:2]
    sample = [0, 5, 60, 99, 128]
    np.testing.assert_allclose(every[sample], [theo1_sum(x, int(m), NO_GAPS, 0)[0] for m in many[sample]],
                               rtol=1e-14 * every_ratio.max() + 1e-13)


def test_theo1_sums_split_ill_conditioned_levels_and_sum_the_rest_directly(monkeypatch):
    x = noises(12_000)["random-walk FM"]
    factors = np.array([2, 64, 256, 1024, 4000])
    direct = [theo1_sum(x, int(m), NO_GAPS, 0)[0] for m in factors]
    calls = []

    def counted(v, m):
        calls.append(m)
        return theo1_sum(v, m, NO_GAPS, 0)[0]

    monkeypatch.setattr(theo_levels, "DIRECT_TERMS", 0)
    sums, expanded = theo_levels.theo1_sums(x, factors, counted)
    assert expanded == factors.size and not calls  # whole-record ratios up to 1e9 here: split
    np.testing.assert_allclose(sums, direct, rtol=1e-11)
    monkeypatch.setattr(theo_levels, "MAX_RATIO", 3.0)  # the split not good enough either: directly
    sums, expanded = theo_levels.theo1_sums(x, factors, counted)
    assert expanded < factors.size and calls
    np.testing.assert_allclose(sums, direct, rtol=1e-11)


def test_theobr_terms_of_random_walk_fm_equal_the_direct_ones(monkeypatch):
    """kf's OAVAR and Theo1 sums: the ill-conditioned ones by the split (kf within 1e-11 of the
    all-direct mean at a tolerance of 1e-12), and no direct sum at the default tolerance."""
    x = noises(4000, seed=11)["random-walk FM"]
    calls = []
    monkeypatch.setattr(theo, "theo1_sum", lambda *args: calls.append(args[1]) or theo1_sum(*args))
    monkeypatch.setattr(theo, "oavar_sums", lambda v, m: calls.extend(m.tolist()) or oavar_sums(v, m))
    terms, n = theo.theobr_terms(x)
    assert not calls
    i = np.arange(n + 1)
    m_avar, m_theo = 9 + 3 * i, 12 + 4 * i
    avar = oavar_sums(x, m_avar) / (2.0 * m_avar**2 * (x.size - 2 * m_avar))
    theo1 = np.array([theo1_sum(x, int(m), NO_GAPS, 0)[0] for m in m_theo]) / (0.75 * (x.size - m_theo) * m_theo**2)
    assert np.mean(terms) == pytest.approx(np.mean(avar / theo1), rel=1e-8)
    monkeypatch.setattr(theo, "KF_TOLERANCE", 1e-12)
    terms, n = theo.theobr_terms(x)
    assert np.mean(terms) == pytest.approx(np.mean(avar / theo1), rel=1e-11)
    np.testing.assert_allclose(terms[:20], (avar / theo1)[:20], rtol=1e-10)  # the smallest m: split or direct


def test_theo1s_own_kernels_on_the_threads_and_serially(monkeypatch):
    """Theo1's direct loop (its own kernels, not MTOTDEV's): serially and in tasks on the threads
    the same bits, the plain loop to 1e-12, and the terms touching a gap skipped."""
    from avar._kernels.total import windows

    x = noises(1500)["random-walk FM"]
    missing = np.zeros(x.size, dtype=bool)
    missing[[40, 41, 900]] = True
    bad = np.concatenate(([0], np.cumsum(missing))).astype(np.int64)
    for m in (2, 10, 64):
        serial = theo1_sum(x, m, NO_GAPS, 0)
        gapped = theo1_sum(x, m, bad, 0)
        monkeypatch.setattr(windows, "PARALLEL_WORK", 0)
        assert theo1_sum(x, m, NO_GAPS, 0) == serial and theo1_sum(x, m, bad, 0) == gapped
        monkeypatch.undo()
        assert serial.total == pytest.approx(plain_theo1(x, m), rel=1e-12)
        assert serial.n_terms == x.size - m
        assert gapped.n_terms == sum(not missing[i : i + m + 1].any() for i in range(x.size - m))
