"""ITU-T wander masks: the transcribed tables, and checks of MTIE / TDEV results against them."""

import numpy as np
import pytest
from matplotlib.figure import Figure

import avar
from avar.stability.time_error.masks import MASKS, Mask, MaskPiece

NS, US = 1e-9, 1e-6

#: The limits each Recommendation's table prints at the ends of its pieces (tau s, limit s).
PRINTED = {
    "G.811 PRC MTIE": [(1000, 0.3 * US)],
    "G.811 PRC TDEV": [(100, 3 * NS), (1000, 30 * NS), (1e4, 30 * NS)],
    "G.8272 PRTC-A MTIE": [(273, 0.1 * US), (1e5, 0.1 * US)],
    "G.8272 PRTC-B MTIE": [(54.5, 0.04 * US), (1e5, 0.04 * US)],
    "G.8272 PRTC-B TDEV": [(100, 1 * NS), (500, 5 * NS), (1e5, 5 * NS)],
    "G.8262 EEC option 1 MTIE": [(0.5, 40 * NS), (1, 40 * NS)],
    "G.8262 EEC option 1 TDEV": [(25, 3.2 * NS), (100, 6.4 * NS), (1000, 6.4 * NS)],
    "G.8262 EEC option 2 MTIE": [(1, 20 * NS), (1000, 60 * NS)],
    "G.8262 EEC option 2 TDEV": [(10, 2 * NS), (40, 2 * NS), (1e4, 10 * NS)],
}


def test_the_printed_values_at_the_ends_of_the_pieces():
    for name, points in PRINTED.items():
        taus, limits = np.array(points).T
        np.testing.assert_allclose(MASKS[name].limit(taus), limits, rtol=0.011, err_msg=name)


@pytest.mark.parametrize("name", list(MASKS))
def test_every_mask_is_continuous_at_its_breakpoints(name):
    """The Recommendations' pieces meet to 1.5 % (their coefficients are rounded; 3.2 / sqrt(2.5) =
    2.02 meets 2 at 2.5 s, the widest gap): a mistyped coefficient or power breaks this."""
    mask = MASKS[name]
    for left, right in zip(mask.pieces, mask.pieces[1:]):
        assert left.high == right.low
        tau = np.array([left.high])
        assert left.limit(tau)[0] == pytest.approx(right.limit(tau)[0], rel=0.015), (name, left.high)
    assert mask.statistic in ("mtie", "tdev") and mask.source.startswith("ITU-T G.")
    assert np.all(np.diff(mask.breakpoints()) > 0)


def test_the_limits_grow_as_the_tables_state():
    eec1 = MASKS["G.8262 EEC option 1 MTIE"]
    assert eec1.limit([10.0])[0] == pytest.approx(40 * 10**0.1 * NS, rel=1e-15)
    assert eec1.limit([500.0])[0] == pytest.approx(25.25 * 500**0.2 * NS, rel=1e-15)
    assert MASKS["G.811 PRC MTIE"].limit([5e3])[0] == pytest.approx((1e-5 * 5e3 + 0.29) * US, rel=1e-15)
    assert np.isnan(eec1.limit([0.05, 2000.0])).all()  # outside 0.1 .. 1000 s


def test_a_quiet_clock_passes_and_a_wandering_one_fails():
    rng = np.random.default_rng(1)
    quiet = rng.standard_normal(5000) * 1e-9  # 1 ns white PM
    check = avar.mask_check(avar.tdev(quiet, data_type="phase"), "G.8262 EEC option 1 TDEV")
    assert check.passed and bool(np.all(check.margin > 1))
    wander = np.cumsum(rng.standard_normal(5000)) * 1e-7  # random walk of 100 ns steps
    result = avar.mtie(wander, data_type="phase")
    check = avar.mask_check(result, "G.8262 EEC option 1 MTIE")
    assert not check.passed
    inside = (result.taus > 0.1) & (result.taus <= 1000)
    np.testing.assert_array_equal(check.taus, result.taus[inside])
    np.testing.assert_array_equal(check.measured, result.deviation[inside])
    np.testing.assert_array_equal(check.margin, check.limit / check.measured)
    np.testing.assert_array_equal(check.passes, check.measured <= check.limit)
    assert "fails at" in repr(check)
    assert list(check.summary().columns) == ["Tau (s)", "Measured (s)", "Limit (s)", "Margin", "Pass"]
    assert isinstance(check.plot(), Figure)


def test_a_custom_mask():
    flat = Mask("flat 10 ns", "tdev", (MaskPiece(0.0, np.inf, (10 * NS,), (0.0,)),), "a test")
    x = np.random.default_rng(2).standard_normal(2000) * 20e-9
    check = avar.mask_check(avar.tdev(x, data_type="phase"), flat)
    assert check.passes[0] == bool(check.measured[0] <= 10 * NS)


def test_errors_name_what_is_wrong():
    x = np.random.default_rng(3).standard_normal(1000) * 1e-9
    with pytest.raises(ValueError, match="unknown mask 'G.8262'"):
        avar.mask_check(avar.tdev(x, data_type="phase"), "G.8262")
    with pytest.raises(ValueError, match="limits MTIE, but result is TDEV"):
        avar.mask_check(avar.tdev(x, data_type="phase"), "G.8262 EEC option 1 MTIE")
    with pytest.raises(ValueError, match="no tau of the result"):
        avar.mask_check(avar.tdev(x, data_type="phase", rate=1e5), "G.8262 EEC option 2 TDEV")
    with pytest.raises(TypeError, match="MTIE or TDEV Deviation"):
        avar.mask_check(np.zeros(3), "G.811 PRC TDEV")
