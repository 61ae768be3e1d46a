"""OADEV of long gap-free frequency records at the octave factors: the "mo" sweep and ADEV's
pyramid moments (:func:`avar.stability.classic.core.oadev_by_sweep`) against the phase path."""

from __future__ import annotations

import numpy as np
import pytest

import avar
from avar._kernels.runtime.paths import forced
from avar.stability.classic import core

N = core.SWEEP_SAMPLES + 5


def _record(kind: str) -> np.ndarray:
    w = np.random.default_rng(11).standard_normal(N)
    t = np.arange(N, dtype=np.float64)
    return {"white fm": w * 1e-11, "offset": 1e6 + w, "rw fm": np.cumsum(w) * 1e-3,
            "drift": w + 1e-3 * t, "flicker-ish": np.cumsum(w) / np.sqrt(1.0 + t)}[kind]


@pytest.mark.parametrize("kind", ["white fm", "offset", "rw fm", "drift", "flicker-ish"])
def test_the_sweep_equals_the_phase_path(kind, monkeypatch):
    y = _record(kind)
    calls = []
    sweep = core.oadev_by_sweep
    monkeypatch.setattr(core, "oadev_by_sweep", lambda *a: calls.append(1) or sweep(*a))
    with forced("compiled"):  # the sweep's kernels, compiled or not
        fast = avar.oadev(y)
        assert calls, "the record did not take the sweep"
        monkeypatch.setattr(core, "SWEEP_SAMPLES", 1 << 40)
        plain = avar.oadev(y)
    assert len(calls) == 1
    np.testing.assert_array_equal(fast.n, plain.n)
    np.testing.assert_allclose(fast.variance, plain.variance, rtol=1e-12, atol=0)
    np.testing.assert_array_equal(fast.alpha, plain.alpha)
    np.testing.assert_allclose(fast.edf, plain.edf, rtol=1e-12)


def test_cold_sweep_kernels_leave_the_phase_path(monkeypatch):
    """While the sweep's kernels are not compiled (auto mode), a long record takes the phase path,
    whose kernels compile in about half the time; forced, the sweep."""
    y = _record("white fm")
    calls = []
    monkeypatch.setattr(core, "oadev_by_sweep", lambda *a: calls.append(1))
    monkeypatch.setattr(core, "compiled", lambda kernels: False)
    with forced("auto"):
        assert core._sweeps("oadev", y, np.array([1, 2, 4]), "freq", core.scan(y)) is False
    with forced("compiled"):
        assert core._sweeps("oadev", y, np.array([1, 2, 4]), "freq", core.scan(y)) is True
    assert not calls


def test_the_sweep_equals_a_plain_loop():
    """sum_i (x_{i+2m} - 2 x_{i+m} + x_i)^2 / (2 m^2 (N + 1 - 2m)) over the phase x = cumsum(y),
    in exact rational arithmetic at the first and a far level."""
    from fractions import Fraction

    y = np.random.default_rng(3).integers(-50, 50, N).astype(np.float64)
    with forced("compiled"):
        res = avar.oadev(y)
    x = [Fraction(0)]
    for v in y.tolist():
        x.append(x[-1] + Fraction(int(v)))
    for level in (0, res.averaging_factors.size - 1):
        m = int(res.averaging_factors[level])
        total = sum((x[i + 2 * m] - 2 * x[i + m] + x[i]) ** 2 for i in range(len(x) - 2 * m))
        exact = total / (2 * m * m * (len(x) - 2 * m))
        assert abs(res.variance[level] / float(exact) - 1.0) < 1e-13
