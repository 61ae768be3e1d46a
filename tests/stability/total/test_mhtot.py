"""MHTOTDEV against a plain loop over its definition, in floats and in exact rationals."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

import avar
from avar.stability.uncertainty.edf import estimator_edf


def plain_mhtotvar(x: list, m: int, rate, number=float):
    """The modified Hadamard total variance by its definition (SigmaTau.jl's ``_mhtotdev_core``, half-means
    detrending) on the phase x (s), in the arithmetic of ``number``: (variance, windows)."""
    n = len(x)
    span = 3 * m + 1
    half = span // 2
    windows = []
    for start in range(n - 4 * m + 1):
        w = x[start:start + span]
        slope = (sum(w[half:], number(0)) / (span - half) - sum(w[:half], number(0)) / half) / (Fraction(span, 2)
                                                                                                  if number is Fraction
                                                                                                  else span / 2)
        d = [w[k] - slope * k for k in range(span)]
        ext = d[::-1] + d + d[::-1]
        third = [ext[i] - 3 * ext[i + m] + 3 * ext[i + 2 * m] - ext[i + 3 * m] for i in range(len(ext) - 3 * m)]
        sums = [sum(third[j:j + m], number(0)) for j in range(len(third) - m + 1)]
        assert len(sums) == 5 * m + 4
        squares = [a * a for a in sums]
        windows.append((math.fsum(squares) if number is float else sum(squares, number(0))) / len(sums))
    tau = number(m) / number(rate)
    total = math.fsum(windows) if number is float else sum(windows, number(0))
    return total / (6 * m * m * tau * tau * len(windows)), len(windows)


@pytest.mark.parametrize("kind", ["white", "random walk"])
def test_equals_a_plain_loop_over_the_definition(kind):
    rng = np.random.default_rng(4)
    data = rng.standard_normal(400) * 1e-9
    if kind == "random walk":
        data = np.cumsum(data)
    for data_type in ("freq", "phase"):
        x = np.concatenate(([0.0], np.cumsum(data))) / 2.0 if data_type == "freq" else data
        res = avar.mhtotdev(data, rate=2.0, data_type=data_type, taus="all")
        assert res.averaging_factors[-1] == x.size // 4
        for k in (0, 1, 2, 7, 30, res.taus.size - 1):
            m = int(res.averaging_factors[k])
            variance, windows = plain_mhtotvar(list(x), m, 2.0)
            assert res.n[k] == windows == x.size - 4 * m + 1
            assert res.variance[k] == pytest.approx(variance, rel=1e-10)


def test_exact_rationals():
    """Small rational data: the statistic in exact arithmetic, to 1e-12."""
    data = [Fraction(v) for v in (3, -1, 4, 1, -5, 9, 2, -6, 5, 3, -5, 8, 9, -7, 9, 3, 2, -3, 8, 4)]
    x = [Fraction(0)]
    for v in data:
        x.append(x[-1] + v)
    res = avar.mhtotdev(np.array(data, dtype=float), rate=4.0, taus="all")
    for k, m in enumerate(res.averaging_factors.tolist()):
        variance, windows = plain_mhtotvar([v / 4 for v in x], m, Fraction(4), number=Fraction)
        assert res.n[k] == windows
        assert res.variance[k] == pytest.approx(float(variance), rel=1e-12)


def test_near_mhdev_on_white_fm_blind_to_an_offset_not_to_a_drift():
    y = np.random.default_rng(5).standard_normal(20_000)
    total, plain = avar.mhtotdev(y, taus=[4, 16, 64]), avar.mhdev(y, taus=[4, 16, 64])
    np.testing.assert_allclose(total.deviation, plain.deviation, rtol=0.1)
    np.testing.assert_allclose(avar.mhtotdev(y + 1e3, taus=[4, 16, 64]).deviation, total.deviation, rtol=1e-9)
    drifted = avar.mhtotdev(y + 1e-2 * np.arange(y.size), taus=[4, 16, 64])
    assert drifted.deviation[-1] > 2 * total.deviation[-1]  # the reflected windows keep a drift's curvature


def test_noise_and_edf_are_mhdevs():
    y = np.random.default_rng(6).standard_normal(3000)
    res = avar.mhtotdev(y, taus="octave")
    assert res.estimator == "mhtotdev" and res.long_name == "modified Hadamard total deviation"
    np.testing.assert_array_equal(res.alpha, avar.mhdev(y, taus="octave").alpha)
    np.testing.assert_allclose(res.edf, estimator_edf("mhdev", res.alpha, res.averaging_factors, 3001), rtol=1e-14)
    fixed = avar.mhtotdev(y, taus="octave", alpha=-1)
    assert fixed.alpha.tolist() == [-1] * res.taus.size
    np.testing.assert_array_equal(fixed.deviation, res.deviation)
    assert np.all((res.lci < res.deviation) & (res.deviation < res.uci))


def test_gaps_skip_the_windows_that_touch_them():
    rng = np.random.default_rng(7)
    x = np.cumsum(rng.standard_normal(300))
    x[[50, 51, 200]] = np.nan
    res = avar.mhtotdev(x, data_type="phase", taus=[1, 5], nan_policy="omit")
    for k, m in enumerate((1, 5)):
        span = 3 * m + 1
        clean = [s for s in range(300 - 4 * m + 1) if not np.isnan(x[s:s + span]).any()]
        assert res.n[k] == len(clean)
    with pytest.raises(ValueError, match="NaN"):
        avar.mhtotdev(x, data_type="phase")


def test_errors():
    with pytest.raises(ValueError, match="needs at least 3"):
        avar.mhtotdev([1.0, 2.0])
    with pytest.raises(ValueError, match="taus"):
        avar.mhtotdev(np.arange(40.0), taus=[11.0])
    with pytest.raises(TypeError, match="bias_correction"):
        avar.mhtotdev(np.arange(40.0), bias_correction=True)
