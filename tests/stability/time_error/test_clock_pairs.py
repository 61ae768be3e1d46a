"""Three-cornered hat and Groslambert codeviation: the algebra, allantools, simulated clocks with known truth."""

from __future__ import annotations

import math

import allantools
import numpy as np
import pytest

import avar


def _clocks(seed, n=4001, scales=(1.0, 2.0, 3.0)):
    rng = np.random.default_rng(seed)
    return [s * rng.standard_normal(n) for s in scales]


def test_hat_is_the_signed_half_sum_of_the_pairs():
    a, b, c = _clocks(0, 801)
    ab, bc, ca = a - b, b - c, c - a
    hat = avar.three_cornered_hat(ab, bc, ca, rate=2.0, data_type="freq", taus="octave", statistic="mdev")
    v = {name: avar.mdev(s, rate=2.0).variance for name, s in (("ab", ab), ("bc", bc), ("ca", ca))}
    np.testing.assert_allclose(hat.a.variance, (v["ab"] + v["ca"] - v["bc"]) / 2, rtol=1e-12)
    np.testing.assert_allclose(hat.b.variance, (v["ab"] + v["bc"] - v["ca"]) / 2, rtol=1e-12)
    np.testing.assert_allclose(hat.c.variance, (v["bc"] + v["ca"] - v["ab"]) / 2, rtol=1e-12)
    assert hat.a.estimator == "mdev" and hat.a.n.tolist() == avar.mdev(ab, rate=2.0).n.tolist()


def test_hat_equals_allantools_where_positive():
    a, b, c = _clocks(1, 1001)
    ab, bc, ca = np.cumsum(a - b), np.cumsum(b - c), np.cumsum(c - a)  # phase
    hat = avar.three_cornered_hat(ab, bc, ca, taus=[1.0, 4.0, 16.0])
    _, dev_a, _, _ = allantools.three_cornered_hat_phase(ab, bc, ca, 1.0, np.array([1.0, 4.0, 16.0]),
                                                         allantools.oadev)
    positive = hat.a.variance > 0
    np.testing.assert_allclose(hat.a.deviation[positive], dev_a[positive], rtol=1e-10)
    assert np.all(dev_a[~positive] == 0)  # allantools clips; we report the negative variance


def test_hat_recovers_known_clocks_within_its_bands_and_reports_negatives():
    inside = total = 0
    for seed in range(10):
        a, b, c = _clocks(seed + 10)
        hat = avar.three_cornered_hat(a - b, b - c, c - a, data_type="freq", taus=[1.0, 2.0, 4.0],
                                      confidence=0.95)
        for clock, sigma in zip(hat, (1.0, 2.0, 3.0)):
            truth = sigma / np.sqrt(hat.a.taus)  # white FM: ADEV = sigma / sqrt(m)
            inside += int(np.sum((clock.lci <= truth) & (truth <= clock.uci)))
            total += truth.size
    assert inside / total >= 0.85
    # a quiet clock among two loud ones: its variance estimate is often negative, and stays so
    a, b, c = _clocks(3, 501, scales=(0.01, 3.0, 3.0))
    hat = avar.three_cornered_hat(a - b, b - c, c - a, data_type="freq", taus="all")
    negative = hat.a.variance < 0
    assert negative.any()
    assert np.isnan(hat.a.deviation[negative]).all() and np.isnan(hat.a.lci[negative]).all()
    with pytest.raises(ValueError, match="one length"):
        avar.three_cornered_hat(a, b[:-1], c)
    with pytest.raises(ValueError, match="statistic must be one of"):
        avar.three_cornered_hat(a, b, c, statistic="mtie")


def _gcov_loop(x1, x2, m, tau):
    terms = [(x1[i + 2 * m] - 2 * x1[i + m] + x1[i]) * (x2[i + 2 * m] - 2 * x2[i + m] + x2[i])
             for i in range(len(x1) - 2 * m)]
    return math.fsum(terms) / (2 * len(terms) * tau * tau)


def test_gcodev_plain_loop_allantools_and_sign():
    a, b, c = _clocks(4, 600)
    x1, x2 = np.cumsum(a - b), np.cumsum(b - c)
    res = avar.gcodev(x1, x2, rate=2.0, data_type="phase", taus="all")
    expected = [_gcov_loop(x1, x2, int(m), m / 2.0) for m in res.averaging_factors]
    np.testing.assert_allclose(res.variance, expected, rtol=1e-9)
    np.testing.assert_allclose(res.deviation, np.sign(expected) * np.sqrt(np.abs(expected)), rtol=1e-9)
    taus, devs, _, ns = allantools.gcodev(x1, x2, rate=2.0, data_type="phase", taus=res.taus[:50])
    np.testing.assert_allclose(np.abs(res.deviation[:50]), devs, rtol=1e-10)
    assert res.n[:50].tolist() == ns.astype(int).tolist()
    assert res.variance[0] < 0  # AB and BC share B with opposite signs: - sigma_B**2
    assert np.isnan(res.edf).all()


def test_gcodev_estimates_the_shared_clock_free_of_the_others():
    rng = np.random.default_rng(8)
    b = rng.standard_normal(200001)
    loud = [10 * rng.standard_normal(b.size) for _ in range(2)]
    res = avar.gcodev(loud[0] - b, loud[1] - b, taus=[1.0, 10.0])
    np.testing.assert_allclose(res.variance, [1.0, 0.1], rtol=0.25)


def test_gcodev_gaps_and_validation():
    rng = np.random.default_rng(9)
    x1, x2 = rng.standard_normal(100), rng.standard_normal(100)
    x2[40] = np.nan
    res = avar.gcodev(x1, x2, data_type="phase", taus=[1, 3], nan_policy="omit")
    for m, var, n in zip(res.averaging_factors, res.variance, res.n):
        m = int(m)
        terms = [(x1[i + 2 * m] - 2 * x1[i + m] + x1[i]) * (x2[i + 2 * m] - 2 * x2[i + m] + x2[i])
                 for i in range(100 - 2 * m)]
        terms = [t for t in terms if np.isfinite(t)]
        assert n == len(terms) and var == pytest.approx(math.fsum(terms) / (2 * len(terms) * m * m), rel=1e-9)
    with pytest.raises(ValueError, match="one length"):
        avar.gcodev(x1, x1[:-1], data_type="phase")
    with pytest.raises(ValueError, match="data_2 has 1 NaN"):
        avar.gcodev(x1, x2, data_type="phase")
