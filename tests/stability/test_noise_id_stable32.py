"""Noise identification against Stable32's printed tables, and its rule on constructed cases.

The tables (tests/data/stable32, see its README) are Stable32 1.60's output on its
own PHASE.DAT: the AF, # and Alpha columns of every row, at every tau ("all taus").
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from powerlaw import powerlaw_phase

import avar
from avar.stability.noise_id import (
    MIN_ACF_POINTS,
    NOISE_ID_ESTIMATORS,
    b1_rule,
    b1_theory,
    identify_noise,
    phase_noise,
)

DATA = Path(__file__).resolve().parents[1] / "data" / "stable32"
TABLES = sorted(DATA.glob("phase_dat_*_all.txt"))


def _phase_dat() -> np.ndarray:
    return np.loadtxt(DATA / "PHASE.DAT")


def _agreement(table: Path) -> tuple[int, int, list]:
    estimator = table.name.split("_")[2]
    rows = np.loadtxt(table, dtype=np.int64)
    res = getattr(avar, estimator)(_phase_dat(), data_type="phase", taus=rows[:, 0].astype(float))
    np.testing.assert_array_equal(res.averaging_factors, rows[:, 0])
    np.testing.assert_array_equal(res.n, rows[:, 1])  # the same levels: Stable32's "#"
    wrong = [(int(m), int(want), int(got)) for m, want, got in zip(rows[:, 0], rows[:, 2], res.alpha) if want != got]
    return int(rows.shape[0]), len(wrong), wrong


def test_fixtures_are_stable32s_phase_dat():
    x = _phase_dat()
    assert x.size == 1001 and len(TABLES) == 7
    # the header of every table: Maximum = 4.356529e+00, Minimum = -4.707879e+00, Average = -5.403683e-01
    assert (round(x.max(), 6), round(x.min(), 6), round(x.mean(), 7)) == (4.356529, -4.707879, -0.5403683)


@pytest.mark.parametrize("table", TABLES, ids=lambda p: p.stem)
def test_alpha_of_every_row_as_stable32(table):
    rows, wrong, detail = _agreement(table)
    assert wrong == 0, detail


def test_alpha_agrees_with_stable32_on_99_percent_of_all_rows():
    rows = wrong = 0
    for table in TABLES:
        n, bad, _ = _agreement(table)
        rows, wrong = rows + n, wrong + bad
    assert rows == 991
    assert wrong <= 0.01 * rows, (wrong, rows)


def test_octave_and_frequency_paths_give_the_table_values():
    # the octave grid of phase data, and the same data as frequency (the pyramid's moments
    # for ADEV/HDEV): the same alpha as the all-tau table at the shared factors
    x = _phase_dat()
    for table in TABLES:
        estimator = table.name.split("_")[2]
        rows = np.loadtxt(table, dtype=np.int64)
        want = dict(zip(rows[:, 0].tolist(), rows[:, 2].tolist()))
        for data, data_type in ((x, "phase"), (np.diff(x), "freq")):
            res = getattr(avar, estimator)(data, data_type=data_type)
            shared = [m in want for m in res.averaging_factors.tolist()]
            assert sum(shared) >= 7
            got = res.alpha[shared].tolist()
            assert got == [want[m] for m in res.averaging_factors[shared].tolist()], (estimator, data_type)


def test_b1_rule_thresholds():
    # ADEV and HDEV: B1 while n >= 8 terms; theory sample size n + 1 (= K for ADEV)
    assert b1_rule("adev", 1001, 111, 9) == (True, 9)
    assert b1_rule("adev", 1001, 113, 8) == (False, 8)
    assert b1_rule("hdev", 1001, 99, 10) == (True, 9)
    assert b1_rule("hdev", 1001, 101, 9) == (False, 8)
    # overlapping estimators: K >= 8 averages; theory sample size n + 1 ~ N
    assert b1_rule("oadev", 1001, 125, 8) == (True, 1001 - 250 + 1)
    assert b1_rule("mdev", 1001, 127, 7) == (False, 1001 - 381 + 2)
    # TOTDEV: K >= 4
    assert b1_rule("totdev", 1001, 250, 4) == (True, 1000)
    assert b1_rule("totdev", 1001, 251, 3) == (False, 1000)
    # a plain dmax (no estimator): B1 of the K averages wherever K >= 3
    assert b1_rule(None, 1001, 300, 3) == (True, 3)
    assert b1_rule(None, 1001, 400, 2) == (False, 2)


def test_noise_rules_are_the_lag1_dmax():
    assert {name: int(rule) for name, rule in NOISE_ID_ESTIMATORS.items()} == {
        "adev": 2, "oadev": 2, "mdev": 2, "tdev": 2, "totdev": 2, "hdev": 3, "ohdev": 3}
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
    # constructed: white FM, then a level with too few ADEV terms (7) holds it, even though
    # B1 of its 8 averages alone would say otherwise
    x = _phase_dat()
    direct = phase_noise(x, np.array([115]), 2)  # a plain dmax: B1 of the 8 averages
    assert direct[0] == 0
    got = identify_noise(x, [111, 115], "adev")
    assert got.tolist() == [1, 1]  # 111: 9 averages, B1 says flicker PM; 115 holds it
    # the B1 theory: with n + 1 = K the ADEV boundary between FM and PM is higher than
    # with n + 1 ~ N (overlapping), which moves m = 75 of PHASE.DAT from PM to white FM
    k = 13
    adev_boundary = np.sqrt(b1_theory(k, -1) * b1_theory(k, -2))
    oadev_boundary = np.sqrt(b1_theory(852, -1) * b1_theory(852, -2))
    assert oadev_boundary < 0.831 < adev_boundary
    assert identify_noise(x, [75], "adev")[0] == 1 and identify_noise(x, [75], "oadev")[0] == 0
