"""Tests of the flicker (bias instability) process FN: theory, exact simulation, units."""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from avar.models import FN, RW, WN
from avar.models.flicker import FLICKER_AV_FACTOR, av_fn
from avar.stability.allan.columns import allan_variance_columns


def reference_av(b2, m):
    """Plain loops over the definition, in exact rationals times 4 b2 / pi.

    Increment autocovariance gamma(h) = (4 b2 / pi) / (1 - 4 h^2); the AV of
    cluster size m is Var(sum of triangular weights times increments) / (2 m^2).
    """
    weights = [min(k + 1, 2 * m - 1 - k) for k in range(2 * m - 1)]  # 1, 2, .., m, .., 1
    total = Fraction(0)
    for i, wi in enumerate(weights):
        for j, wj in enumerate(weights):
            total += wi * wj * Fraction(1, 1 - 4 * (i - j) ** 2)
    return float(total / (2 * m * m)) * 4.0 * b2 / math.pi


@pytest.mark.parametrize("m", [1, 2, 3, 5, 8, 13])
def test_theoretical_av_matches_the_definition(m):
    assert FN(b2=2.5).theoretical_av(m) == pytest.approx(reference_av(2.5, m), rel=1e-12)


def test_av_tends_to_the_ieee_plateau():
    values = FN(b2=1.0).theoretical_av([1, 2**10, 2**16, 2**20])
    assert values[0] == pytest.approx(2 / math.pi, rel=1e-14)
    assert values[-1] == pytest.approx(2 * math.log(2) / math.pi, rel=1e-5)
    # the deviation plateau is 0.664 B (IEEE 952)
    assert math.sqrt(values[-1]) == pytest.approx(0.6643, abs=1e-4)
    assert np.all(np.diff(values) < 0)  # decreasing towards the plateau


def test_av_is_linear_in_b2_and_adds_to_other_processes():
    m = np.array([1, 4, 64])
    np.testing.assert_allclose(FN(b2=3.0).theoretical_av(m), 3.0 * av_fn(1.0, m), rtol=1e-14)
    model = WN(sigma2=1.0) + FN(b2=0.5) + RW(gamma2=1e-4)
    expected = 1.0 / m + 0.5 * av_fn(1.0, m) + (2 * m**2 + 1) * 1e-4 / (6 * m)
    np.testing.assert_allclose(model.theoretical_av(m), expected, rtol=1e-13)


def test_simulated_increments_have_the_stated_autocovariance():
    x = FN(b2=math.pi / 4).simulate_replicates(64, 4000, seed=3)
    u = np.diff(x, axis=1)
    lag0 = np.mean(u**2)
    lag1 = np.mean(u[:, 1:] * u[:, :-1])
    lag2 = np.mean(u[:, 2:] * u[:, :-2])
    assert lag0 == pytest.approx(1.0, abs=0.01)  # gamma(0) = 4 b2 / pi
    assert lag1 == pytest.approx(-1 / 3, abs=0.01)
    assert lag2 == pytest.approx(-1 / 15, abs=0.01)


def test_simulated_av_is_unbiased_at_every_scale():
    n, factors = 2048, np.array([1, 2, 4, 16, 64, 256])
    x = FN(b2=1.0).simulate_replicates(n, 600, seed=4)
    av = allan_variance_columns(np.ascontiguousarray(x.T), factors, "mo").mean(axis=0)
    ratio = av / FN(b2=1.0).theoretical_av(factors)
    np.testing.assert_allclose(ratio, 1.0, atol=0.05)


def test_simulation_is_reproducible_and_scaled():
    a = FN(b2=4.0).simulate(500, seed=7)
    b = FN(b2=1.0).simulate(500, seed=7)
    np.testing.assert_allclose(a, 2.0 * b, rtol=1e-13)
    assert FN(b2=0.0).simulate(10, seed=1).tolist() == [0.0] * 10
    assert FN(b2=1.0).simulate(1, seed=1).shape == (1,)
    odd = FN(b2=1.0).simulate_replicates(100, 3, seed=1)
    assert odd.shape == (3, 100) and np.all(np.isfinite(odd))


def test_from_continuous_is_rate_free_and_validates():
    assert FN.from_continuous(0.5, 200.0) == FN(b2=0.25)
    assert FN.from_continuous(0.5, 1.0) == FN(b2=0.25)
    assert FN(b2=0.25).B == 0.5
    assert FLICKER_AV_FACTOR == pytest.approx(0.664 ** 2, rel=1e-3)
    with pytest.raises(ValueError, match="b2"):
        FN(b2=-1.0)
    with pytest.raises(ValueError, match="freq"):
        FN.from_continuous(1.0, 0.0)
    assert repr(WN(sigma2=1) + FN(b2=2)) == "WN(sigma2=1) + FN(b2=2)"
    assert (WN(sigma2=1) + FN(b2=2)).parameter_names == ("WN.sigma2", "FN.b2")
