"""MTIE, TIE rms and PDEV: plain loops over the formulas, allantools on the same data, gaps, alpha=."""

from __future__ import annotations

import math

import allantools
import numpy as np
import pytest

import avar
from tests._support.deviation_reference import nbs14_1000
from tests._support.paths import STABLE32


def _phase(data, data_type, rate):
    data = np.asarray(data, dtype=np.float64)
    if data_type == "phase":
        return data
    return np.concatenate(([0.0], np.cumsum(data - data.mean()))) / rate


def _mtie_loop(x, m):
    return max(max(x[i : i + m + 1]) - min(x[i : i + m + 1]) for i in range(len(x) - m))


def _tierms_loop(x, m):
    return math.sqrt(math.fsum((x[i + m] - x[i]) ** 2 for i in range(len(x) - m)) / (len(x) - m))


def _pdev_loop(x, m, tau0):
    n = len(x) - 2 * m
    if m == 1:
        return math.sqrt(math.fsum((x[i + 2] - 2 * x[i + 1] + x[i]) ** 2 for i in range(n)) / (2 * n)) / tau0
    total = math.fsum(
        math.fsum(((m - 1) / 2 - k) * (x[i + k] - x[i + k + m]) for k in range(m)) ** 2 for i in range(n)
    )
    return math.sqrt(72 * total / (n * m**4 * (m * tau0) ** 2))


SERIES = {
    "white": lambda rng, n: rng.standard_normal(n),
    "walk": lambda rng, n: np.cumsum(rng.standard_normal(n)),
    "offset": lambda rng, n: 1e-3 + 1e-9 * rng.standard_normal(n),
}


@pytest.mark.parametrize("kind", sorted(SERIES))
@pytest.mark.parametrize("data_type", ["phase", "freq"])
def test_plain_loops(kind, data_type):
    rng = np.random.default_rng(len(kind))
    data = SERIES[kind](rng, 157)
    x = _phase(data, data_type, 4.0)
    for name, loop in [("mtie", _mtie_loop), ("tierms", _tierms_loop),
                       ("pdev", lambda x, m: _pdev_loop(x, m, 0.25))]:
        res = getattr(avar, name)(data, rate=4.0, data_type=data_type, taus="all")
        expected = [loop(list(x), int(m)) for m in res.averaging_factors]
        if name == "tierms" and data_type == "freq":  # m = N: one term over the mean-removed data, 0 by construction
            assert res.averaging_factors[-1] == len(x) - 1 and abs(expected[-1]) < 1e-6 * max(expected)  # the twin's rounding residue
            expected[-1] = 0.0
        np.testing.assert_allclose(res.deviation, expected, rtol=1e-9, atol=0, err_msg=name)
        n_phase = len(x)
        counts = n_phase - (2 if name == "pdev" else 1) * res.averaging_factors
        assert res.n.tolist() == counts.tolist()
        assert res.averaging_factors[-1] == ((n_phase - 1) // 2 if name == "pdev" else n_phase - 1)


@pytest.mark.parametrize("name", ["mtie", "tierms", "pdev"])
@pytest.mark.parametrize("data_type", ["phase", "freq"])
def test_equals_allantools(name, data_type):
    rng = np.random.default_rng(7)
    data = np.cumsum(rng.standard_normal(400)) + rng.standard_normal(400)
    ours = getattr(avar, name)(data, rate=2.0, data_type=data_type, taus="octave")
    taus, devs, _, ns = getattr(allantools, name)(data, rate=2.0, data_type=data_type, taus=ours.taus)
    at = np.searchsorted(ours.taus, taus)
    assert len(taus) >= len(ours.taus) - 1  # allantools drops a level with a single term
    np.testing.assert_allclose(ours.deviation[at], devs, rtol=1e-10)
    assert ours.n[at].tolist() == ns.astype(int).tolist()


def test_mtie_of_a_ramp_and_a_step():
    ramp = np.arange(100.0) * 1e-9
    res = avar.mtie(ramp, data_type="phase", taus=[1, 10, 50])
    np.testing.assert_allclose(res.deviation, [1e-9, 1e-8, 5e-8], rtol=1e-12)
    step = np.r_[np.zeros(50), np.ones(50)]
    res = avar.mtie(step, data_type="phase", taus="octave")
    assert res.deviation.tolist() == [1.0] * len(res)
    assert np.isnan(res.edf).all() and np.isnan(res.lci).all() and np.isnan(res.uci).all()


def test_pdev_cancels_a_phase_line_and_matches_white_pm_theory():
    rng = np.random.default_rng(3)
    x = rng.standard_normal(20000)
    line = 5.0 + 0.3 * np.arange(x.size)
    a = avar.pdev(x, data_type="phase", taus=[8, 32])
    b = avar.pdev(x + line, data_type="phase", taus=[8, 32])
    np.testing.assert_allclose(a.deviation, b.deviation, rtol=1e-9)
    # white PM (sigma_x = 1, tau0 = 1): PVAR = 72 sigma**2 / (m**4 tau**2) * 2 sum_k c_k**2,
    # sum_k c_k**2 = (m - 1) m (m + 1) / 12: PVAR = 12 (m**2 - 1) / (m**5 tau**2) ... with tau = m
    m = np.array([8.0, 32.0])
    theory = np.sqrt(72 * 2 * (m - 1) * m * (m + 1) / 12 / (m**4 * m**2))
    assert np.all(a.lci < theory * 1.02) and np.all(theory * 0.98 < a.uci)
    np.testing.assert_allclose(a.deviation, theory, rtol=0.05)


def test_gaps_are_skipped_as_a_plain_loop_does():
    rng = np.random.default_rng(11)
    x = np.cumsum(rng.standard_normal(120))
    x[[17, 60, 61]] = np.nan
    for name in ("mtie", "tierms", "pdev"):
        res = getattr(avar, name)(x, data_type="phase", taus=[1, 2, 5, 9], nan_policy="omit")
        for m, dev, n in zip(res.averaging_factors, res.deviation, res.n):
            m = int(m)
            if name == "mtie":
                vals = [np.ptp(x[i : i + m + 1]) for i in range(x.size - m)]
            elif name == "tierms":
                vals = [(x[i + m] - x[i]) ** 2 for i in range(x.size - m)]
            else:
                vals = [_pdev_loop(list(x[i : i + 2 * m + 1]), m, 1.0) ** 2 for i in range(x.size - 2 * m)]
            vals = [v for v in vals if np.isfinite(v)]
            expected = max(vals) if name == "mtie" else math.sqrt(np.mean(vals))
            assert n == len(vals)
            assert dev == pytest.approx(expected, rel=1e-9)
        with pytest.raises(ValueError, match="NaN"):
            getattr(avar, name)(x, data_type="phase")


def test_alpha_fixes_the_noise_and_sets_the_bounds():
    rng = np.random.default_rng(5)
    y = rng.standard_normal(2000)
    free = avar.pdev(y)
    assert free.alpha[:6].tolist() == [0] * 6  # white FM, identified where many terms remain
    fixed = avar.pdev(y, alpha=-2)
    assert fixed.alpha.tolist() == [-2] * len(fixed)
    np.testing.assert_array_equal(fixed.deviation, free.deviation)
    assert not np.allclose(fixed.edf, free.edf)
    assert np.all(fixed.lci < fixed.deviation) and np.all(fixed.deviation < fixed.uci)
    with pytest.raises(ValueError, match="alpha must be in -2 .. 2"):
        avar.mtie(y, alpha=3)
    with pytest.raises(TypeError, match="alpha must be None or an integer"):
        avar.tierms(y, alpha=0.5)


def test_validation_names_the_argument():
    with pytest.raises(ValueError, match="data_type"):
        avar.mtie([1.0, 2.0, 3.0], data_type="time")
    with pytest.raises(ValueError, match="needs at least"):
        avar.pdev([1.0], data_type="phase")
    with pytest.raises(ValueError, match="taus"):
        avar.tierms(np.arange(10.0), data_type="phase", taus=[100.0])
    res = avar.tierms(np.arange(10.0), data_type="phase")
    assert "TIERMS (time interval error rms)" in str(res)


def test_noise_of_the_line_free_phase_is_the_deviation_familys():
    from avar.stability.classic.deviations import noise_exponents

    rng = np.random.default_rng(12)
    cases = [np.cumsum(rng.standard_normal(20000)), rng.standard_normal(20000),
             np.cumsum(np.cumsum(rng.standard_normal(20000))) + 3.0 * np.arange(20000)]
    for data in cases:
        for data_type in ("phase", "freq"):
            res = avar.tierms(data, data_type=data_type, taus="decade")
            expected = noise_exponents("oadev", data, data_type, 1.0, res.averaging_factors)
            assert res.alpha.tolist() == expected.tolist()


def test_frequency_gaps_skip_the_windows_that_span_them():
    rng = np.random.default_rng(13)
    y = rng.standard_normal(90)
    y[[20, 55]] = np.nan
    x = np.concatenate(([0.0], np.cumsum(np.where(np.isnan(y), 0.0, y - np.nanmean(y)))))
    for name in ("mtie", "tierms"):
        res = getattr(avar, name)(y, data_type="freq", taus=[1, 3, 10], nan_policy="omit")
        for m, dev, n in zip(res.averaging_factors, res.deviation, res.n):
            m = int(m)
            starts = [i for i in range(x.size - m) if not np.isnan(y[i : i + m]).any()]
            if name == "mtie":
                expected = max(np.ptp(x[i : i + m + 1]) for i in starts)
            else:
                expected = math.sqrt(np.mean([(x[i + m] - x[i]) ** 2 for i in starts]))
            assert n == len(starts)
            assert dev == pytest.approx(expected, rel=1e-9)


#: Stable32 1.60 on its PHASE.DAT (1001 phase points, tau0 = 1 s): (AF, #, value), from the
#: MTIE and TIE rms tables kept in allantools' tests (5 printed digits).
STABLE32_PHASE_DAT = {
    "mtie": [(1, 1000, 5.0597e-01), (3, 998, 1.2984e+00), (7, 994, 2.2922e+00), (15, 986, 2.9949e+00),
             (31, 970, 4.4550e+00), (63, 938, 6.5989e+00), (127, 874, 6.8061e+00), (255, 746, 7.8205e+00),
             (511, 490, 7.8205e+00)],
    "tierms": [(1, 1000, 2.8832e-01), (2, 999, 4.0240e-01), (3, 998, 4.9390e-01), (10, 991, 8.7588e-01),
               (71, 930, 2.3318e+00), (133, 868, 2.9611e+00), (247, 754, 2.6144e+00)],
}


@pytest.mark.parametrize("name", sorted(STABLE32_PHASE_DAT))
def test_stable32_tables_of_phase_dat(name):
    x = np.loadtxt(STABLE32 / "PHASE.DAT")
    rows = np.array(STABLE32_PHASE_DAT[name])
    res = getattr(avar, name)(x, rate=1.0, data_type="phase", taus=rows[:, 0])
    assert res.n.tolist() == rows[:, 1].astype(int).tolist()
    np.testing.assert_allclose(res.deviation, rows[:, 2], rtol=5e-5)  # Stable32 prints 5 digits


#: SigmaTheta v3.0 (FEMTO-ST) on NIST's 1000-point NBS14 frequency record, kept in allantools'
#: tests: PDEV at (AF, value) to 17 digits, an implementation independent of allantools.
SIGMATHETA_NBS14_PDEV = [(1, 2.9223187810675200e-01), (2, 2.1445233564252639e-01), (4, 1.5618112158618463e-01),
                         (8, 1.1709745745448434e-01), (16, 6.9029585189839343e-02), (32, 4.9749707730398392e-02),
                         (64, 3.8947417330713739e-02), (128, 3.0862392741372108e-02), (256, 1.2447414341332683e-02),
                         (500, 9.3531187831254377e-04)]


def test_pdev_equals_sigmatheta_on_nbs14():
    rows = np.array(SIGMATHETA_NBS14_PDEV)
    res = avar.pdev(nbs14_1000(), taus=rows[:, 0])
    assert res.n.tolist() == [1001 - 2 * int(m) for m in rows[:, 0]]  # N - 2m windows of the N = 1001 phase points
    np.testing.assert_allclose(res.deviation, rows[:, 1], rtol=1e-10)  # 1e-11 at m = 500 (a single window)
