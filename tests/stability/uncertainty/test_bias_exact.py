"""Barnes' B2 and B3 against exact evaluations of their defining sums, and against the printed B3 formula.

No printed table of B2(r, mu) (Barnes, NBS TN 375, 1969) or B3(2, M, r, mu) (Barnes and Allan,
NIST TN 1318, 1990) could be found to compare with, so the functions are checked against
independent evaluations of the definitions in exact arithmetic: the two-sample variance of
averages over intervals of a process with phase structure function D(t) is
-1/4 sum_k sum_l a_k a_l D(s_k - s_l) over the interval ends s_k with weights a_k (summing to
zero). For the integer exponents (random-walk FM D = |t|**3, white FM D = |t|, white PM D = a
step) the sums are exact fractions; for flicker FM (t**2 ln t) and the fractional exponents they
are evaluated with 40-digit decimals. The float functions must agree to ~1e-13.
"""

from __future__ import annotations

from decimal import Decimal, localcontext
from fractions import Fraction

import pytest

import avar

#: alpha -> D(t), exact: fractions for the integer exponents of the phase structure function.
EXACT = {
    -2: lambda t: abs(t) ** 3,                  # random-walk FM, mu = 1
    0: lambda t: abs(t),                        # white FM, mu = -1
    2: lambda t: Fraction(0 if t == 0 else 1),  # white PM, mu = -2 (a step)
    1: lambda t: Fraction(0 if t == 0 else 1),  # flicker PM: Barnes' tables use mu = -2 too
}


def decimal_structure(alpha: float):
    """D(t) in 40-digit decimals for flicker FM (t^2 ln|t|) and the fractional exponents (|t|^(mu+2))."""
    mu = Decimal(-alpha - 1)

    def structure(t: Decimal) -> Decimal:
        t = abs(t)
        if t == 0:
            return Decimal(0)
        if mu == 0:
            return t * t * t.ln()
        return t ** (mu + 2)

    return structure


def two_sample_variance(structure, n: int, period, length):
    """sigma^2(2, n, T = period, tau = length) up to the noise level: averages of n measurements of
    length ``length`` every ``period``, two such averages one after the other."""
    points, weights = [], []
    for group, sign in ((0, -1), (1, 1)):
        for i in range(n):
            start = (group * n + i) * period
            points += [start + length, start]
            weights += [sign / (n * length), -sign / (n * length)]
    total = sum(ak * al * structure(sk - sl) for sk, ak in zip(points, weights) for sl, al in zip(points, weights))
    return -total / 4


def exact_b2_b3(structure, n: int, r):
    one = r / r  # 1 in the arithmetic of r
    b2 = two_sample_variance(structure, 1, r, one) / two_sample_variance(structure, 1, one, one)
    b3 = two_sample_variance(structure, n, r, one) / two_sample_variance(structure, 1, n * r, n * one)
    return b2, b3


RATIOS = [Fraction(1, 2), Fraction(1), Fraction(3, 2), Fraction(2), Fraction(3), Fraction(10)]


@pytest.mark.parametrize("alpha", sorted(EXACT))
@pytest.mark.parametrize("n", [1, 2, 3, 4, 6])
def test_b2_and_b3_equal_the_exact_fractions(alpha, n):
    for r in RATIOS:
        b2, b3 = exact_b2_b3(EXACT[alpha], n, r)
        assert isinstance(b2, Fraction) and isinstance(b3, Fraction)
        assert avar.bias_b2(alpha, float(r)) == pytest.approx(float(b2), rel=1e-13, abs=1e-15), (alpha, r)
        assert avar.bias_b3(alpha, n, float(r)) == pytest.approx(float(b3), rel=1e-13, abs=1e-15), (alpha, n, r)


def test_some_exact_values():
    """A few of the exact fractions, written out (random-walk FM, mu = 1; white PM; white FM)."""
    rw = EXACT[-2]
    assert exact_b2_b3(rw, 2, Fraction(2)) == (Fraction(5, 2), Fraction(17, 20))   # B2 = (3 r - 1) / 2
    assert exact_b2_b3(rw, 2, Fraction(5))[1] == Fraction(11, 14)
    assert exact_b2_b3(rw, 4, Fraction(2))[1] == Fraction(13, 16)
    assert avar.bias_b3(-2, 2, 2.0) == pytest.approx(17 / 20, rel=1e-14)
    assert avar.bias_b3(-2, 2, 5.0) == pytest.approx(11 / 14, rel=1e-14)
    assert avar.bias_b3(-2, 4, 2.0) == pytest.approx(13 / 16, rel=1e-14)
    assert exact_b2_b3(EXACT[2], 4, Fraction(3)) == (Fraction(2, 3), Fraction(4))     # white PM: B2 = 2/3, B3 = n
    assert exact_b2_b3(EXACT[0], 4, Fraction(3)) == (Fraction(1), Fraction(1))        # white FM: no bias


@pytest.mark.parametrize("alpha", [-1, -0.5, -1.5, -2.5, 0.5])
@pytest.mark.parametrize("n", [2, 3, 5])
def test_b2_and_b3_equal_40_digit_evaluations(alpha, n):
    """Flicker FM (mu = 0, D = t^2 ln t) and fractional exponents, where fractions cannot be exact."""
    structure = decimal_structure(alpha)
    with localcontext() as context:
        context.prec = 40
        for r in ("0.5", "1", "1.5", "2", "3", "10"):
            b2, b3 = exact_b2_b3(structure, n, Decimal(r))
            assert avar.bias_b2(alpha, float(r)) == pytest.approx(float(b2), rel=1e-14), (alpha, r)
            assert avar.bias_b3(alpha, n, float(r)) == pytest.approx(float(b3), rel=1e-14), (alpha, n, r)


def decimal_b3(alpha: float, n: int, r: str) -> Decimal:
    """B3 from the F sums (the form the test above checks against the covariances), in 50 digits."""
    structure = decimal_structure(alpha)

    def f(a: Decimal) -> Decimal:
        return 2 * structure(a) - structure(a + 1) - structure(a - 1)

    ratio, count = Decimal(r), Decimal(n)
    inner = sum((n - k) * (2 * f(k * ratio) - f((n + k) * ratio) - f((n - k) * ratio)) for k in range(1, n))
    numerator = 2 * count * structure(Decimal(1)) + count * f(count * ratio) - inner
    long = count * ratio
    return numerator / (2 * structure(count) + 2 * structure(long) - structure(long + count) - structure(long - count))


@pytest.mark.parametrize("alpha", [-1, -0.5, -1.5, -2.5])
def test_b3_keeps_its_digits_for_long_averages_and_long_dead_times(alpha):
    """n r up to 3e6: F(A) = 2 D(A) - D(A + 1) - D(A - 1) taken directly from three D ~ A**(mu+2)
    lost ~2 log10(A) digits (B3 of flicker FM was 0.6 % off at n = 1000, r = 1e4); it comes from its
    series in 1/A beyond A = 4."""
    with localcontext() as context:
        context.prec = 50
        for n, r in ((300, "10"), (300, "1e4"), (40, "3e4")):
            assert avar.bias_b3(alpha, n, float(r)) == pytest.approx(float(decimal_b3(alpha, n, r)), rel=1e-13)


def printed_b3(n: int, r: float, mu: float, last_sign: int) -> float:
    """Barnes and Allan's closed form of B3(2, M, r, mu) for the power laws (mu != 0, -2), with
    F(A) = 2 A^(mu+2) - (A + 1)^(mu+2) - |A - 1|^(mu+2):

        [2M + M F(Mr) - sum_{k=1}^{M-1} (M - k) (2 F(kr) - F((M + k) r) +/- F((M - k) r))] / [M^(mu+2) (F(r) + 2)]

    ``last_sign`` is the sign of the last term: reproductions of the formula (e.g. the Allan
    variance article of Wikipedia, citing TN 1318) print +; the direct sum of covariances gives -."""

    def f(a):
        return 2 * a ** (mu + 2) - (a + 1) ** (mu + 2) - abs(a - 1) ** (mu + 2)

    inner = sum((n - k) * (2 * f(k * r) - f((n + k) * r) + last_sign * f((n - k) * r)) for k in range(1, n))
    return (2 * n + n * f(n * r) - inner) / (n ** (mu + 2) * (f(r) + 2))


@pytest.mark.parametrize("alpha", [-2, -0.5, -1.5, -2.5])
def test_the_printed_b3_formula_holds_with_a_minus_sign(alpha):
    mu = -alpha - 1
    for n in (2, 3, 4, 8):
        for r in (1.0, 1.5, 2.0, 5.0):
            assert avar.bias_b3(alpha, n, r) == pytest.approx(printed_b3(n, r, mu, -1), rel=1e-12)
        # with the + sign, B3 at r = 1 (no dead time: the n averages ARE single measurements n tau0
        # long) would not be 1: the + is a misprint
        assert printed_b3(n, 1.0, mu, +1) != pytest.approx(1.0, rel=1e-3)
        assert avar.bias_b3(alpha, n, 1.0) == pytest.approx(1.0, rel=1e-12)
