"""MTOTDEV, TTOTDEV, HTOTDEV, Theo1 and ThêoH against plain loops over NIST SP 1065, allantools and theory."""

from __future__ import annotations

from fractions import Fraction

import allantools
import numpy as np
import pytest

import avar
from avar._kernels.runtime.paths import forced
from avar._kernels.total.fft import autocorrelation
from avar._kernels.total.theobr import lag_diagonals, oavar_expanded, oavar_sums, theo1_every
from avar._kernels.total.windows import htot_sum, mtot_sum, theo1_sum
from avar.stability.shared.grids import total_factors
from avar.stability.total.theoh import theobr_factor
from avar.stability.uncertainty.edf import estimator_edf
from avar.stability.uncertainty.total_edf import total_edf
from tests._support.paths import STABLE32

NO_GAPS = np.zeros(0, dtype=np.int64)


def reflected_total(window: list, m: int) -> Fraction:
    """(1 / 6m) sum_j ((A_j - 2 B_j + C_j) / m)^2 of one 3m-point window, detrended by the
    means of its halves and reflected to 9m points: a plain loop over NIST SP 1065's recipe."""
    span = 3 * m
    half = span // 2
    gap = span - half
    slope = (sum(window[gap:]) - sum(window[:half])) / half / gap
    w = [window[k] - slope * k for k in range(span)]
    star = w[::-1] + w + w[::-1]
    total = Fraction(0)
    for j in range(6 * m):
        a = sum(star[j : j + m])
        b = sum(star[j + m : j + 2 * m])
        c = sum(star[j + 2 * m : j + 3 * m])
        total += ((a - 2 * b + c) / m) ** 2
    return total / (6 * m)


def plain_mtotvar(x: list, m: int) -> Fraction:
    """NIST SP 1065 eq. (27) in exact arithmetic (tau0 = 1)."""
    n = len(x) - 3 * m + 1
    return sum(reflected_total(x[i : i + 3 * m], m) for i in range(n)) / (2 * m * m * n)


def plain_htotvar(y: list, m: int) -> Fraction:
    """NIST SP 1065 eq. (29) on frequency data, exact."""
    n = len(y) - 3 * m + 1
    return sum(reflected_total(y[i : i + 3 * m], m) for i in range(n)) / (6 * n)


def plain_theo1(x: list, m: int) -> Fraction:
    """NIST SP 1065 eq. (30), exact (tau0 = 1)."""
    n, h = len(x), m // 2
    total = Fraction(0)
    for i in range(n - m):
        for d in range(h):
            total += ((x[i] - x[i - d + h]) + (x[i + m] - x[i + d + h])) ** 2 / Fraction(h - d)
    return total / (Fraction(3, 4) * (n - m) * m * m)


def exact(values) -> list:
    return [Fraction(float(v)) for v in values]


RNG = np.random.default_rng(20261125)
SMALL_X = np.cumsum(RNG.standard_normal(40))
SMALL_Y = RNG.standard_normal(40)


@pytest.mark.parametrize("m", [1, 2, 3, 5, 13])
def test_mtotdev_equals_exact_formula(m):
    res = avar.mtotdev(SMALL_X, data_type="phase", taus=[float(m)])
    assert res.n.tolist() == [40 - 3 * m + 1]
    assert res.variance[0] == pytest.approx(float(plain_mtotvar(exact(SMALL_X), m)), rel=1e-11)
    t = avar.ttotdev(SMALL_X, rate=4.0, data_type="phase", taus=[m / 4.0])
    assert t.variance[0] == pytest.approx(float(plain_mtotvar(exact(SMALL_X), m)) * 16 * (m / 4.0) ** 2 / 3, rel=1e-11)


@pytest.mark.parametrize("m", [2, 3, 6, 13])
def test_htotdev_equals_exact_formula(m):
    res = avar.htotdev(SMALL_Y, taus=[float(m)], bias_correction=False)
    assert res.n.tolist() == [40 - 3 * m + 1]
    assert res.variance[0] == pytest.approx(float(plain_htotvar(exact(SMALL_Y), m)), rel=1e-11)


def test_htotdev_is_ohdev_at_one_and_blind_to_drift():
    drifting = SMALL_Y + 0.3 * np.arange(40) + 5.0
    res = avar.htotdev(drifting, taus="all", bias_correction=False)
    assert res.deviation[0] == pytest.approx(avar.ohdev(SMALL_Y, taus=[1.0]).deviation[0], rel=1e-12)
    base = avar.htotdev(SMALL_Y, taus="all", bias_correction=False)
    np.testing.assert_allclose(res.deviation, base.deviation, rtol=1e-9)


@pytest.mark.parametrize("m", [2, 4, 10, 38])
def test_theo1_equals_exact_formula(m):
    res = avar.theo1(SMALL_X, rate=2.0, data_type="phase", taus=[0.75 * m / 2.0])
    assert res.taus.tolist() == [0.375 * m] and res.n.tolist() == [(40 - m) * m // 2]
    assert res.variance[0] == pytest.approx(float(plain_theo1(exact(SMALL_X), m)) * 4.0, rel=1e-11)


def test_kernels_match_the_plain_loops_on_larger_data():
    x = np.cumsum(RNG.standard_normal(60))
    for m in (1, 4, 19):
        total, count = mtot_sum(x, m, NO_GAPS, 0)
        assert count == 60 - 3 * m + 1
        assert total / (2 * m * m * count) == pytest.approx(float(plain_mtotvar(exact(x), m)), rel=1e-10)
    y = np.diff(x)
    total, count = htot_sum(x, 6, NO_GAPS, 0)
    assert total / (6 * count) == pytest.approx(float(plain_htotvar(exact(y), 6)), rel=1e-10)


def test_threads_give_the_serial_sums(monkeypatch):
    from avar._kernels.total import windows as total

    x = np.cumsum(RNG.standard_normal(3000))
    monkeypatch.setattr(total, "FAST_WORK", 1 << 62)  # the direct loop (tests/stability/test_total_blocks.py: the rest)
    for kind, m in ((0, 5), (1, 3), (2, 40)):  # several tasks of CHUNK terms each
        monkeypatch.setattr(total, "PARALLEL_WORK", 1 << 60)
        serial = total.level_sums(kind, x, np.array([m]), NO_GAPS, 0)
        monkeypatch.setattr(total, "PARALLEL_WORK", 0)
        threaded = total.level_sums(kind, x, np.array([m]), NO_GAPS, 0)
        assert threaded[0][0] == serial[0][0] and threaded[1][0] == serial[1][0]


def detrended(x: np.ndarray) -> np.ndarray:
    t = np.arange(x.size)
    return x - np.polyval(np.polyfit(t, x, 1), t)


@pytest.mark.parametrize("n", [121, 3001])
def test_theo1_at_every_factor_equals_the_direct_sum(n):
    """theo1_every (FFT, half convolutions, exponential sums) against the double loop at every even m,
    within eps times its conditioning ratio; OAVAR from the same lag diagonals."""
    rng = np.random.default_rng(n)
    largest = min(n - 1, 1000)
    for x in (rng.standard_normal(n), np.cumsum(rng.standard_normal(n)), np.cumsum(np.cumsum(rng.standard_normal(n)))):
        x = detrended(x)
        diagonals = lag_diagonals(x, np.ascontiguousarray(x[::-1]), largest + 1)
        sums, ratio = theo1_every(x, largest, autocorrelation(x), diagonals)
        m = np.arange(2, largest + 1, 2 if n < 1000 else 38)
        direct = np.array([theo1_sum(x, int(k), NO_GAPS, 0)[0] for k in m])
        assert np.all(np.abs(sums[m] / direct - 1) < 1e-13 * ratio[m])
        m = np.arange(1, min(largest, (n - 1) // 2) + 1)
        avar_sums, avar_ratio = oavar_expanded(x, m, autocorrelation(x), diagonals)
        assert np.all(np.abs(avar_sums / oavar_sums(x, m) - 1) < 1e-13 * avar_ratio)


@pytest.mark.parametrize("name", ["mtotdev", "ttotdev", "htotdev", "theo1"])
@pytest.mark.parametrize("data_type", ["phase", "freq"])
def test_equal_to_allantools(name, data_type):
    data = np.cumsum(RNG.standard_normal(160)) if data_type == "phase" else RNG.standard_normal(160)
    ours = getattr(avar, name)(data, rate=10.0, data_type=data_type, taus="octave", bias_correction=False)
    taus = ours.averaging_factors / 10.0
    theirs = getattr(allantools, name)(data, rate=10.0, data_type=data_type, taus=taus)
    k = len(theirs[1])  # allantools drops single-term levels
    assert k >= len(ours) - 1
    first = 1 if name == "htotdev" else 0  # allantools' HTOTDEV at m = 1 is OHDEV too, but from phase rounding
    np.testing.assert_allclose(ours.deviation[first:k], theirs[1][first:k], rtol=1e-10)
    if name == "theo1":
        np.testing.assert_allclose(theirs[0] * 0.75, ours.taus[:k])  # allantools labels Theo1 at m tau0
    assert ours.n[:k].tolist() == theirs[3].astype(int).tolist()


def test_large_offset_and_frequency_do_not_cost_accuracy():
    x = np.cumsum(RNG.standard_normal(200)) * 1e-9
    shifted = x + 1.0 + 1e-6 * np.arange(200)  # 1 s offset and a 1e-6 frequency offset, 1e9 x the noise
    for name in ("mtotdev", "htotdev", "theo1"):
        a = getattr(avar, name)(x, data_type="phase", bias_correction=False)
        b = getattr(avar, name)(shifted, data_type="phase", bias_correction=False)
        np.testing.assert_allclose(b.deviation, a.deviation, rtol=1e-5)  # the input itself is exact to ~1e-7 of the noise


def test_white_fm_theory():
    """White FM: MTOTVAR ~ MVAR = sigma^2 / (2 tau) (large m), Theo1 and HTOTVAR unbiased, ThêoH ~ AVAR."""
    y = np.random.default_rng(7).standard_normal(2**14)
    h = avar.htotdev(y, taus=[64.0])
    assert h.deviation[0] == pytest.approx(np.sqrt(1 / 64), rel=0.1)
    t = avar.theo1(y, taus=[0.75 * 256])
    assert t.deviation[0] == pytest.approx(np.sqrt(1 / 192), rel=0.1)
    th = avar.theoh(y)
    assert np.all(np.abs(th.deviation / np.sqrt(1 / th.taus) - 1)[:-1] < 0.25)  # the last level: 2 terms
    assert th.alpha[:8].tolist() == [0] * 8


def test_theobr_factor_follows_its_definition():
    x = np.cumsum(np.random.default_rng(3).standard_normal(400))
    kf, n = theobr_factor(x)
    assert n == 400 // 6 - 3  # Stable32's count
    ratios = []
    for i in range(n + 1):
        ma, mt = 9 + 3 * i, 12 + 4 * i
        avar_i = oavar_sums(x, np.array([ma]))[0] / (2 * ma * ma * (400 - 2 * ma))
        theo_i = theo1_sum(x, mt, NO_GAPS, 0)[0] / (0.75 * (400 - mt) * mt * mt)
        ratios.append(avar_i / theo_i)
    assert kf == pytest.approx(np.mean(ratios), rel=1e-10)
    res = avar.theoh(x, data_type="phase", taus=[2.0, 150.0])
    assert res.averaging_factors.tolist() == [2, 200]
    assert res.deviation[0] == pytest.approx(avar.oadev(x, data_type="phase", taus=[2.0]).deviation[0], rel=1e-12)
    raw = avar.theo1(x, data_type="phase", taus=[150.0], bias_correction=False).variance[0]
    assert res.variance[1] == pytest.approx(kf * raw, rel=1e-12)


def test_edf_and_bias_formulas():
    np.testing.assert_allclose(total_edf("mtotdev", np.array([2, 1, 0, -1, -2]), np.full(5, 10), 1001),
                               [1.9 * 100.1 - 2.1, 1.7319 * 100 - 2.9896, 1.3313 * 100 - 1.8927, 0.9204 * 100 - 0.7596,
                                0.75 * 100.1 - 0.31])  # Stable32's law at white FM, flicker PM and FM, else Table 8
    r, n = 75.0, 1001.0
    assert total_edf("theo1", np.array([0]), np.array([100]), 1001)[0] == pytest.approx(
        ((4.1 * n + 0.8) / r - (3.1 * n + 6.5) / n) * r**1.5 / (r**1.5 + 5.2))
    assert total_edf("htotdev", np.array([-1]), np.array([32]), 1001)[0] == pytest.approx((n / 32) / (0.868 + 1.14 * 32 / n))
    assert total_edf("htotdev", np.array([-1]), np.array([8]), 1001)[0] == pytest.approx(5 * 1001**2 / (32 * 1025) + 2)
    y = np.random.default_rng(5).standard_normal(500)
    raw = avar.htotdev(y, taus=[4.0], alpha=-1, bias_correction=False)
    fixed = avar.htotdev(y, taus=[4.0], alpha=-1)
    assert fixed.variance[0] == pytest.approx(raw.variance[0] / 0.851)
    t_raw = avar.theo1(y, taus=[7.5], alpha=2, bias_correction=False)
    t_fix = avar.theo1(y, taus=[7.5], alpha=2, bias_correction=True)
    assert t_fix.variance[0] == pytest.approx(t_raw.variance[0] * (0.09 + 0.74 / 7.5**0.4))
    assert t_fix.alpha.tolist() == [2] and t_fix.edf[0] == pytest.approx(
        0.86 * 502 * (501 - 10) / (501 - 7.5) * 7.5 / 8.64)  # N = 501 phase points


def test_gaps_skip_the_windows_that_touch_them():
    x = np.cumsum(RNG.standard_normal(60))
    holed = x.copy()
    holed[30] = np.nan
    res = avar.mtotdev(holed, data_type="phase", taus=[2.0], nan_policy="omit")
    windows = [i for i in range(60 - 5) if not 24 < i <= 30]
    expected = sum(reflected_total(exact(x[i : i + 6]), 2) for i in windows) / (2 * 4 * len(windows))
    assert res.n.tolist() == [len(windows)] and res.variance[0] == pytest.approx(float(expected), rel=1e-10)
    th = avar.theo1(holed, data_type="phase", taus=[3.0], nan_policy="omit")
    assert th.n.tolist() == [2 * len([i for i in range(56) if not 26 <= i <= 30])]
    with pytest.raises(ValueError, match="NaN"):
        avar.theoh(np.concatenate((x, holed)), data_type="phase", nan_policy="omit")


def test_grids_and_validation():
    assert total_factors("theo1", 100, 1.0, "octave").tolist() == [2, 4, 8, 16, 32, 64]
    assert total_factors("theo1", 100, 1.0, "decade").tolist() == [2, 4, 10, 20, 40]
    assert total_factors("mtotdev", 100, 1.0, "octave").tolist() == [1, 2, 4, 8, 16, 32]
    with pytest.raises(ValueError, match="m even"):
        avar.theo1(SMALL_Y, taus=[2.25])
    # the range in Theo1's taus: m = 2 .. 40 (even, N = 41 phase points) is tau = 1.5 .. 30 s
    with pytest.raises(ValueError, match=r"taus \[0.1, 31.0\] are outside the valid range \[1.5, 30\] s of theo1"):
        avar.theo1(SMALL_Y, taus=[0.1, 1.5, 31.0])
    assert avar.theo1(SMALL_Y, taus=[1.5, 30.0]).averaging_factors.tolist() == [2, 40]
    with pytest.raises(ValueError, match="alpha must be in -2 .. 2"):
        avar.mtotdev(SMALL_Y, alpha=3)
    with pytest.raises(TypeError, match="alpha must be None or an integer"):
        avar.htotdev(SMALL_Y, alpha=0.5)
    with pytest.raises(TypeError, match="bias_correction"):
        avar.theo1(SMALL_Y, bias_correction="yes")
    with pytest.raises(ValueError, match="at least 19 phase points"):
        avar.theoh(SMALL_Y[:10])
    with pytest.raises(ValueError, match="switch"):
        avar.theoh(np.zeros(200), switch=0.9)
    with pytest.raises(ValueError, match="data_type"):
        avar.ttotdev(SMALL_Y, data_type="time")
    res = avar.ttotdev(SMALL_Y, rate=2.0, alpha=-1)
    assert res.estimator == "ttotdev" and set(res.alpha.tolist()) == {-1}
    assert "time total deviation" in str(res) and len(res.summary()) == len(res)


# Stable32 on its PHASE.DAT (N = 1001 phase points), confidence printed 0.683 (one sigma): AF, #,
# alpha, min, sigma, max.
STABLE32_HTOTDEV = [(1, 998, 0, 2.8670e-01, 2.9439e-01, 3.0274e-01), (2, 995, 0, 1.9726e-01, 2.0297e-01, 2.0922e-01),
                    (4, 989, 0, 1.3744e-01, 1.4252e-01, 1.4821e-01), (8, 977, 0, 1.0303e-01, 1.0822e-01, 1.1430e-01),
                    (16, 953, 0, 6.1280e-02, 6.5265e-02, 7.0151e-02), (32, 905, 0, 4.0870e-02, 4.4644e-02, 4.9703e-02),
                    (64, 809, 0, 2.9694e-02, 3.3576e-02, 3.9530e-02), (128, 617, 1, 2.6309e-02, 2.8790e-02, 3.2137e-02),
                    (256, 233, 1, 1.2846e-02, 1.4773e-02, 1.7946e-02)]
# The same of the 1253-point clock record (allantoolkit's tests/assets/Sr87/phase/{octave,decade}/htotdev.txt):
# white, flicker and random-walk FM below m = 16, flicker PM at 100.
STABLE32_HTOTDEV_SR87 = [(1, 1250, -1, 8.0946e-17, 8.2651e-17, 8.4469e-17), (2, 1247, -2, 7.5923e-17, 7.8025e-17, 8.0313e-17),
                         (4, 1241, -1, 8.8264e-17, 9.1349e-17, 9.4785e-17), (8, 1229, 0, 8.5090e-17, 8.8938e-17, 9.3364e-17),
                         (10, 1223, 0, 8.1805e-17, 8.5915e-17, 9.0718e-17), (16, 1205, 0, 7.8591e-17, 8.3165e-17, 8.8649e-17),
                         (64, 1061, 0, 4.8613e-17, 5.4288e-17, 6.2567e-17), (100, 953, 1, 4.4525e-17, 4.7680e-17, 5.1617e-17),
                         (256, 485, 0, 1.8034e-17, 2.2308e-17, 3.2500e-17), (400, 53, -1, 1.1419e-17, 1.5213e-17, 3.1436e-17)]
STABLE32_COUNTS = {"mtotdev": {1: 999, 2: 996, 16: 954, 256: 234}, "htotdev": {1: 998, 2: 995, 128: 617, 256: 233},
                   "theo1": {10: 4955, 100: 45050, 998: 1497}}  # Thêo1 #, printed 4.9550e+03 ...


@pytest.mark.parametrize("n_phase, table", [(1001, STABLE32_HTOTDEV), (1253, STABLE32_HTOTDEV_SR87)])
def test_stable32_htotdev_bounds_and_term_counts(n_phase, table):
    from avar.stability.shared.term_counts import term_counts
    from avar.stability.uncertainty.edf import chi2_bounds, simple_edf

    rows = np.array(table)
    factors, alpha = rows[:, 0].astype(int), rows[:, 2].astype(int)
    edf = total_edf("htotdev", alpha, factors, n_phase)
    lci, uci = chi2_bounds(rows[:, 4], edf, quantiles="stable32")  # one sigma
    # 5 printed digits: 8.6e-5 at most (m = 400, 2.5 EDF). Below m = 16 and at PM that takes NIST SP
    # 1065 Table 5's EDF plus 2 (at flicker PM: 18.54 degrees of freedom at m = 256, where Stable32's
    # bounds imply 18.55)
    np.testing.assert_allclose(lci, rows[:, 3], rtol=1e-4)
    np.testing.assert_allclose(uci, rows[:, 5], rtol=1e-4)
    table_5 = (factors < 16) | (alpha > 0)
    bare = chi2_bounds(rows[:, 4], np.where(table_5, simple_edf(n_phase, factors, alpha), edf), quantiles="stable32")
    assert np.max(np.abs(bare[1] / rows[:, 5] - 1)[table_5]) > 9e-4  # Table 5 alone misses them
    assert term_counts("htotdev", n_phase, factors).tolist() == rows[:, 1].astype(int).tolist()
    for name, counts in STABLE32_COUNTS.items():
        assert term_counts(name, 1001, np.array(list(counts))).tolist() == list(counts.values())
    # Stable32's HTOTDEV of PHASE.DAT with and without its bias removal at m = 2 (alpha = 0):
    assert (2.0297e-01 / 2.0247e-01) ** 2 == pytest.approx(1 / 0.995, rel=5e-4)


# Stable32 1.60, PHASE.DAT, octave, alpha 0: AF, min, sigma, max of MTOTDEV and TTOTDEV (allantools'
# tests/phasedat/phase_dat_{mtotdev,ttotdev}_octave.txt). Below m = 10 its bounds follow MDEV's EDF.
STABLE32_MTOTDEV = [(1, 2.0163e-01, 2.0664e-01, 2.1204e-01), (2, 1.3898e-01, 1.4337e-01, 1.4821e-01),
                    (4, 9.0598e-02, 9.4613e-02, 9.9218e-02), (8, 6.1866e-02, 6.5721e-02, 7.0406e-02)]
STABLE32_TTOTDEV = [(1, 1.1641e-01, 1.1930e-01, 1.2242e-01), (2, 1.6048e-01, 1.6555e-01, 1.7114e-01),
                    (4, 2.0923e-01, 2.1850e-01, 2.2913e-01), (8, 2.8575e-01, 3.0355e-01, 3.2519e-01)]


@pytest.mark.parametrize("name, table", [("mtotdev", STABLE32_MTOTDEV), ("ttotdev", STABLE32_TTOTDEV)])
def test_stable32_mtotdev_bounds_at_small_factors(name, table):

    x = np.loadtxt(STABLE32 / "PHASE.DAT")
    rows = np.array(table)
    res = getattr(avar, name)(x, data_type="phase", taus=rows[:, 0], alpha=0)
    np.testing.assert_allclose(res.deviation, rows[:, 2], rtol=3e-5)  # Stable32 prints 5 digits
    # Stable32's chi-squared quantiles above 100 EDF (avar.stability.uncertainty.chi2): its 5 printed digits
    np.testing.assert_allclose(res.lci, rows[:, 1], rtol=6e-5)
    np.testing.assert_allclose(res.uci, rows[:, 3], rtol=6e-5)
    assert np.all(res.edf == estimator_edf("mdev", [0] * 4, rows[:, 0].astype(int), 1001))


# Stable32 1.60, PHASE.DAT, MTOTDEV octave and decade, m >= 10: AF, alpha, min, sigma, max.
STABLE32_MTOTDEV_LONG = [(10, 0, 5.2415e-02, 5.5529e-02, 5.9277e-02), (16, 0, 3.4536e-02, 3.7135e-02, 4.0425e-02),
                         (32, 0, 2.6331e-02, 2.9114e-02, 3.3017e-02), (64, 0, 2.0550e-02, 2.3606e-02, 2.8612e-02),
                         (100, 1, 1.6730e-02, 1.9547e-02, 2.4523e-02), (128, 1, 1.3978e-02, 1.6668e-02, 2.1915e-02),
                         (256, 1, 4.6190e-03, 5.9607e-03, 1.0238e-02)]


# Stable32 1.60 of a clock's phase record of N = 1253 points (BIPM Sr87, tau0 = 2.5 s; allantoolkit's
# tests/assets/Sr87/{phase,freq}/decade/mtotdev.txt), m >= 10: AF, alpha, min, sigma, max.
STABLE32_MTOTDEV_SR87 = [(10, 0, 6.3861e-17, 6.7260e-17, 7.1270e-17), (20, 0, 5.3546e-17, 5.7573e-17, 6.2669e-17),
                         (40, 0, 3.9907e-17, 4.4121e-17, 5.0032e-17), (100, 1, 2.5070e-17, 2.8818e-17, 3.4977e-17),
                         (200, -1, 1.1921e-17, 1.5037e-17, 2.3447e-17), (400, -1, 1.2033e-17, 1.6256e-17, 3.7550e-17)]
STABLE32_MTOTDEV_SR87_FREQ_DECADE = [(200, -1, 1.1920e-17, 1.5037e-17, 2.3453e-17),
                                     (400, -1, 1.2032e-17, 1.6256e-17, 3.7578e-17)]


# The same record's octave tables as 1253 phase and as 1252 frequency points (m = 64 .. 256): their
# bounds differ, as Stable32's law takes the number of points given for its N.
STABLE32_MTOTDEV_SR87_PHASE = [(64, 0, 3.2783e-17, 3.7146e-17, 4.3893e-17), (128, 0, 1.8760e-17, 2.2288e-17, 2.9039e-17),
                               (256, 0, 1.0818e-17, 1.3733e-17, 2.1958e-17)]
STABLE32_MTOTDEV_SR87_FREQ = [(64, 0, 3.2782e-17, 3.7146e-17, 4.3897e-17), (128, 0, 1.8759e-17, 2.2288e-17, 2.9043e-17),
                              (256, 0, 1.0817e-17, 1.3733e-17, 2.1966e-17)]


@pytest.mark.parametrize("n_phase, n_given, table", [(1001, 1001, STABLE32_MTOTDEV_LONG), (1253, 1253, STABLE32_MTOTDEV_SR87),
                                                     (1253, 1253, STABLE32_MTOTDEV_SR87_PHASE),
                                                     (1253, 1252, STABLE32_MTOTDEV_SR87_FREQ),
                                                     (1253, 1252, STABLE32_MTOTDEV_SR87_FREQ_DECADE)])
def test_mtotdev_bounds_from_m_10_are_stable32s(n_phase, n_given, table):
    # From m = 10 Stable32's bounds follow b (N - 1) / m - c degrees of freedom, (b, c) = (1.3313,
    # 1.8927) at white FM, (1.7319, 2.9896) at flicker PM, (0.9204, 0.7596) at flicker FM, on records
    # of two lengths; NIST SP 1065's Table 8 gives 10 to 45 % fewer at the first two, and simulated
    # records fewer still (benchmarks/total_edf_simulation.py).
    from avar.stability.uncertainty.edf import chi2_bounds

    rows = np.array(table)
    factors, alpha = rows[:, 0].astype(int), rows[:, 1].astype(int)
    edf = total_edf("mtotdev", alpha, factors, n_phase, n_given=n_given)
    lci, uci = chi2_bounds(rows[:, 3], edf, quantiles="stable32")  # one sigma
    np.testing.assert_allclose(lci, rows[:, 2], rtol=8e-5)  # 5 printed digits
    np.testing.assert_allclose(uci, rows[:, 4], rtol=8e-5)
    if n_given != n_phase:  # with the phase count the frequency tables' last bound misses by 3.7e-4 and more
        wrong = chi2_bounds(rows[:, 3], total_edf("mtotdev", alpha, factors, n_phase), quantiles="stable32")
        assert abs(wrong[1][-1] / rows[-1, 4] - 1) > 3e-4
    table_8 = {0: (1.10, 1.20), 1: (1.20, 1.40), -1: (0.85, 0.50)}
    b, c = np.array([table_8[a] for a in alpha]).T
    nist = chi2_bounds(rows[:, 3], b * n_phase / factors - c, quantiles="stable32")
    assert not np.allclose(nist[1], rows[:, 4], rtol=1e-3, atol=0)  # Table 8 misses them
    assert np.all((nist[0] < lci) & (nist[1] > uci) | (alpha == -1))  # wider at white FM and flicker PM


def test_theo1_with_a_fixed_noise_is_scaled_by_theobr_as_stable32():
    """Stable32's Theo1 of PHASE.DAT with alpha fixed to 1 is the raw statistic times TheoBR's kf
    (n = floor(N / 6) - 3: 0.6028 here); with alpha = 0 it is the raw one."""
    x = np.loadtxt(STABLE32 / "PHASE.DAT")
    factors = np.array([10, 12, 20, 100, 400, 998])
    fixed_flicker_pm = [8.3520e-02, 7.6196e-02, 5.6492e-02, 2.4681e-02, 1.1118e-02, 3.9001e-03]
    white_fm = [1.0757e-01, 9.8141e-02, 7.2762e-02, 3.1789e-02, 1.4321e-02, 5.0234e-03]
    res = avar.theo1(x, data_type="phase", taus=0.75 * factors, alpha=1)
    np.testing.assert_allclose(res.deviation, fixed_flicker_pm, rtol=4e-5)  # Stable32 prints 5 digits
    np.testing.assert_allclose(avar.theo1(x, data_type="phase", taus=0.75 * factors, alpha=0).deviation, white_fm,
                               rtol=4e-5)
    plain = avar.theo1(x, data_type="phase", taus=0.75 * factors, alpha=1, bias_correction=False)
    kf, n = theobr_factor(x - np.polyval(np.polyfit(np.arange(x.size), x, 1), np.arange(x.size)))
    assert n == 163 and kf == pytest.approx(0.602787, abs=2e-6)
    np.testing.assert_allclose(res.variance, plain.variance * kf, rtol=1e-9)
    assert avar.theo1(x, data_type="phase", taus=[7.5], alpha=1, bias_correction="theobr").deviation[0] == \
        pytest.approx(res.deviation[0], rel=1e-12)
    with pytest.raises(ValueError, match="gap-free"):
        avar.theo1(np.where(np.arange(x.size) == 5, np.nan, x), data_type="phase", taus=[7.5], alpha=1,
                   nan_policy="omit")


def test_triangle_products_equal_their_loops():
    from avar._kernels.total.fft import half_convolution, hankel_lower, phi_sums

    rng = np.random.default_rng(12)
    y, kappa, f, g = (rng.standard_normal(1400) for _ in range(4))
    count = 700  # a few depths above the leaves
    lower = [sum(y[i] * kappa[k + i] for i in range(k)) for k in range(count)]
    np.testing.assert_allclose(hankel_lower(y, kappa, count), lower, atol=1e-11)
    half = [sum(f[a] * g[k - a] for a in range(k // 2 + 1)) for k in range(count)]
    np.testing.assert_allclose(half_convolution(f, g, count), half, atol=1e-11)
    phi = [sum(2.0 * y[j] / (c + j) for j in range(c % 2, c, 2)) for c in range(count)]
    np.testing.assert_allclose(phi_sums(y, count), phi, atol=1e-12)


def test_theo1_by_fft_equals_the_direct_sum(monkeypatch):
    from avar._kernels.total import theo1 as theo_levels

    rng = np.random.default_rng(11)
    for x in (rng.standard_normal(3001), np.cumsum(rng.standard_normal(3001)),
              np.cumsum(np.cumsum(rng.standard_normal(3001)))):
        x = detrended(x)
        prepared = theo_levels.prepare(x, 1500)
        for m in (2, 300, 1026, 2000, 3000):
            total, ratio = theo_levels.theo1_expanded(prepared, m)
            direct = theo1_sum(x, m, NO_GAPS, 0)[0]
            assert total == pytest.approx(direct, rel=max(1e-13, 1e-14 * ratio)), (m, ratio)
    monkeypatch.setattr(theo_levels, "DIRECT_TERMS", 0)  # every level by FFT, or direct where ill-conditioned
    factors = np.array([2, 4, 64, 512, 2048])
    sums, expanded = theo_levels.theo1_sums(x, factors, lambda v, m: theo1_sum(v, m, NO_GAPS, 0)[0])
    assert expanded == factors.size  # the ill-conditioned small levels by the split (test_theo_blocks.py)
    np.testing.assert_allclose(sums, [theo1_sum(x, m, NO_GAPS, 0)[0] for m in factors], rtol=1e-10)
    for phase in (rng.standard_normal(2000), np.cumsum(rng.standard_normal(2000))):  # white PM, white FM
        phase = phase * 1e-9 + 1e3 + 1e-3 * np.arange(2000)  # offset and drift 1e6 and 1e12 x the noise
        monkeypatch.setattr(theo_levels, "DIRECT_TERMS", 1 << 40)
        slow = avar.theo1(phase, data_type="phase", taus="all")
        monkeypatch.setattr(theo_levels, "DIRECT_TERMS", 0)
        np.testing.assert_allclose(avar.theo1(phase, data_type="phase", taus="all").deviation, slow.deviation,
                                   rtol=1e-10)


def test_theobr_factor_of_random_walk_fm_redoes_only_the_levels_kf_needs(monkeypatch):
    """Random-walk FM: most expansions of kf's Theo1 sums are ill-conditioned at the per-level
    tolerance, but kf is their mean: summing directly only the worst (the smallest m) keeps
    kf within its tolerance of the all-direct mean, with far fewer direct sums."""
    import avar.stability.total.theobr as theo

    y = np.cumsum(np.random.default_rng(11).standard_normal(6000))
    x = np.concatenate([[0.0], np.cumsum(y)])
    x -= np.polyval(np.polyfit(np.arange(x.size), x, 1), np.arange(x.size))  # as prepared_phase
    calls = []

    def counted(x, m, bad, shift):
        calls.append(m)
        return theo1_sum(x, m, bad, shift)

    monkeypatch.setattr(theo, "theo1_sum", counted)
    with forced("compiled"):  # (the kernels' path: the NumPy twin sums directly with NumPy's own loops)
        kf_default, n = theo.theobr_factor(x)
        monkeypatch.setattr(theo, "KF_TOLERANCE", 1e-12)  # at N = 6000 the default needs no direct sum
        calls.clear()
        kf, n = theo.theobr_factor(x)
    with forced("numpy"):
        kf_twin, _ = theo.theobr_factor(x)
    direct = np.mean([oavar_sums(x, np.array([9 + 3 * i]))[0] / (2 * (9 + 3 * i) ** 2 * (x.size - 2 * (9 + 3 * i)))
                      / (theo1_sum(x, 12 + 4 * i, NO_GAPS, 0)[0] / (0.75 * (x.size - 12 - 4 * i) * (12 + 4 * i) ** 2))
                      for i in range(n + 1)])
    assert kf_default == pytest.approx(direct, rel=1e-8)
    assert kf == pytest.approx(direct, rel=1e-11)
    assert kf_twin == pytest.approx(direct, rel=1e-11)
    assert 0 < len(calls) < n + 1 and 12 + 4 * n not in calls  # the worst conditioned: small factors


def test_theo1_every_on_threads_gives_the_serial_bits(monkeypatch):
    import avar._kernels.total.theobr as kernels

    x = np.cumsum(np.random.default_rng(21).standard_normal(3000))
    x -= x.mean()
    autocorr = autocorrelation(x)
    diagonals = lag_diagonals(x, np.ascontiguousarray(x[::-1]), 1001)
    threaded = theo1_every(x, 2000, autocorr, diagonals)
    monkeypatch.setattr(kernels, "run_concurrently", lambda *calls: [call() for call in calls])
    serial = theo1_every(x, 2000, autocorr, lag_diagonals(x, np.ascontiguousarray(x[::-1]), 1001))
    assert all(np.array_equal(a, b) for a, b in zip(threaded, serial))
    assert all(np.array_equal(a, b) for a, b in zip(diagonals, lag_diagonals(x, np.ascontiguousarray(x[::-1]), 1001)))


def test_theoh_levels_are_stable32s_table():
    """Stable32's ThêoH of a 1253-point record (octave): OADEV at m = 1 .. 256 (<= N / 4), Theo1 at
    m = 256, 512, 1024 (>= floor(N / 5)), both at m = 256; decade: OADEV to 200, Theo1 at 400, 1000."""
    x = np.cumsum(np.random.default_rng(4).standard_normal(1253))
    octave = avar.theoh(x, data_type="phase")
    assert octave.averaging_factors.tolist() == [1, 2, 4, 8, 16, 32, 64, 128, 256, 256, 512, 1024]
    assert octave.taus.tolist()[8:] == [256.0, 192.0, 384.0, 768.0]  # Allan tau m tau0, Theo1's 0.75 m tau0
    oadev = avar.oadev(x, data_type="phase", taus=octave.taus[:9])
    np.testing.assert_allclose(octave.deviation[:9], oadev.deviation, rtol=1e-12)
    theo1 = avar.theo1(x, data_type="phase", taus=octave.taus[9:], bias_correction="theobr")
    np.testing.assert_allclose(octave.deviation[9:], theo1.deviation, rtol=1e-9)
    decade = avar.theoh(x, data_type="phase", taus="decade")
    assert decade.averaging_factors.tolist() == [1, 2, 4, 10, 20, 40, 100, 200, 400, 1000]
    explicit = avar.theoh(x, data_type="phase", taus=[300.0, 301.5, 750.0])  # m = 300 <= 313: OADEV
    assert explicit.averaging_factors.tolist() == [300, 402, 1000]
    howe = avar.theoh(x, data_type="phase", switch=0.1)
    assert howe.taus.max() == octave.taus.max() and 128 not in howe.averaging_factors[:8].tolist()
