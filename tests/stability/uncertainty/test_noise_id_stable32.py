"""Noise identification against Stable32's printed tables, and its rule on constructed cases.

The tables (tests/data/stable32, see its README) are Stable32's output at every tau
("all taus") on its own PHASE.DAT (phase data) and on a 10,000-point flicker FM record
(frequency data, tau0 = 42 s): the AF, # and Alpha columns of every row.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import avar
from avar.stability.uncertainty.noise_id import (
    MIN_ACF_POINTS,
    NOISE_ID_ESTIMATORS,
    b1_rule,
    b1_theory,
    identify_noise,
    phase_noise,
)
from tests._support.paths import STABLE32
from tests._support.powerlaw import powerlaw_phase

DATA = STABLE32
TABLES = sorted(DATA.glob("*_all.txt"))
PINK_TAU0 = 42.0


def _phase_dat() -> np.ndarray:
    return np.loadtxt(DATA / "PHASE.DAT")


def _deviation(table: Path, taus: object = None):
    """The table's statistic of its data, at the table's factors (or ``taus``)."""
    estimator = table.name.split("_")[-2]
    rows = np.loadtxt(table, dtype=np.int64)
    if table.name.startswith("pink"):
        data, kind, tau0 = np.loadtxt(DATA / "pink_frequency.txt"), "freq", PINK_TAU0
    else:
        data, kind, tau0 = _phase_dat(), "phase", 1.0
    grid = rows[:, 0] * tau0 if taus is None else taus
    return getattr(avar, estimator)(data, rate=1.0 / tau0, data_type=kind, taus=grid), rows


def _agreement(table: Path) -> tuple[int, int, list]:
    res, rows = _deviation(table)
    np.testing.assert_array_equal(res.averaging_factors, rows[:, 0])
    np.testing.assert_array_equal(res.n, rows[:, 1])  # the same levels: Stable32's "#"
    wrong = [(int(m), int(want), int(got)) for m, want, got in zip(rows[:, 0], rows[:, 2], res.alpha) if want != got]
    return int(rows.shape[0]), len(wrong), wrong


def test_fixtures_are_stable32s_phase_dat():
    x = _phase_dat()
    assert x.size == 1001 and len(TABLES) == 14
    # the header of every table: Maximum = 4.356529e+00, Minimum = -4.707879e+00, Average = -5.403683e-01
    assert (round(x.max(), 6), round(x.min(), 6), round(x.mean(), 7)) == (4.356529, -4.707879, -0.5403683)
    y = np.loadtxt(DATA / "pink_frequency.txt")
    # Maximum = 1.200570e-06, Minimum = -8.447800e-07, Average = 1.228155e-07
    assert y.size == 10000 and (y.max(), y.min(), round(y.mean(), 13)) == (1.20057e-06, -8.4478e-07, 1.228155e-07)


@pytest.mark.parametrize("table", TABLES, ids=lambda p: p.stem)
def test_alpha_of_the_rows_as_stable32(table):
    rows, wrong, detail = _agreement(table)
    # every row but one: PHASE.DAT's ADEV at m = 105 (9 averages), where the rule
    # that fits every other row (B1 from 10 averages) holds alpha = 1 and Stable32 prints 0
    assert wrong == (1 if table.name == "phase_dat_adev_all.txt" else 0), detail


def test_alpha_agrees_with_stable32_on_99_percent_of_all_rows():
    rows = wrong = 0
    for table in TABLES:
        n, bad, _ = _agreement(table)
        rows, wrong = rows + n, wrong + bad
    assert rows == 2416
    assert wrong <= 0.01 * rows, (wrong, rows)


def test_octave_and_frequency_paths_give_the_table_values():
    # the octave grid (the pyramid's moments for ADEV/HDEV of frequency data, HDEV with its
    # drift removed and given back), and PHASE.DAT as frequency data: the table's alpha
    x = _phase_dat()
    for table in TABLES:
        res, rows = _deviation(table, taus="octave")
        want = dict(zip(rows[:, 0].tolist(), rows[:, 2].tolist()))
        runs = [res]
        if table.name.startswith("phase"):
            runs.append(getattr(avar, table.name.split("_")[-2])(np.diff(x), data_type="freq"))
        for got in runs:
            shared = [m in want for m in got.averaging_factors.tolist()]
            assert sum(shared) >= 7
            assert got.alpha[shared].tolist() == [want[m] for m in got.averaging_factors[shared].tolist()], table


def test_b1_rule_thresholds():
    # ADEV and HDEV: B1 while K >= 10 averages; theory sample size n (K - 1 for ADEV)
    assert b1_rule("adev", 1001, 100, 10) == (True, 9)
    assert b1_rule("adev", 1001, 101, 9) == (False, 8)
    assert b1_rule("hdev", 1001, 99, 10) == (True, 8)
    assert b1_rule("hdev", 1001, 101, 9) == (False, 7)
    # overlapping estimators: K >= 8 averages; theory sample size n ~ N
    assert b1_rule("oadev", 1001, 125, 8) == (True, 1001 - 250)
    assert b1_rule("mdev", 1001, 127, 7) == (False, 1001 - 381 + 1)
    # TOTDEV: K >= 4
    assert b1_rule("totdev", 1001, 250, 4) == (True, 999)
    assert b1_rule("totdev", 1001, 251, 3) == (False, 999)
    # a plain dmax (no estimator): B1 of the K averages wherever K >= 3
    assert b1_rule(None, 1001, 300, 3) == (True, 3)
    assert b1_rule(None, 1001, 400, 2) == (False, 2)


def test_noise_rules_are_the_lag1_dmax():
    assert {name: int(rule) for name, rule in NOISE_ID_ESTIMATORS.items()} == {
        "adev": 2, "oadev": 2, "mdev": 2, "tdev": 2, "totdev": 2, "hdev": 3, "ohdev": 3, "mhdev": 3, "htdev": 3,
        "mtotdev": 2, "ttotdev": 2, "htotdev": 2}
    assert all(rule.estimator == name for name, rule in NOISE_ID_ESTIMATORS.items())


def test_lag1_down_to_30_averages_then_b1():
    # random-walk FM: the lag-1 method finds it at K = 30 averages; at K = 29 the overlapping
    # estimators' B1 (theory for n + 1 ~ N samples) reads it as flicker FM, ADEV's as RW FM
    n = 2**14 + 1
    at30, at29 = (n - 1) // 30, (n - 1) // 29 - 1  # K = 30 and 29 (pick m with K exact)
    assert (n - 1) // at30 == MIN_ACF_POINTS and (n - 1) // at29 == MIN_ACF_POINTS - 1
    lag1 = oadev_b1 = adev_b1 = 0
    for seed in range(10):
        x = powerlaw_phase(n, -2, 500 + seed)
        lag1 += identify_noise(x, [at30], "oadev")[0] == -2
        oadev_b1 += identify_noise(x, [at29], "oadev")[0] == -1
        adev_b1 += identify_noise(x, [at29], "adev")[0] == -2
    assert lag1 >= 9 and oadev_b1 >= 9 and adev_b1 >= 6, (lag1, oadev_b1, adev_b1)


def test_levels_past_b1_hold_the_previous_alpha():
    # a level with too few averages for ADEV's B1 (8) holds the previous level's alpha,
    # even though B1 of its 8 averages alone would say otherwise (Stable32: 1)
    x = _phase_dat()
    direct = phase_noise(x, np.array([115]), 2)  # a plain dmax: B1 of the 8 averages
    assert direct[0] == 0
    got = identify_noise(x, [99, 115], "adev")
    assert got.tolist() == [1, 1]  # 99: 10 averages, B1 says flicker PM; 115 holds it
    # the B1 theory: with n = K - 1 the ADEV boundary between FM and PM is higher than
    # with n ~ N (overlapping), which moves m = 75 of PHASE.DAT from PM to white FM
    adev_boundary = np.sqrt(b1_theory(12, -1) * b1_theory(12, -2))
    oadev_boundary = np.sqrt(b1_theory(851, -1) * b1_theory(851, -2))
    assert oadev_boundary < 0.831 < adev_boundary
    assert identify_noise(x, [75], "adev")[0] == 1 and identify_noise(x, [75], "oadev")[0] == 0


def test_totals_read_b1_with_their_own_term_count_down_to_6_averages():
    """Stable32's HTOTDEV of PHASE.DAT (octave) prints flicker PM at m = 128 and 256, where
    OHDEV's rule said white FM; on a 1253-point clock record its MTOTDEV, TTOTDEV and HTOTDEV
    columns (143 all-tau rows each) follow B1 with n = the statistic's own "#" while K >= 6."""
    from avar.stability.uncertainty.noise_id import b1_rule

    res = avar.htotdev(_phase_dat(), data_type="phase", taus="octave")
    assert res.alpha.tolist() == [0] * 7 + [1, 1]
    assert b1_rule("mtotdev", 1253, 201, 6) == (True, 1253 - 3 * 201 + 1)
    assert b1_rule("htotdev", 1253, 201, 6) == (True, 1253 - 3 * 201)
    assert b1_rule("ttotdev", 1253, 209, 5)[0] is False and b1_rule("totdev", 1253, 209, 5)[0] is True


def test_phase_data_keep_their_frequency_offset_as_in_stable32():
    # A caesium clock's phase at the factors where 30 to 77 averages remain: Stable32 reads white
    # FM (alpha 0) from the decimated phase less its mean; less its least-squares line (the rule
    # for phase integrated from frequency data) the same points read as white PM
    rows = np.loadtxt(DATA / "cs5071a_decimated.txt")
    for m in (7197, 10098, 14167):
        points = rows[rows[:, 0] == m, 2]
        assert points.size == 556_989 // m + 1
        assert identify_noise(points, [1], "oadev").tolist() == [0]
        assert identify_noise(points, [1], "oadev", from_frequency=True).tolist() == [2]
        # the whole path of a deviation: a phase record whose every m-th point is these
        full = np.interp(np.arange((points.size - 1) * m + 1) / m, np.arange(points.size), points)
        for estimator in ("oadev", "adev", "mdev", "ohdev", "totdev"):
            res = getattr(avar, estimator)(full, data_type="phase", taus=[float(m)])
            assert res.alpha.tolist() == [0], (estimator, m)
