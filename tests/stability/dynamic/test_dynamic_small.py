"""The dynamic deviations' NumPy phase (:func:`avar.stability.dynamic.small.twin_phase_parts`)
against the compiled phase the window kernel reads otherwise: the same bits."""

from __future__ import annotations

import numpy as np
import pytest

from avar._kernels.classic.phase import detrended_phase
from avar.stability.classic.core import phase_line, phase_parts
from avar.stability.dynamic import small
from avar.stability.shared.inputs import check_data
from avar.stability.shared.registry import CLASSIC

RNG = np.random.default_rng(41)
N = 5000
WHITE = RNG.standard_normal(N)
#: Frequency far above its noise (the centre's rounding errors fill ``lo``) and a random-walk phase.
DATA = {"freq": WHITE * 1e-3 + 1e3, "phase": np.cumsum(np.cumsum(WHITE)) * 1e-6 + 7.0}


@pytest.mark.parametrize("data_type", ["freq", "phase"])
@pytest.mark.parametrize("block", [1000, 777, 1 << 16])
def test_detrended_phase_is_the_kernels_bit_for_bit(data_type, block):
    """Kinds 0 and 1 (the phase) and 2 (its running sum), in one block and in several (the second
    pass starts each block from the earlier blocks' double-double sum)."""
    kind = int(data_type == "phase")
    line = phase_line(DATA[data_type], data_type, "ohdev")  # (a drift slope for the Hadamard family)
    hi = np.empty(line.count + 1)
    lo = np.empty(line.count + 1, dtype=np.float32)
    detrended_phase(line.filled, np.zeros(1, dtype=np.float32), kind, line.centre, line.slope, line.scale, hi, lo, block)
    twin = small.detrended_phase(line.filled, None, kind, line.centre, line.slope, line.scale, block)
    assert np.array_equal(twin.hi, hi) and np.array_equal(twin.lo, lo)
    assert np.count_nonzero(lo) > N // 2  # the compensation is exercised
    running_hi = np.empty(line.count + 2)
    running_lo = np.empty(line.count + 2, dtype=np.float32)
    centre = float(np.mean(hi))
    detrended_phase(hi, lo, 2, centre, 0.0, 1.0, running_hi, running_lo, block)
    running = small.detrended_phase(hi, lo, 2, centre, 0.0, 1.0, block)
    assert np.array_equal(running.hi, running_hi) and np.array_equal(running.lo, running_lo)


@pytest.mark.parametrize("statistic", CLASSIC)
@pytest.mark.parametrize("data_type", ["freq", "phase"])
def test_twin_phase_parts_are_phase_parts(statistic, data_type):
    """Every classic statistic's phase (with gaps): hi, lo, scale, gap mode and prefix count."""
    data = DATA[data_type].copy()
    data[[5, 6, 700]] = np.nan
    values, scanned = check_data(data, data_type, "omit")
    compiled = phase_parts(values, data_type, statistic, scanned)
    twin = small.twin_phase_parts(values, data_type, statistic, scanned)
    assert np.array_equal(twin.hi, compiled.hi) and np.array_equal(twin.lo, compiled.lo)
    assert (twin.scale, twin.mode) == (compiled.scale, compiled.mode) == (twin.scale, 1 if data_type == "phase" else 2)
    assert np.array_equal(twin.bad, compiled.bad)
