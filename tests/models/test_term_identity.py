"""Each process class describes its term once, and the description is consistent with its theory.

The estimators read a term's variance scale, shape, Allan variance per unit
scale, IEEE 952 slope and coefficient off the class (avar.models.base.Process);
these tests hold them to the closed forms of ``theoretical_av`` and to the
``from_continuous`` constructors.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from avar.models import AR1, DR, FN, QN, RW, SIN, WN
from avar.models.base import process_classes

POWER_LAWS = (QN, WN, FN, RW, DR)
INSTANCES = [QN(q2=0.3), WN(sigma2=2.0), FN(b2=0.7), RW(gamma2=1e-3), DR(omega=-0.2),
             AR1(phi=0.93, sigma2=0.4), SIN(a2=0.5, f=0.013)]


@pytest.mark.parametrize("process", INSTANCES, ids=repr)
def test_scale_times_unit_av_is_the_theoretical_av(process):
    m = np.array([1, 2, 3, 7, 64, 1000, 4096])
    np.testing.assert_allclose(process.scale * type(process).unit_av(m.astype(float), process.shape),
                               process.theoretical_av(m), rtol=1e-12, atol=1e-300)


def test_scale_and_shape_are_the_declared_fields():
    assert [(p.scale, p.shape) for p in INSTANCES] == [
        (0.3, None), (2.0, None), (0.7, None), (1e-3, None), (0.2 * 0.2, None), (0.4, 0.93), (0.5, 0.013)]
    for process in INSTANCES:
        names = [f.name for f in dataclasses.fields(process)]
        assert process.scale_field in names and (process.shape_field is None or process.shape_field in names)


@pytest.mark.parametrize("cls", POWER_LAWS, ids=lambda cls: cls.name)
def test_the_ieee_law_is_the_slope_and_coefficient(cls):
    tau = np.geomspace(1e-3, 1e4, 15)
    np.testing.assert_allclose(cls.ieee_av(tau), (cls.ad_coefficient * tau**cls.slope) ** 2, rtol=1e-14)
    # the per-sample Allan variance tends to the law at large m (tau = m at 1 Hz)
    m = np.array([2.0**20])
    assert cls.unit_av(m) == pytest.approx(cls.ieee_av(m), rel=1e-6)


@pytest.mark.parametrize("cls", POWER_LAWS, ids=lambda cls: cls.name)
@pytest.mark.parametrize("freq", [1.0, 100.0, 0.25])
def test_the_coefficient_inverts_from_continuous(cls, freq):
    process = cls.from_continuous(0.37, freq)
    assert cls.coefficient(process.scale, freq) == pytest.approx(0.37, rel=1e-14)
    assert cls.coefficient_label.split(" [")[0] in {"Q", "sigma", "B", "gamma", "omega"}


def test_only_the_power_laws_have_a_slope_and_only_the_shaped_terms_a_shape():
    classes = process_classes()
    assert {name for name, cls in classes.items() if cls.slope is not None} >= {"DR", "FN", "QN", "RW", "WN"}
    assert [cls.name for cls in sorted(POWER_LAWS, key=lambda cls: cls.slope)] == ["QN", "WN", "FN", "RW", "DR"]
    assert {name for name, cls in classes.items() if cls.shape_field is not None} >= {"AR1", "SIN"}
    assert AR1.slope is None and SIN.slope is None and WN.shape_field is None
    with pytest.raises(NotImplementedError):
        AR1.ieee_av(np.ones(2))
    assert math.isclose(FN.ad_coefficient, 0.664, rel_tol=1e-3)
