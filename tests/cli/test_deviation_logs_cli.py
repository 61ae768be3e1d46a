"""``avar deviation`` on clock logs (read by content), with ``--check``, ``--dynamic`` and ThêoH's joined table."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import avar
from tests._support.cli_runner import cli

LOGS = Path(__file__).resolve().parents[1] / "data" / "clock_logs"
BANNER = ("=" * 131, "   Date (UTC) Time     IP Address   St   Freq ppm   Skew ppm     Offset L Co  Offset sd Rem. corr. "
          "Root delay Root disp. Max. error", "=" * 131)


def rows_of(block: str) -> list[list[str]]:
    return [line.split() for line in block.strip().splitlines()[2:] if not line.startswith("Wrote ")]


def plain_adev1(x: np.ndarray, tau: float) -> tuple[float, int]:
    """ADEV at m = 1 of phase with NaN gaps by a plain loop: every second difference of three finite points."""
    terms = [(x[i + 2] - 2 * x[i + 1] + x[i]) ** 2 for i in range(len(x) - 2)
             if np.isfinite(x[i]) and np.isfinite(x[i + 1]) and np.isfinite(x[i + 2])]
    return float(np.sqrt(sum(terms) / (2 * tau**2 * len(terms)))), len(terms)


def write_tracking(path: Path, offsets: np.ndarray, skip: tuple[int, ...] = ()) -> None:
    """A chrony tracking.log in chronyd's layout, one update every 64 s, the updates ``skip`` missed."""
    lines = list(BANNER)
    start = pd.Timestamp("2024-03-01 00:00:00")
    for k, offset in enumerate(offsets):
        if k in skip:
            continue
        stamp = (start + pd.Timedelta(seconds=64 * k)).strftime("%Y-%m-%d %H:%M:%S")
        lines.append(f"{stamp} 203.0.113.15     2     -3.541      0.075 {offset:10.3e} N  2  2.940e-06 -2.084e-07  "
                     "1.534e-02  3.472e-04  8.304e-03")
    path.write_text("\n".join(lines) + "\n")


def test_chrony_tracking_log_offset_with_its_gap(capsys):
    code, out, err = cli(capsys, "deviation", LOGS / "tracking.log", "--stat", "adev")
    assert code == 0, err
    assert "chrony tracking.log" in err and "column: chrony tracking.log: Offset (s)" in err
    assert "1 missing sample(s): NaN gaps" in err
    x = avar.read_clock_log(LOGS / "tracking.log").to_series().to_numpy()
    assert np.isnan(x).sum() == 1 and x.size == 11
    value, count = plain_adev1(x, 64.0)
    first = rows_of(out)[0]
    assert first[0] == "1" and float(first[1]) == 64.0 and int(first[2]) == count
    assert float(first[5]) == pytest.approx(value, rel=1e-4)


def test_ptp4l_master_offset_in_seconds(capsys):
    code, out, err = cli(capsys, "deviation", LOGS / "ptp4l.log", "--stat", "adev")
    assert code == 0, err
    assert "master offset" in err and "ns, read as s" in err
    log = avar.read_clock_log(LOGS / "ptp4l.log")
    x = log.to_series().to_numpy()
    value, count = plain_adev1(x, 1.0)
    first = rows_of(out)[0]
    assert int(first[2]) == count and float(first[5]) == pytest.approx(value, rel=1e-4)
    assert np.nanmax(np.abs(x)) < 1e-5  # ns read as s


@pytest.mark.parametrize(("name", "what"), [("loopstats", "ntpd loopstats: offset (s)"),
                                            ("igs_sample.clk", "RINEX clock 3.04: clock bias (s)"),
                                            ("statistics.log", "Est offset (s)")])
def test_other_logs_are_found_by_content(capsys, tmp_path, name, what):
    copy = tmp_path / "log.txt"  # no telling name: the content decides
    copy.write_bytes((LOGS / name).read_bytes())
    code, out, err = cli(capsys, "deviation", copy, "--stat", "adev")
    assert code == 0, err
    assert what in err and "ADEV" in out


def test_another_column_and_source(capsys, tmp_path):
    code, out, err = cli(capsys, "deviation", LOGS / "tracking.log", "--column", "Freq ppm", "--stat", "adev")
    assert code == 0, err
    assert "freq samples" in out and "Freq ppm" in err
    code, out, err = cli(capsys, "deviation", LOGS / "statistics.log", "--source", "198.51.100.7", "--stat", "adev")
    assert code == 0 and "source: 198.51.100.7 (asked for" in err
    log = avar.read_clock_log(LOGS / "statistics.log", source="198.51.100.7")
    x, tau = log.values, 1 / log.rate   # three offsets: one second difference
    assert float(rows_of(out)[0][5]) == pytest.approx(abs(x[2] - 2 * x[1] + x[0]) / (np.sqrt(2) * tau), rel=1e-4)
    code, _, err = cli(capsys, "deviation", LOGS / "tracking.log", "--data-type", "freq")
    assert code == 2 and "--data-type freq" in err and "phase" in err
    code, _, err = cli(capsys, "deviation", LOGS / "tracking.log", "--rate", "2")
    assert code == 2 and "--rate: the time stamps of a chrony tracking.log give its rate" in err
    code, _, err = cli(capsys, "deviation", LOGS / "loopstats", "--source", "x")
    assert code == 2 and "--source: a ntpd loopstats holds one source" in err
    table = tmp_path / "x.csv"
    pd.DataFrame({"x": np.arange(20.0)}).to_csv(table, index=False)
    code, _, err = cli(capsys, "deviation", table)
    assert code == 2 and "--data-type" in err


def test_check_names_each_jump_and_spike_with_its_line(capsys, tmp_path):
    rng = np.random.default_rng(5)
    x = np.cumsum(rng.standard_normal(400)) * 1e-9
    x[150:] += 2e-6   # a 2 us phase jump before sample 151
    x[300] += 3e-6    # a 3 us phase spike at sample 301
    path = tmp_path / "tracking.log"
    write_tracking(path, x, skip=(50,))
    code, out, err = cli(capsys, "deviation", path, "--check", "--stat", "adev")
    assert code == 0, err
    warnings = [line for line in err.splitlines() if ": warning: " in line]
    assert len(warnings) == 2, err
    # sample numbers count the NaN of the missed update; file lines count the 3 banner lines
    assert "phase jump at sample 151 (t = 9600 s, line 153)" in warnings[0]
    assert float(warnings[0].rsplit("size ", 1)[1].split()[0]) == pytest.approx(2e-6, rel=0.01)
    assert "phase spike at sample 301 (t = 19200 s, line 303)" in warnings[1]
    assert float(warnings[1].rsplit("size ", 1)[1].split()[0]) == pytest.approx(3e-6, rel=0.01)
    assert err.index("warning") < len(err) and out.startswith("tracking.log [Offset]: ADEV")
    write_tracking(path, np.cumsum(rng.standard_normal(400)) * 1e-9)
    code, _, err = cli(capsys, "deviation", path, "--check", "--force")
    assert code == 0 and "check: no outliers or jumps in 400 phase values" in err
    code, _, err = cli(capsys, "deviation", LOGS / "loopstats", "--check")
    assert code == 0 and "warning: check not run" in err  # never silent


def test_dynamic_summary_surface_and_heat_map(capsys, tmp_path):
    y = np.random.default_rng(3).standard_normal(20_000)
    y[12_000:] += 1.0
    path = tmp_path / "y.csv"
    pd.DataFrame({"y": y}).to_csv(path, index=False)
    surface, figure = tmp_path / "surface.csv", tmp_path / "dyn.png"
    code, out, err = cli(capsys, "deviation", path, "--data-type", "freq", "--dynamic", "1000:100",
                         "--output", surface, "--plot", figure)
    assert code == 0, err
    assert "DOADEV" in out and "non-stationary" in out
    changes = [float(line.split("change near t = ")[1].split(" s")[0]) for line in out.splitlines()
               if "change near" in line]
    assert any(abs(t - 12_000) <= 100 for t in changes)
    frame = pd.read_csv(surface)
    assert list(frame.columns) == ["time", "tau", "deviation", "lower", "upper"]
    first = frame[frame.time == 500.0]  # window 0: samples 0 .. 999, centre 500 s
    expected = avar.oadev(y[:1000], taus=first.tau.to_numpy())
    np.testing.assert_allclose(first.deviation, expected.deviation, rtol=1e-9)
    np.testing.assert_allclose(first.lower, expected.lci, rtol=1e-9)
    assert frame.time.nunique() == (20_000 - 1000) // 100 + 1
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    code, out, _ = cli(capsys, "deviation", path, "--data-type", "freq", "--dynamic", "4000")
    assert code == 0 and "windows of 4000 samples every 400" in out
    code, _, err = cli(capsys, "deviation", path, "--data-type", "freq", "--dynamic", "10:x")
    assert code == 2 and "WINDOW:STEP" in err
    code, _, err = cli(capsys, "deviation", path, "--data-type", "freq", "--dynamic", "1000", "--stat", "theo1")
    assert code == 2 and "--dynamic takes one --stat" in err


def test_theoh_rows_are_sorted_and_unique(capsys, tmp_path):
    x = np.cumsum(np.random.default_rng(0).standard_normal(10_000)) * 1e-9
    path = tmp_path / "x.csv"
    pd.DataFrame({"x": x}).to_csv(path, index=False)
    code, out, err = cli(capsys, "deviation", path, "--data-type", "phase", "--stat", "theoh",
                         "--output", tmp_path / "t.csv")
    assert code == 0, err
    rows = rows_of(out)
    taus = [float(r[2]) for r in rows]
    assert taus == sorted(taus) and len(set(taus)) == len(taus)
    assert [r[1] for r in rows].count("2048") == 1
    expected = avar.theoh(x, data_type="phase")
    parts = {float(r[2]): r[0] for r in rows}
    assert parts[2048.0] == "OADEV" and parts[1536.0] == "Theo1" and parts[1024.0] == "OADEV"
    by_tau = dict(zip(expected.taus.tolist(), expected.deviation.tolist()))
    for r in rows:
        assert float(r[6]) == pytest.approx(by_tau[float(r[2])], rel=1e-4)
    assert len(rows) == len(by_tau)
    table = pd.read_csv(tmp_path / "t.csv")
    assert list(table.columns[:3]) == ["Stat", "Part", "AF"] and table.Tau.is_monotonic_increasing
