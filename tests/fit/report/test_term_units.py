"""Every noise term's unit, derived from the term's definition by dimensional analysis (not restated).

A term theta of slope b has AD(tau) = c theta tau^b (IEEE 952), so theta's
dimension is that of the deviation times s^-b. The units the report writes are
parsed here (u, s, Hz = 1/s, h = 3600 s, rad, deg, m, g, ug; ``*``, ``/``, ``^``, sqrt())
into a scale and exponents, and compared with that; customary factors must be the
ratio of the parsed scales.
"""

import math
import re
from fractions import Fraction

import numpy as np
import pytest

from avar.fit.report.noise_terms import ACCEL, CUSTOMARY, GYRO, SI_UNITS, unit_of
from avar.fit.report.rows import channel_rows
from avar.fit.report.sensor_fit import fit_sensor_model
from avar.fit.terms import POWER_LAWS
from avar.models import AR1, SIN, WN

G0 = 9.80665
#: symbol -> (scale in SI, exponents)
SYMBOLS = {
    "u": (1.0, {"u": 1}), "s": (1.0, {"s": 1}), "Hz": (1.0, {"s": -1}), "h": (3600.0, {"s": 1}),
    "rad": (1.0, {"rad": 1}), "deg": (math.pi / 180.0, {"rad": 1}), "m": (1.0, {"m": 1}),
    "g": (G0, {"m": 1, "s": -2}), "ug": (G0 * 1e-6, {"m": 1, "s": -2}),
}


def parse(unit: str) -> tuple[float, dict[str, Fraction]]:
    """(scale, exponents) of a unit string: products, quotients (left to right), powers and sqrt()."""
    tokens = re.findall(r"sqrt\(|\(|\)|\^-?\d+(?:/\d+)?|[A-Za-z]+|[*/ ]", unit)
    assert "".join(tokens).replace(" ", "") == unit.replace(" ", ""), f"unparsed characters in {unit!r}"
    position = 0

    def product() -> tuple[float, dict[str, Fraction]]:
        nonlocal position
        scale, dims, sign = 1.0, {}, 1
        while position < len(tokens) and tokens[position] != ")":
            token = tokens[position]
            position += 1
            if token in "* ":
                continue
            if token == "/":
                sign = -1
                continue
            if token == "sqrt(":
                inner_scale, inner = product()
                position += 1  # ")"
                value, factor_dims = math.sqrt(inner_scale), {k: v / 2 for k, v in inner.items()}
            else:
                value, base = SYMBOLS[token]
                factor_dims = {k: Fraction(v) for k, v in base.items()}
            power = Fraction(1)
            if position < len(tokens) and tokens[position].startswith("^"):
                power = Fraction(tokens[position][1:])
                position += 1
            scale *= value ** float(sign * power)
            for k, v in factor_dims.items():
                dims[k] = dims.get(k, Fraction(0)) + sign * power * v
            sign = 1
        return scale, {k: v for k, v in dims.items() if v != 0}

    return product()


def expected(slope: float, deviation: dict[str, int]) -> dict[str, Fraction]:
    """The dimension of theta in AD(tau) = c theta tau^slope: the deviation's times s^-slope."""
    dims = {k: Fraction(v) for k, v in deviation.items()}
    dims["s"] = dims.get("s", Fraction(0)) - Fraction(slope).limit_denominator(4)
    return {k: v for k, v in dims.items() if v != 0}


def test_the_parser_reads_what_it_is_given():
    assert parse("u/s/sqrt(Hz)")[1] == {"u": 1, "s": Fraction(-1, 2)}
    assert parse("u*sqrt(Hz)/s")[1] == {"u": 1, "s": Fraction(-3, 2)}  # the old, wrong random-walk unit
    assert parse("deg/sqrt(h)")[0] == pytest.approx(math.pi / 180.0 / 60.0)


@pytest.mark.parametrize("term", [cls.name for cls in POWER_LAWS])
def test_plain_series_units_follow_from_the_definition(term):
    slope = next(cls.slope for cls in POWER_LAWS if cls.name == term)
    assert parse(unit_of(term, None, None))[1] == expected(slope, {"u": 1})
    assert unit_of(term, None, "V").replace("V", "u") == unit_of(term, None, None)


@pytest.mark.parametrize("kind, data_unit, deviation", [(GYRO, "deg/s", {"rad": 1, "s": -1}),
                                                         (ACCEL, "g", {"m": 1, "s": -2})])
@pytest.mark.parametrize("term", [cls.name for cls in POWER_LAWS])
def test_si_and_customary_units_follow_from_the_definition(kind, data_unit, deviation, term):
    slope = next(cls.slope for cls in POWER_LAWS if cls.name == term)
    si = unit_of(term, kind, data_unit)
    assert si == SI_UNITS[kind][term]
    si_scale, si_dims = parse(si)
    assert si_scale == 1.0 and si_dims == expected(slope, deviation)
    custom, factor = CUSTOMARY[kind][term]
    custom_scale, custom_dims = parse(custom)
    assert custom_dims == si_dims
    assert factor == pytest.approx(si_scale / custom_scale, rel=1e-12)  # value in customary = SI value * factor


def test_gauss_markov_and_sinusoid_rows_of_a_plain_series():
    """sigma and amplitude in the data unit (their deviation's), T in s, the frequency in Hz."""
    m = 2 ** np.arange(16)
    nu = WN(sigma2=1.0).theoretical_av(m) + AR1(phi=math.exp(-1 / 40.0), sigma2=0.05).theoretical_av(m) \
        + SIN(a2=2.0, f=0.01).theoretical_av(m)
    fit = fit_sensor_model(m, np.asarray(nu), (2**17 - 2 * m + 1) / m)
    rows = {row["Process"]: row for row in channel_rows("x", None, "V", fit, 10.0, 0.05)}
    assert {"AR1_1", "AR1_1.T", "SIN_1", "SIN_1.f"} <= set(rows)
    assert parse(rows["AR1_1"]["Unit"].replace("V", "u"))[1] == {"u": 1}
    assert parse(rows["SIN_1"]["Unit"].replace("V", "u"))[1] == {"u": 1}
    assert parse(rows["AR1_1.T"]["Unit"])[1] == {"s": 1}
    assert parse(rows["SIN_1.f"]["Unit"])[1] == {"s": -1}
    for process in ("QN", "WN", "FN", "RW", "DR"):
        slope = next(cls.slope for cls in POWER_LAWS if cls.name == process)
        assert parse(rows[process]["Unit"].replace("V", "u"))[1] == expected(slope, {"u": 1})
