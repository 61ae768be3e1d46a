"""Tests of avar.fit.terms: a fitted term refers to its process class, and any model becomes components."""

from __future__ import annotations

import numpy as np
import pytest

from avar.fit.terms import POWER_LAWS, SHAPED, Component, basis, components_of, process_class
from avar.models import AR1, DR, QN, RW, SIN, WN


def test_a_component_is_its_class_with_values():
    c = Component("AR1", 0.4, 0.93)
    assert c.process is AR1
    m = np.array([1, 4, 16])
    np.testing.assert_allclose(c.av(m), AR1(phi=0.93, sigma2=0.4).theoretical_av(m), rtol=1e-12)
    np.testing.assert_array_equal(basis("RW", None, m), RW.unit_av(m.astype(float)))
    with pytest.raises(ValueError, match="unknown term 'XX'"):
        Component("XX", 1.0)
    with pytest.raises(ValueError, match="unknown term 'wn'"):
        process_class("wn")


def test_components_of_any_model_description():
    model = QN(q2=0.5) + WN(sigma2=1.0) + DR(omega=-0.1) + SIN(a2=0.2, f=0.05)
    components = components_of(model)
    assert components == (Component("QN", 0.5), Component("WN", 1.0), Component("DR", 0.1 * 0.1),
                          Component("SIN", 0.2, 0.05))
    assert components_of(list(model.components)) == components
    assert components_of(components) == components
    assert components_of(WN(sigma2=3.0)) == (Component("WN", 3.0),)
    with pytest.raises(TypeError, match="processes or components"):
        components_of(["WN"])


def test_the_term_orders_come_from_the_classes():
    assert [cls.name for cls in POWER_LAWS] == ["QN", "WN", "FN", "RW", "DR"]
    assert all(cls.shape_field is None for cls in POWER_LAWS) and all(cls.shape_field for cls in SHAPED)
