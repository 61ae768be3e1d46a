"""Tests of avar.theory: closed-form Allan variances (Zhang 2008, R avar 0.1.3)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from avar.models.theory import av_ar1, av_dr, av_qn, av_rw, av_wn


def ar1_exact(n: int, phi, sigma2) -> float:
    """R's av_ar1 formula in exact rational arithmetic (phi, sigma2 taken exactly)."""
    p, s2 = Fraction(phi), Fraction(sigma2)
    num = n - 3 * p - n * p**2 + 4 * p ** (n + 1) - p ** (2 * n + 1)
    return float(s2 * num / (n**2 * (1 - p) ** 2 * (1 - p**2)))


def rel(a, b):
    return abs(a / b - 1.0)


# ----------------------------------------------------------------- values of R 0.1.3
def test_r_examples_by_hand():
    # written-out arithmetic, independent of the library
    assert av_wn(2, 8) == 2 / 8 == 0.25
    assert rel(av_qn(2, 8), 3 * 2 / 8**2) < 1e-12 and av_qn(2, 8) == 0.09375
    assert rel(av_rw(2, 8), (2 * 8**2 + 1) * 2 / (6 * 8)) < 1e-12 and av_rw(2, 8) == 5.375
    assert rel(av_dr(2, 8), 8**2 * 2**2 / 2) < 1e-12 and av_dr(2, 8) == 128.0
    # the manual's other examples
    assert av_wn(sigma2=1, n=5) == 0.2
    assert av_qn(Q2=1, n=5) == pytest.approx(3 / 25, rel=1e-15)
    assert av_rw(omega2=1, n=5) == pytest.approx(51 / 30, rel=1e-15)
    assert av_dr(delta=1, n=5) == 12.5


def test_av_ar1_r_examples():
    # av_ar1(n = 5, phi = 0.9, sigma2 = 1) and av_ar1(n = 8, phi = 0.5, sigma2 = 2)
    p = Fraction(9, 10)
    exact1 = (5 - 3 * p - 5 * p**2 + 4 * p**6 - p**11) / (25 * (1 - p) ** 2 * (1 - p**2))
    assert float(exact1) == pytest.approx(1.3042821875789474, rel=1e-15)
    assert rel(av_ar1(n=5, phi=0.9, sigma2=1), float(exact1)) < 1e-12
    q = Fraction(1, 2)
    exact2 = 2 * (8 - 3 * q - 8 * q**2 + 4 * q**9 - q**17) / (64 * (1 - q) ** 2 * (1 - q**2))
    assert exact2 == Fraction(196949, 262144)  # 0.75130081176757812...
    assert rel(av_ar1(8, 0.5, 2), float(exact2)) < 1e-12


def test_av_ar1_special_cases():
    # phi = 0 is white noise
    assert av_ar1(7, 0.0, 3.0) == pytest.approx(av_wn(3.0, 7), rel=1e-15)
    # n = 1: AV = sigma2 (1 - phi)^3 / ((1 - phi)^2 (1 - phi^2)) = sigma2 / (1 + phi)
    for phi in (-0.9, -0.3, 0.2, 0.7, 0.99):
        assert av_ar1(1, phi, 2.0) == pytest.approx(2.0 / (1 + phi), rel=1e-14)
    # phi -> 1 with fixed innovation variance tends to a random walk: (2n^2 + 1)/(6n)
    assert av_ar1(4, 1 - 1e-9, 1.0) == pytest.approx(av_rw(1.0, 4), rel=1e-6)
    # large n: sigma2 / ((1 - phi)^2 n) to first order
    assert av_ar1(10**6, 0.5, 1.0) == pytest.approx(4e-6, rel=1e-5)


@pytest.mark.parametrize("phi", [0.9999, 0.99999, 1 - 1e-7, -0.9999, -1 + 1e-8, 0.5, -0.5])
@pytest.mark.parametrize("n", [1, 2, 3, 10, 64, 1001])
def test_av_ar1_accurate_near_unit_root(phi, n):
    # R's literal expression loses ~(n (1 - phi))^-3 ulps here; ours must not
    assert rel(av_ar1(n, phi, 1.0), ar1_exact(n, phi, 1)) < 1e-13


@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 300), phi=st.floats(-0.999999, 0.999999), s2=st.floats(1e-3, 1e3))
def test_av_ar1_matches_exact_rational(n, phi, s2):
    assert rel(av_ar1(n, phi, s2), ar1_exact(n, phi, s2)) < 1e-13


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 10**6), v=st.floats(0.0, 1e6))
def test_simple_processes_match_exact_rational(n, v):
    fv = Fraction(v)
    assert av_wn(v, n) == pytest.approx(float(fv / n), rel=1e-15, abs=0)
    assert av_qn(v, n) == pytest.approx(float(3 * fv / n**2), rel=1e-15, abs=0)
    assert av_rw(v, n) == pytest.approx(float((2 * n**2 + 1) * fv / (6 * n)), rel=1e-15, abs=0)
    assert av_dr(v, n) == pytest.approx(float(n**2 * fv**2 / 2), rel=1e-15, abs=0)


# ----------------------------------------------------------------- vectorization
def test_scalar_inputs_return_python_float():
    for val in (av_wn(1, 2), av_qn(1, 2), av_rw(1, 2), av_dr(1, 2), av_ar1(2, 0.5, 1),
                av_wn(np.float32(1), np.int64(2)), av_wn(1.0, 2.0), av_wn(np.array(1.0), 4)):
        assert type(val) is float


def test_array_n_returns_float64_array():
    m = 2 ** np.arange(1, 11)
    for f, args in ((av_wn, (2.0, m)), (av_qn, (2.0, m)), (av_rw, (2.0, m)),
                    (av_dr, (2.0, m)), (av_ar1, (m, 0.9, 2.0))):
        out = f(*args)
        assert isinstance(out, np.ndarray) and out.dtype == np.float64 and out.shape == (10,)
    np.testing.assert_allclose(av_wn(2.0, m), 2.0 / m, rtol=1e-15)
    np.testing.assert_allclose(av_rw(2.0, m), (2 * m**2 + 1) * 2.0 / (6 * m), rtol=1e-15)
    np.testing.assert_allclose(av_ar1(m, 0.9, 2.0),
                               [ar1_exact(int(k), 0.9, 2) for k in m], rtol=1e-13)
    assert av_wn(1.0, [1, 2, 4]).tolist() == [1.0, 0.5, 0.25]
    # a list with one element is still an array
    assert isinstance(av_qn(1.0, [2]), np.ndarray)


def test_broadcasting_of_parameters():
    out = av_wn(np.array([[1.0], [2.0]]), np.array([1, 2, 4]))
    assert out.shape == (2, 3)
    np.testing.assert_array_equal(out, [[1, 0.5, 0.25], [2, 1, 0.5]])
    out = av_ar1(np.array([1, 2]), np.array([[0.0], [0.5]]), 1.0)
    np.testing.assert_allclose(out, [[1.0, 0.5], [ar1_exact(1, 0.5, 1), ar1_exact(2, 0.5, 1)]],
                               rtol=1e-14)
    with pytest.raises(ValueError, match="cannot be broadcast"):
        av_wn([1.0, 2.0], [1, 2, 3])


def test_whole_float_n_accepted():
    assert av_wn(1.0, 4.0) == av_wn(1.0, 4) == 0.25
    assert av_ar1(np.array([2.0, 4.0]), 0.5, 1.0).tolist() == av_ar1([2, 4], 0.5, 1.0).tolist()


def test_negative_drift_allowed():
    assert av_dr(-2.0, 8) == av_dr(2.0, 8) == 128.0


# ----------------------------------------------------------------- bad input
@pytest.mark.parametrize("f", [av_wn, av_qn, av_rw, av_dr])
def test_bad_n(f):
    with pytest.raises(ValueError, match=r"n must be whole numbers.*got 1\.5"):
        f(1.0, 1.5)
    with pytest.raises(ValueError, match="n must be >= 1, got 0"):
        f(1.0, 0)
    with pytest.raises(ValueError, match="n must be >= 1, got -4"):
        f(1.0, [2, -4])
    with pytest.raises(ValueError, match="n must be finite"):
        f(1.0, np.nan)
    with pytest.raises(TypeError, match="n must be a real number"):
        f(1.0, "8")
    with pytest.raises(TypeError, match="n must be a real number"):
        f(1.0, True)
    with pytest.raises(ValueError, match="n must not be empty"):
        f(1.0, [])


@pytest.mark.parametrize("f, name", [(av_wn, "sigma2"), (av_qn, "Q2"), (av_rw, "omega2")])
def test_negative_variance(f, name):
    with pytest.raises(ValueError, match=rf"{name} must be >= 0 \(a variance\), got -1"):
        f(-1.0, 4)
    with pytest.raises(ValueError, match=rf"{name} must be finite"):
        f(np.inf, 4)
    with pytest.raises(TypeError, match=rf"{name} must be a real number"):
        f(None, 4)


def test_av_dr_bad_delta():
    with pytest.raises(ValueError, match="delta must be finite"):
        av_dr(np.nan, 2)
    with pytest.raises(TypeError, match="delta must be a real number"):
        av_dr(1 + 2j, 2)


def test_av_ar1_bad_input():
    for phi in (1.0, -1.0, 1.5):
        with pytest.raises(ValueError, match=r"phi must satisfy \|phi\| < 1"):
            av_ar1(4, phi, 1.0)
    with pytest.raises(ValueError, match=r"sigma2 must be >= 0"):
        av_ar1(4, 0.5, -0.1)
    with pytest.raises(ValueError, match="n must be whole numbers"):
        av_ar1(2.5, 0.5, 1.0)
    with pytest.raises(ValueError, match="n must be >= 1"):
        av_ar1(0, 0.5, 1.0)
    with pytest.raises(TypeError, match="phi must be a real number"):
        av_ar1(2, "0.5", 1.0)
