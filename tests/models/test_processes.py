"""Tests of avar.models: process objects, sums, simulation and theoretical AV."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from avar.models import AR1, DR, QN, RW, WN, CompositeModel
from avar.stability.allan.columns import allan_variance_columns
from avar.stability.shared.grids import averaging_factors


# Closed forms written out here (not taken from avar.theory) so that a wrong
# constant anywhere in the chain makes a test fail.
def closed_form_av(process, m):
    m = np.asarray(m, dtype=np.float64)
    if isinstance(process, WN):
        return process.sigma2 / m
    if isinstance(process, QN):
        return 3.0 * process.q2 / m**2
    if isinstance(process, RW):
        return (2.0 * m**2 + 1.0) * process.gamma2 / (6.0 * m)
    if isinstance(process, DR):
        return m**2 * process.omega**2 / 2.0
    phi, s2 = process.phi, process.sigma2
    num = m - 3 * phi - m * phi**2 + 4 * phi ** (m + 1) - phi ** (2 * m + 1)
    return s2 * num / (m**2 * (1 - phi) ** 2 * (1 - phi**2))


# --------------------------------------------------------------------------- objects
def test_repr_is_readable_and_exact():
    assert repr(WN(sigma2=1) + RW(gamma2=1e-06)) == "WN(sigma2=1) + RW(gamma2=1e-06)"
    assert repr(QN(q2=0.5)) == "QN(q2=0.5)"
    assert repr(DR(omega=-2.25)) == "DR(omega=-2.25)"
    assert repr(AR1(phi=0.9, sigma2=0.1)) == "AR1(phi=0.9, sigma2=0.1)"
    assert repr(WN(sigma2=0.1 + 0.2)) == "WN(sigma2=0.30000000000000004)"


def test_equality_hash_and_flat_ordered_sums():
    assert WN(sigma2=1) == WN(sigma2=1.0)
    assert WN(sigma2=1) != WN(sigma2=2)
    assert WN(sigma2=1) != QN(q2=1)
    assert hash(WN(1)) == hash(WN(1.0))
    a, b, c = WN(1), RW(2), DR(3)
    assert (a + b) + c == a + (b + c) == CompositeModel((a, b, c))
    assert len(a + b + c) == 3
    assert a + b != b + a  # ordered, like the parameter vector
    assert a + b != a
    assert sum([a, b, c]) == a + b + c
    assert sum([a]) is a


def test_parameter_vector_and_names():
    model = WN(sigma2=1) + AR1(phi=0.5, sigma2=2) + DR(omega=3)
    np.testing.assert_array_equal(model.parameter_vector, [1.0, 0.5, 2.0, 3.0])
    assert model.parameter_vector.dtype == np.float64
    assert model.parameter_names == ("WN.sigma2", "AR1.phi", "AR1.sigma2", "DR.omega")
    np.testing.assert_array_equal(QN(q2=4).parameter_vector, [4.0])
    assert QN(q2=4).parameters == {"q2": 4.0}


def test_models_are_immutable():
    with pytest.raises(dataclasses.FrozenInstanceError):
        WN(1).sigma2 = 2
    with pytest.raises(dataclasses.FrozenInstanceError):
        (WN(1) + RW(1)).components = ()


@pytest.mark.parametrize(
    "build, error, match",
    [
        (lambda: WN(sigma2=-1), ValueError, "sigma2 must be >= 0"),
        (lambda: QN(q2=float("nan")), ValueError, "q2 must be finite"),
        (lambda: RW(gamma2="1"), TypeError, "gamma2 must be a real number"),
        (lambda: DR(omega=True), TypeError, "omega must be a real number"),
        (lambda: AR1(phi=1.0, sigma2=1), ValueError, r"\|phi\| < 1"),
        (lambda: AR1(phi=0.5, sigma2=-1), ValueError, "sigma2 must be >= 0"),
        (lambda: CompositeModel(()), TypeError, "one or more processes"),
    ],
)
def test_bad_parameters_raise(build, error, match):
    with pytest.raises(error, match=match):
        build()


def test_bad_simulation_and_scale_arguments_raise():
    with pytest.raises(ValueError, match="n must be a whole number >= 1"):
        WN(1).simulate(0)
    with pytest.raises(ValueError, match="n must be a whole number"):
        WN(1).simulate(2.5)
    with pytest.raises(TypeError, match="n must be a whole number"):
        WN(1).simulate("10")
    with pytest.raises(ValueError, match="replicates must be"):
        WN(1).simulate_replicates(10, 0)
    with pytest.raises(ValueError, match="m must hold averaging factors >= 1"):
        WN(1).theoretical_av([0, 1])
    with pytest.raises(ValueError, match="m must hold whole numbers"):
        WN(1).theoretical_av(1.5)
    with pytest.raises(TypeError):
        WN(1) + 1


# --------------------------------------------------------------------------- theory
def test_theoretical_av_is_the_sum_of_closed_forms():
    parts = [WN(2.0), QN(0.3), RW(1e-3), DR(0.01), AR1(phi=0.8, sigma2=0.5)]
    model = sum(parts)
    m = np.array([1, 2, 3, 8, 100, 4096])
    expected = sum(closed_form_av(p, m) for p in parts)
    np.testing.assert_allclose(model.theoretical_av(m), expected, rtol=1e-13)
    for part in parts:
        np.testing.assert_allclose(part.theoretical_av(m), closed_form_av(part, m), rtol=1e-13)
    value = model.theoretical_av(8)
    assert isinstance(value, float)
    assert value == pytest.approx(expected[3], rel=1e-13)
    assert model.theoretical_av(np.array([[1, 2], [3, 8]])).shape == (2, 2)
    assert WN(sigma2=1).theoretical_av(4.0) == 0.25  # whole floats accepted


# --------------------------------------------------------------------------- simulation
def test_simulation_is_seeded_and_float64():
    model = WN(1) + QN(0.1) + RW(0.01) + DR(0.001) + AR1(0.5, 1)
    x = model.simulate(1000, seed=7)
    assert x.shape == (1000,) and x.dtype == np.float64
    np.testing.assert_array_equal(x, model.simulate(1000, seed=7))
    assert not np.array_equal(x, model.simulate(1000, seed=8))
    np.testing.assert_array_equal(x, model.simulate(1000, seed=np.random.default_rng(7)))
    np.testing.assert_array_equal(x, model.simulate_replicates(1000, 1, seed=7)[0])
    many = model.simulate_replicates(500, 4, seed=1)
    assert many.shape == (4, 500) and many.flags.c_contiguous
    assert len({row.tobytes() for row in many}) == 4


def test_drift_is_exact_and_composite_is_the_sum_of_components():
    np.testing.assert_array_equal(DR(omega=0.5).simulate(4), [0.5, 1.0, 1.5, 2.0])
    # the drift draws no random numbers, so adding it shifts the series exactly
    x = (WN(1) + DR(0.5)).simulate(100, seed=3)
    np.testing.assert_allclose(x - WN(1).simulate(100, seed=3), 0.5 * np.arange(1, 101), rtol=0, atol=1e-12)


def test_sample_moments_match_definitions():
    n = 200_000
    tolerance = 4 * np.sqrt(2.0 / n)  # relative SE of a sample variance, Gaussian case
    wn = WN(sigma2=2.5).simulate(n, seed=11)
    assert wn.mean() == pytest.approx(0.0, abs=4 * np.sqrt(2.5 / n))
    assert wn.var() == pytest.approx(2.5, rel=tolerance)

    qn = QN(q2=0.7).simulate(n, seed=12)
    assert qn.var() == pytest.approx(2 * 0.7, rel=tolerance)  # var = 2 q2
    assert np.abs(qn).max() <= np.sqrt(12 * 0.7)  # difference of two sqrt(12 q2) U(0, 1)
    lag1 = np.mean(qn[1:] * qn[:-1]) / qn.var()
    assert lag1 == pytest.approx(-0.5, abs=0.02)  # first difference of white noise

    rw = RW(gamma2=0.04).simulate(n, seed=13)
    steps = np.diff(rw, prepend=0.0)
    assert steps.var() == pytest.approx(0.04, rel=tolerance)
    assert abs(np.corrcoef(steps[1:], steps[:-1])[0, 1]) < 0.01

    phi, sigma2 = 0.9, 0.5
    ar = AR1(phi=phi, sigma2=sigma2).simulate(n, seed=14)
    assert ar.var() == pytest.approx(sigma2 / (1 - phi**2), rel=0.05)
    assert np.corrcoef(ar[1:], ar[:-1])[0, 1] == pytest.approx(phi, abs=0.01)
    innovations = ar[1:] - phi * ar[:-1]
    assert innovations.var() == pytest.approx(sigma2, rel=tolerance)


def test_ar1_starts_from_its_stationary_law():
    phi, sigma2 = 0.95, 1.0
    first = AR1(phi=phi, sigma2=sigma2).simulate_replicates(3, 20_000, seed=5)
    stationary = sigma2 / (1 - phi**2)
    for t in range(3):
        assert first[:, t].var() == pytest.approx(stationary, rel=0.05)


@pytest.mark.parametrize(
    "model",
    [WN(sigma2=2.0), QN(q2=0.5), RW(gamma2=0.01), AR1(phi=0.9, sigma2=1.0), WN(1.0) + RW(1e-3)],
    ids=repr,
)
def test_mean_empirical_av_matches_theory_within_3_standard_errors(model):
    n, replicates = 2**12, 100
    factors = averaging_factors(n)
    series = model.simulate_replicates(n, replicates, seed=2024)
    av = allan_variance_columns(series.T, factors, "mo")  # (replicates, levels)
    mean = av.mean(axis=0)
    standard_error = av.std(axis=0, ddof=1) / np.sqrt(replicates)
    theory = model.theoretical_av(factors)
    assert np.all(np.abs(mean - theory) <= 3 * standard_error), (mean / theory, standard_error / theory)
    # and the check has teeth: a 20% error in the theory would be caught at the small scales
    assert np.any(np.abs(mean - 1.2 * theory) > 3 * standard_error)


def test_empirical_av_of_a_drift_is_exact():
    n = 2**12
    factors = averaging_factors(n)
    series = DR(omega=0.003).simulate(n)
    av = allan_variance_columns(series[:, None], factors, "mo")[0]
    np.testing.assert_allclose(av, DR(omega=0.003).theoretical_av(factors), rtol=1e-9)


def test_simulate_into_fills_a_reused_buffer():
    out = np.full((3, 50), np.nan)
    (WN(1) + RW(0.1)).simulate_into(out, np.random.default_rng(4))
    np.testing.assert_array_equal(out, (WN(1) + RW(0.1)).simulate_replicates(50, 3, seed=4))
    with pytest.raises(TypeError, match="C-contiguous float64"):
        WN(1).simulate_into(np.empty((50, 3)).T, np.random.default_rng(0))
    with pytest.raises(TypeError, match="rng must be a numpy.random.Generator"):
        WN(1).simulate_into(out, 0)
