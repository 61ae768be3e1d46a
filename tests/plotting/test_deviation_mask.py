"""``Deviation.plot(mask=...)``: the ITU-T mask's line is drawn through the mask's breakpoints."""

from __future__ import annotations

import numpy as np
import pytest

import avar
from avar.plotting.masks import CURVE_POINTS


@pytest.fixture(scope="module")
def phase():
    return np.cumsum(np.random.default_rng(4).standard_normal(20_000)) * 1e-10


def mask_lines(fig, name):
    return [line for line in fig.axes[0].lines if line.get_label() == name]


def test_tdev_mask_line_is_the_breakpoints(phase):
    fig = avar.tdev(phase, data_type="phase").plot(mask="G.8262 EEC option 1")
    (line,) = mask_lines(fig, "G.8262 EEC option 1 TDEV")
    # G.8262 Table 3: 3.2 ns to 25 s, 0.64 sqrt(tau) ns to 100 s, 6.4 ns to 1000 s
    assert line.get_xdata().tolist() == [0.1, 25.0, 25.0, 100.0, 100.0, 1000.0]
    np.testing.assert_allclose(line.get_ydata(), np.array([3.2, 3.2, 3.2, 6.4, 6.4, 6.4]) * 1e-9, rtol=1e-12)
    assert set(line.get_xdata()) == set(avar.MASKS["G.8262 EEC option 1 TDEV"].breakpoints())


def test_mtie_mask_with_a_curved_piece_and_an_open_end(phase):
    result = avar.mtie(phase, data_type="phase")
    fig = result.plot(mask=avar.MASKS["G.811 PRC MTIE"])
    (line,) = mask_lines(fig, "G.811 PRC MTIE")
    taus, limits = line.get_xdata(), line.get_ydata()
    # piece 1: 0.275e-3 tau + 0.025 us, a sum of two power laws: a curve from 0.1 s to 1000 s
    assert taus.size == 2 * CURVE_POINTS and taus[0] == 0.1 and taus[CURVE_POINTS - 1] == pytest.approx(1000.0)
    np.testing.assert_allclose(limits, [(0.275e-3 * t + 0.025) * 1e-6 if t <= 1000 * (1 + 1e-12)
                                        else (1e-5 * t + 0.29) * 1e-6 for t in taus], rtol=1e-12)
    assert taus[-1] == pytest.approx(max(result.taus.max(), 1e4))  # the open end: to the last tau


def test_wrong_statistic_or_name_is_refused(phase):
    with pytest.raises(ValueError, match="unknown mask 'G.999'"):
        avar.tdev(phase, data_type="phase").plot(mask="G.999")
    with pytest.raises(ValueError, match="limits MTIE, not TDEV"):
        avar.tdev(phase, data_type="phase").plot(mask="G.811 PRC MTIE")
    with pytest.raises(ValueError, match="for OADEV"):
        avar.oadev(phase, data_type="phase").plot(mask="G.811 PRC")
