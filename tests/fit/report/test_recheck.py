"""``NoiseReport.recheck`` and ``avar report --recheck``: the fitted model simulated and fitted again.

A short log keeps the suite fast (three replicates); the ratios are held to the report's own
standard errors, the coverage to its definition (share of replicates whose interval holds the
fitted value). The 20-replicate coverage of N and K on a 2-hour log is
benchmarks/bench_simulate_recheck.py.
"""

from __future__ import annotations

import io
import math

import numpy as np
import pandas as pd
import pytest

import avar
from avar.fit.report.recheck import RECHECK_COLUMNS, VALUE_COLUMNS, _compare, recheck
from tests._support.cli_runner import cli

RATE = 100.0
Z95 = 1.959964


@pytest.fixture(scope="module")
def report():
    model = avar.WN.from_continuous(1e-3, RATE) + avar.RW.from_continuous(3e-4, RATE)
    x = model.simulate(40_000, seed=1)
    return avar.noise_report(x, gyro_units="rad/s", rate=RATE)


@pytest.fixture(scope="module")
def check(report):
    return recheck(report, 3, seed=2, progress=False)


def test_table_has_a_row_per_fitted_term(report, check):
    assert isinstance(check, avar.Recheck)
    table = report.table
    fitted = table[(table["Status"] == "present") & table["Process"].isin(["QN", "WN", "FN", "RW", "DR"])]
    assert list(check.table.columns) == RECHECK_COLUMNS
    assert check.table["Process"].tolist() == fitted["Process"].tolist() == ["WN", "RW"]
    np.testing.assert_array_equal(check.table["Fitted"], fitted["Value"].astype(float))
    assert (check.table["Replicates"] == 3).all() and (check.table["Resolved"] <= 3).all()
    assert (check.replicates, check.n_samples, check.rate, check.confidence) == (3, 40_000, RATE, 0.95)
    assert list(check.values.columns) == VALUE_COLUMNS and len(check.values) == 3 * 2


def test_ratios_are_near_one_within_the_reports_errors(report, check):
    for process in ("WN", "RW"):
        row = report.table.set_index("Process").loc[process]
        spread = (math.log(row["Upper"]) - math.log(row["Lower"])) / (2 * Z95)  # relative standard error
        mine = check.values[check.values["Process"] == process]
        ratios = mine.loc[mine["Status"] == "present", "Ratio"]
        assert len(ratios) >= 2
        assert np.all(np.abs(np.log(ratios)) < 4 * spread), (process, ratios.tolist(), spread)
        summary = check.table.set_index("Process").loc[process]
        assert summary["Median ratio"] == pytest.approx(float(np.median(ratios)), rel=1e-12)
        assert summary["Coverage"] == pytest.approx(mine["Covered"].mean(), rel=1e-12)
    wn = check.values[check.values["Process"] == "WN"]
    np.testing.assert_allclose(wn["Ratio"] * report.value("x", "WN"), wn["Value"], rtol=1e-12)
    covered = (wn["Lower"] <= report.value("x", "WN")) & (report.value("x", "WN") <= wn["Upper"])
    assert (covered == wn["Covered"]).all()  # coverage by its definition, replicate by replicate


def test_same_seed_same_recheck_and_summary_pools_the_axes(report, check):
    again = recheck(report, 3, seed=2, progress=False)
    pd.testing.assert_frame_equal(check.table, again.table)
    other = recheck(report, 3, seed=3, progress=False)
    assert not check.values["Value"].equals(other.values["Value"])
    summary = check.summary()
    assert summary[["Sensor", "Process", "Axes", "Draws"]].values.tolist() == [
        ["Gyroscope", "WN", 1, 3], ["Gyroscope", "RW", 1, 3]]
    assert "Recheck of x: 3 log(s) of 40000 samples at 100 Hz" in str(check)
    with pytest.raises(ValueError, match="replicates"):
        recheck(report, 0)


def test_compare_counts_bounds_and_absences():
    present = {"Status": "present", "Value": 2.0, "Lower": 1.5, "Upper": 3.0}
    assert _compare(2.5, present) == ("present", 2.0, 1.5, 3.0, 0.8, True)
    assert _compare(1.0, present)[-1] is False
    bound = {"Status": "bound", "Value": pd.NA, "Lower": 0.0, "Upper": 3.0}
    status, value, _, upper, ratio, covered = _compare(2.5, bound)
    assert (status, upper, covered) == ("bound", 3.0, True) and math.isnan(value) and math.isnan(ratio)
    assert _compare(3.5, bound)[-1] is False
    assert _compare(2.5, None)[0] == "absent" and _compare(2.5, None)[-1] is False
    assert _compare(2.5, {"Status": "absent", "Value": pd.NA, "Lower": pd.NA, "Upper": pd.NA})[-1] is False


def test_cli_recheck_prints_the_table_and_keeps_a_csv_stdout_clean(tmp_path, capsys):
    n = 20_000
    rng = np.random.default_rng(4)
    frame = pd.DataFrame({"time": np.arange(n) / RATE, "gx": rng.standard_normal(n) * 1e-2,
                          "ax": rng.standard_normal(n) * 3e-2})
    log = tmp_path / "log.csv"
    frame.to_csv(log, index=False)
    code, out, err = cli(capsys, "report", log, "--recheck", "2", "--seed", "1")
    assert code == 0, err
    text = out[out.index("Recheck of log.csv: 2 log(s) of 20000 samples at 100 Hz"):]
    assert "Angle random walk" in text and "Velocity random walk" in text and "Coverage" in text
    code, out, err = cli(capsys, "report", log, "--recheck", "2", "--seed", "1", "--output", "-")
    assert code == 0, err
    assert "Recheck of" in err and "Recheck of" not in out
    table = pd.read_csv(io.StringIO(out))
    assert set(table["Channel"]) == {"gx", "ax"}
    code, _, err = cli(capsys, "report", log, "--recheck", "0")
    assert code == 2 and "--recheck" in err
