"""``avar deviation``: Stable32-style tables from real files, CSV and figure outputs, the statistics registry."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import avar
from avar.stability.shared.registry import DEVIATION_STATISTICS
from tests._support.cli_runner import cli


@pytest.fixture()
def phase_file(tmp_path):
    x = np.cumsum(np.random.default_rng(0).standard_normal(600)) * 1e-9
    path = tmp_path / "clock.csv"
    pd.DataFrame({"time": np.arange(600) * 0.5, "x": x}).to_csv(path, index=False)
    return path, x


def test_tables_print_the_library_values(capsys, phase_file):
    path, x = phase_file
    code, out, err = cli(capsys, "deviation", path, "--stat", "oadev", "--stat", "pdev", "--stat", "tierms",
                         "--data-type", "phase")
    assert code == 0, err
    blocks = out.strip().split("\n\n")
    assert len(blocks) == 3
    for block, name in zip(blocks, ("oadev", "pdev", "tierms")):
        lines = block.splitlines()
        assert lines[0].startswith(f"clock.csv [x]: {name.upper()} (") and "at 2 Hz" in lines[0]
        assert lines[1].split() == ["AF", "Tau", "#", "Alpha", "Min", "Sigma", "Sigma", "Max", "Sigma"]
        expected = getattr(avar, name)(x, rate=2.0, data_type="phase")
        rows = [line.split() for line in lines[2:]]
        assert [int(r[0]) for r in rows] == expected.averaging_factors.tolist()
        assert [int(r[2]) for r in rows] == expected.n.tolist()
        np.testing.assert_allclose([float(r[5]) for r in rows], expected.deviation, rtol=1e-4)
        if name == "tierms":
            assert {r[4] for r in rows} == {"-"} and {r[6] for r in rows} == {"-"}
        else:
            np.testing.assert_allclose([float(r[4]) for r in rows], expected.lci, rtol=1e-4)


def test_a_fixed_noise_reaches_every_statistic(capsys, phase_file):
    path, x = phase_file
    code, out, err = cli(capsys, "deviation", path, "--stat", "totdev", "--stat", "theo1", "--data-type", "phase",
                         "--noise", "-1")
    assert code == 0, err
    for block, name in zip(out.strip().split("\n\n"), ("totdev", "theo1")):
        rows = [line.split() for line in block.splitlines()[2:]]
        expected = getattr(avar, name)(x, rate=2.0, data_type="phase", alpha=-1)
        assert {r[3] for r in rows} == {"-1"}
        np.testing.assert_allclose([float(r[5]) for r in rows], expected.deviation, rtol=1e-4)
        np.testing.assert_allclose([float(r[6]) for r in rows], expected.uci, rtol=1e-4)
    code, _, err = cli(capsys, "deviation", path, "--data-type", "phase", "--noise", "3")
    assert code == 2 and "--noise" in err


def test_csv_and_figure_outputs(capsys, phase_file, tmp_path):
    path, x = phase_file
    csv, png = tmp_path / "out.csv", tmp_path / "out.png"
    code, out, err = cli(capsys, "deviation", path, "--stat", "mdev", "--stat", "mtie", "--data-type", "phase",
                         "--rate", "2", "--taus", "decade", "--output", csv, "--plot", png)
    assert code == 0, err
    table = pd.read_csv(csv)
    assert list(table.columns) == ["Stat", "AF", "Tau", "#", "Alpha", "Min Sigma", "Sigma", "Max Sigma"]
    mdev = avar.mdev(x, rate=2.0, data_type="phase", taus="decade")
    np.testing.assert_allclose(table.loc[table.Stat == "MDEV", "Sigma"], mdev.deviation, rtol=1e-12)
    assert table.loc[table.Stat == "MTIE", "Max Sigma"].isna().all()
    assert png.read_bytes()[:4] == b"\x89PNG"
    code, _, err = cli(capsys, "deviation", path, "--data-type", "phase", "--output", csv)
    assert code == 2 and "exists" in err


def test_the_modified_hadamard_statistics_print_from_the_registry(capsys, phase_file):
    path, x = phase_file
    code, out, err = cli(capsys, "deviation", path, "--stat", "mhdev", "--stat", "htdev", "--stat", "mhtotdev",
                         "--data-type", "phase")
    assert code == 0, err
    for block, name in zip(out.strip().split("\n\n"), ("mhdev", "htdev", "mhtotdev")):
        lines = block.splitlines()
        assert lines[0].startswith(f"clock.csv [x]: {name.upper()} (")
        expected = getattr(avar, name)(x, rate=2.0, data_type="phase")
        rows = [line.split() for line in lines[2:]]
        assert [int(r[0]) for r in rows] == expected.averaging_factors.tolist() and int(rows[-1][0]) == 128  # <= 600 / 4
        assert [int(r[2]) for r in rows] == expected.n.tolist()
        np.testing.assert_allclose([float(r[5]) for r in rows], expected.deviation, rtol=1e-4)
        np.testing.assert_allclose([float(r[6]) for r in rows], expected.uci, rtol=1e-4)


def test_every_registered_statistic_is_a_public_function(capsys, phase_file):
    path, _ = phase_file
    for name in DEVIATION_STATISTICS:
        assert callable(getattr(avar, name))
    code, out, err = cli(capsys, "deviation", path, *sum((["--stat", s] for s in DEVIATION_STATISTICS), []),
                         "--data-type", "phase", "--taus", "octave")
    assert code == 0, err
    assert out.count("confidence\n") == len(DEVIATION_STATISTICS)


def test_usage_errors(capsys, phase_file, tmp_path):
    path, _ = phase_file
    code, _, err = cli(capsys, "deviation", path, "--stat", "nodev", "--data-type", "phase")
    assert code == 2 and "invalid choice" in err
    code, _, err = cli(capsys, "deviation", path, "--stat", "oadev")
    assert code == 2 and "--data-type" in err
    two = tmp_path / "two.csv"
    pd.DataFrame({"a": np.arange(10.0), "b": np.arange(10.0)}).to_csv(two, index=False)
    code, _, err = cli(capsys, "deviation", two, "--data-type", "freq")
    assert code == 2 and "--column" in err
    code, out, err = cli(capsys, "deviation", two, "--data-type", "freq", "--column", "b")
    assert code == 0, err
