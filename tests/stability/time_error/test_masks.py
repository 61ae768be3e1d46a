"""ITU-T wander masks: the transcribed tables, and checks of MTIE / TDEV results against them."""

import numpy as np
import pytest
from matplotlib.figure import Figure

import avar
from avar.stability.time_error.masks import MASKS, Mask, MaskPiece, find_mask

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
    # G.8261 (08/2013) Tables 4 and 5 as timetools 0.6.0 prints them: 250 ns to 2.5 s, 100 tau ns to
    # 20 s, 2000 ns to 2000 s, 433 tau^0.2 + 0.01 tau ns beyond; 12 ns to 17.14 s, 0.7 tau ns to
    # 100 s, 58 + 1.2 tau^0.5 + 0.0003 tau ns to 1e6 s
    "G.8261 SyncE option 1 network MTIE": [(1, 250 * NS), (2.5, 250 * NS), (20, 2000 * NS), (2000, 2000 * NS)],
    "G.8261 SyncE option 1 network TDEV": [(17.14, 12 * NS), (100, 70 * NS)],
}

#: Each new mask's every piece, at a point inside it, against the printed formula evaluated here.
INSIDE = {
    "G.8261 SyncE option 1 network MTIE": [(1.0, 250 * NS), (10.0, 100 * 10 * NS), (500.0, 2000 * NS),
                                           (1e5, (433 * 1e5**0.2 + 0.01 * 1e5) * NS)],
    "G.8261 SyncE option 1 network TDEV": [(5.0, 12 * NS), (50.0, 0.7 * 50 * NS),
                                           (1e4, (58 + 1.2 * 1e4**0.5 + 3e-4 * 1e4) * NS)],
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


#: The values (ns) Semtech's ToPTrace utility tabulates for the G.823/G.824 network limits
#: (Interface/Masks.cpp, 2015), tau (s) by tau: the masks must give every one to its printed digits.
_TAIL_TAUS = [5000, 1e4, 2e4, 5e4, 1e5, 2e5, 5e5, 1e6, 2e6, 5e6, 1e7, 2e7, 5e7, 1e8]
_TAIL_MTIE = [2428.384, 2832.045, 3338.296, 4269.484, 5330, 6973.864, 10974.229, 16862.588, 27883.043,
              59468.516, 110876.468, 212493.781, 515006.586, 1017238.04]
_TAIL_TDEV_TAUS = [200, 500, 1000, 2000, 5000, 1e4, 2e4, 5e4, 1e5, 2e5, 5e5, 1e6]
_TAIL_TDEV = [75.031, 84.983, 96.247, 112.266, 144.353, 181, 233.706, 341.328, 467.473, 654.656, 1056.528, 1558]
TABULATED = {
    "G.823 PDH network MTIE": ([7.3, 10, 20, 100, 1000, 2000, *_TAIL_TAUS],
                               [732, 1000, 2000, 2000, 2000, 2000, *_TAIL_MTIE]),
    "G.823 PDH network TDEV": ([10, 48, 100, *_TAIL_TDEV_TAUS], [34, 34, 70, *_TAIL_TDEV]),
    "G.823 PRC network MTIE": ([2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000, *_TAIL_TAUS],
                               [25.55, 26.375, 27.75, 30.5, 38.75, 52.5, 80, 162.5, 300, 310, 340, 390, 490,
                                790, 1290, 2290, 5290, 10290, 20290, 50290, 100290, 200290, 500290, 1000290]),
    "G.823 PRC network TDEV": ([10, 100, 1000, 1e4, 2e4, 5e4, 1e5, 2e5, 5e5, 1e6],
                               [3, 3, 30, 30, 33, 42, 57, 87, 177, 327]),
    "G.823 SEC network MTIE": ([2.5, 10, 20, 100, 1000, 2000, *_TAIL_TAUS],
                               [250, 1000, 2000, 2000, 2000, 2000, *_TAIL_MTIE]),
    "G.823 SEC network TDEV": ([10, 17.14, 100, *_TAIL_TDEV_TAUS], [12, 12, 70, *_TAIL_TDEV]),
    "G.823 SSU network MTIE": ([2.5, 10, 100, 200, 1000, 2000, *_TAIL_TAUS],
                               [25, 100, 1000, 2000, 2000, 2000, *_TAIL_MTIE]),
    "G.823 SSU network TDEV": ([4.3, 10, 100, *_TAIL_TDEV_TAUS], [3, 7, 70, *_TAIL_TDEV]),
    "G.824 DS1 network MTIE": ([2, 5, 10, 20, 50, 100, 200, 280, 500, 1000, 2000, *_TAIL_TAUS],
                               [305, 312.5, 325, 350, 425, 550, 800, 1000, 1002, 1007, 1017, 1047, 1097, 1197,
                                1497, 1997, 2997, 5997, 10997, 20997, 50997, 100997, 200997, 500997, 1000997]),
    "G.824 DS1 network TDEV": ([10, 100, 1000], [100, 316.23, 1000.007]),
}


@pytest.mark.parametrize("name", list(TABULATED))
def test_the_network_limits_give_every_tabulated_value(name):
    taus, values = TABULATED[name]
    assert len(taus) == len(values)
    # printed to 0.001 ns (7 digits at most): half a unit of the last digit
    np.testing.assert_allclose(MASKS[name].limit(taus) / NS, values, rtol=0, atol=0.0005 + 5e-7 * max(values),
                               err_msg=name)
    assert np.isnan(MASKS[name].limit([1.0])[0])  # the tabulated range starts at 1 s: open below, as every mask
    assert MASKS[name].taus[0] == 1.0 and "Semtech" in MASKS[name].source


def test_the_network_limits_agree_with_the_other_recommendations():
    taus = np.geomspace(1.01, 1e4, 400)
    np.testing.assert_allclose(MASKS["G.823 PRC network MTIE"].limit(taus), MASKS["G.811 PRC MTIE"].limit(taus),
                               rtol=1e-14)   # the network limit of a PRC interface is the PRC's own
    np.testing.assert_allclose(MASKS["G.823 PRC network TDEV"].limit(taus), MASKS["G.811 PRC TDEV"].limit(taus),
                               rtol=1e-14)
    taus = np.geomspace(1.01, 1e6, 400)
    for statistic in ("MTIE", "TDEV"):       # timetools' G.8261 tables and Semtech's G.823 SEC values
        np.testing.assert_allclose(MASKS[f"G.823 SEC network {statistic}"].limit(taus),
                                   MASKS[f"G.8261 SyncE option 1 network {statistic}"].limit(taus), rtol=1e-14)
    # SSU, SEC and PDH share the long-term limit: 2 us to 2000 s, then 433 tau^0.2 + 0.01 tau ns
    tail = np.geomspace(2001, 1e8, 50)
    limits = [MASKS[f"G.823 {kind} network MTIE"].limit(tail) for kind in ("SSU", "SEC", "PDH")]
    np.testing.assert_array_equal(limits[0], limits[1])
    np.testing.assert_array_equal(limits[0], limits[2])
    np.testing.assert_allclose(limits[0], (433 * tail**0.2 + 0.01 * tail) * NS, rtol=1e-14)


def test_interfaces_against_the_g823_and_g824_limits():
    """A quiet E1 sync interface (2 ns white PM) passes the SSU limits; the same interface with a
    frequency offset of 1e-9 (MTIE ~ tau ns) stays under the SSU's 10 tau ns to 200 s and fails once
    tau ns outgrows its 2 us plateau; the DS1 limit, 300 + 2.5 tau ns, holds it to 280 s."""
    rng = np.random.default_rng(823)
    quiet = rng.standard_normal(20_000) * 2e-9
    assert avar.mask_check(avar.tdev(quiet, data_type="phase"), "G.823 SSU network TDEV").passed
    assert avar.mask_check(avar.mtie(quiet, data_type="phase"), "G.823 SSU network MTIE").passed
    drifting = quiet + 1e-9 * np.arange(quiet.size)            # 1 ns/s: MTIE ~ tau ns
    check = avar.mask_check(avar.mtie(drifting, data_type="phase"), "G.823 SSU network MTIE")
    middle = (check.taus >= 10) & (check.taus <= 200)
    assert middle.any() and check.passes[middle].all()
    assert not check.passed and not check.passes[check.taus >= 4000].any()
    ds1 = avar.mask_check(avar.mtie(drifting, data_type="phase"), "G.824 DS1 network MTIE")
    assert ds1.passes[ds1.taus <= 280].all()                    # 300 + 2.5 tau ns > tau ns
    np.testing.assert_array_equal(ds1.passes, ds1.measured <= ds1.limit)


@pytest.mark.parametrize("name", list(INSIDE))
def test_a_point_inside_every_piece_of_the_new_masks(name):
    mask = MASKS[name]
    taus, limits = np.array(INSIDE[name]).T
    assert len(taus) == len(mask.pieces)
    for tau, piece in zip(taus, mask.pieces):  # one point in each piece
        assert piece.low < tau <= piece.high
    np.testing.assert_allclose(mask.limit(taus), limits, rtol=1e-14, err_msg=name)


def test_the_g8261_network_limit_in_numbers():
    mtie = MASKS["G.8261 SyncE option 1 network MTIE"]
    assert mtie.taus == (0.1, np.inf) and mtie.statistic == "mtie"
    np.testing.assert_array_equal(mtie.breakpoints(), [0.1, 2.5, 20, 2000, np.inf])
    # the last piece meets 2 us at 2000 s: 433 * 2000**0.2 + 20 = 2000.13 ns
    assert mtie.limit([2000.0 * (1 + 1e-12)])[0] == pytest.approx(2000.13 * NS, rel=1e-6)
    tdev = MASKS["G.8261 SyncE option 1 network TDEV"]
    np.testing.assert_array_equal(tdev.breakpoints(), [0.1, 17.14, 100, 1e6])
    assert tdev.limit([1e6])[0] == pytest.approx(1558 * NS, rel=1e-12)   # 58 + 1200 + 300 ns
    assert np.isnan(tdev.limit([2e6])[0])
    for mask in (mtie, tdev):
        assert mask.source.startswith("ITU-T G.8261/Y.1361 (08/2013)") and "timetools" in mask.source
    assert find_mask("G.8261 SyncE option 1 network", "tdev") is tdev


def test_a_network_interface_against_the_g8261_limit():
    """Wander of a SyncE interface: 5 ns white PM passes the option 1 network limit; a random walk
    of 20 ns steps a second passes at short taus and fails once its MTIE outgrows 2 us."""
    rng = np.random.default_rng(41)
    quiet = rng.standard_normal(20_000) * 5e-9
    for statistic in ("mtie", "tdev"):
        result = getattr(avar, statistic)(quiet, data_type="phase")
        check = avar.mask_check(result, f"G.8261 SyncE option 1 network {statistic.upper()}")
        assert check.passed, statistic
    walk = np.cumsum(rng.standard_normal(20_000)) * 20e-9
    check = avar.mask_check(avar.mtie(walk, data_type="phase"), "G.8261 SyncE option 1 network MTIE")
    assert not check.passed
    assert check.passes[check.taus <= 2.5].all() and not check.passes[check.taus >= 1000].any()
    np.testing.assert_array_equal(check.passes, check.measured <= check.limit)


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
