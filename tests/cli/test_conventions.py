"""What a newcomer expects of a command line: --version, the same column options everywhere,
a demo that can run twice, no foreign warnings, the rate's source, no "-" in tables."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pandas as pd
import pytest

import avar
from avar.cli.demo import MARK_KEY, is_own_figure, png_text
from avar.models import RW, WN
from tests._support.cli_runner import cli

FREQ = 50.0
N = 20_000
AXES = ("gx", "gy", "gz", "ax", "ay", "az")


@pytest.fixture(scope="module")
def imu_csv(tmp_path_factory):
    """Six axes and a time column at 50 Hz stamped with a little jitter; the values, by name."""
    rng = np.random.default_rng(11)
    model = WN(sigma2=1e-4) + RW(gamma2=1e-10)
    values = {name: model.simulate(N, seed=rng) for name in AXES}
    time = np.arange(N) / FREQ + rng.uniform(-2e-4, 2e-4, N)
    path = tmp_path_factory.mktemp("imu") / "imu.csv"
    pd.DataFrame({"time": time, **values}).to_csv(path, index=False, float_format="%.12g")
    return path, {name: pd.read_csv(path)[name].to_numpy() for name in AXES}


def test_version(capsys):
    code, out, err = cli(capsys, "--version")
    assert code == 0 and out.strip() == f"avar {avar.__version__}" and err == ""
    assert re.fullmatch(r"\d+\.\d+\.\d+\S*", avar.__version__)


def test_compute_takes_gyro_and_accel_lists(imu_csv, capsys, tmp_path):
    path, values = imu_csv
    listed, repeated = tmp_path / "listed.csv", tmp_path / "repeated.csv"
    code, _, err = cli(capsys, "compute", path, "--gyro", "gx", "gy", "gz", "--accel", "ax", "ay", "az",
                       "--output", listed)
    assert code == 0, err
    code, _, err = cli(capsys, "compute", path, "--gyro", "gx", "--gyro", "gy", "--gyro", "gz",
                       "--accel", "ax", "--accel", "ay", "--accel", "az", "--output", repeated)
    assert code == 0, err
    table = pd.read_csv(listed)
    pd.testing.assert_frame_equal(table, pd.read_csv(repeated))
    assert list(dict.fromkeys(table["Channel"])) == list(AXES)
    # The library's numbers for the same column (at the rate read from the jittered time column).
    rate = 1 / np.median(np.diff(pd.read_csv(path)["time"].to_numpy()))
    expected = avar.avar(values["gy"], freq=rate).summary()
    got = table[table["Channel"] == "gy"]
    np.testing.assert_allclose(got["AVar"].to_numpy(), expected["AVar"].to_numpy(), rtol=1e-12)


def test_fit_takes_gyro_and_accel_lists(imu_csv, capsys):
    path, values = imu_csv
    code, out, err = cli(capsys, "fit", path, "--gyro", "gx", "gy", "gz", "--accel", "ax", "ay", "az",
                         "--wn", "1:5")
    assert code == 0, err
    assert "Estimates for gyroscopes" in out and "Estimates for accelerometers" in out
    # sigma of a white noise of variance 1e-4 per sample at 50 Hz: sqrt(1e-4 / 50) u s^1/2.
    sigmas = [float(v) for v in re.findall(r"WN\s+sigma \[u s\^1/2\]\s+(\S+)", out)]
    assert len(sigmas) == 2 and np.allclose(sigmas, np.sqrt(1e-4 / FREQ), rtol=0.05)


def test_report_takes_gyro_and_accel_lists_and_says_the_rate(imu_csv, capsys):
    path, _ = imu_csv
    code, out, err = cli(capsys, "report", path, "--gyro", "gx", "gy", "gz", "--accel", "ax", "--accel", "ay", "az")
    assert code == 0, err
    assert "gx (gyroscope)" in out and "az (accelerometer)" in out
    # As `avar compute` says it: the rate, where it comes from, and the timestamps' jitter.
    note = next(line for line in err.splitlines() if line.startswith(f"{path}:"))
    # The steps' jitter: the difference of two uniform(-0.2, 0.2) ms stamps, rms 0.4 / sqrt(6) = 0.163 ms.
    jitter = re.search(r"6 column\(s\) x 20000 samples at 50 Hz from time column 'time' \(jitter (\S+) ms rms\)", note)
    assert jitter and float(jitter.group(1)) == pytest.approx(0.4 / np.sqrt(6), rel=0.03)
    code, _, err = cli(capsys, "report", path, "--freq", "40")
    assert code == 0, err
    assert "at 40 Hz (--freq)" in err


def test_demo_replaces_its_own_figure_but_no_other_file(tmp_path, capsys):
    figure = tmp_path / "avar_demo.png"
    for _ in range(2):
        code, out, err = cli(capsys, "demo", "--out", tmp_path)
        assert code == 0, err
        assert f"Wrote {figure}" in out
    assert png_text(figure)[MARK_KEY].startswith("avar demo") and is_own_figure(figure)
    # Someone else's PNG (written by matplotlib, without our mark) is kept.
    import matplotlib.pyplot as plt

    plt.figure().savefig(figure)
    plt.close("all")
    before = figure.read_bytes()
    assert not is_own_figure(figure)
    code, _, err = cli(capsys, "demo", "--out", tmp_path)
    assert code == 2 and "--force" in err and figure.read_bytes() == before
    figure.write_text("notes\n")  # not a PNG at all
    code, _, err = cli(capsys, "demo", "--out", tmp_path)
    assert code == 2 and figure.read_text() == "notes\n"
    code, _, err = cli(capsys, "demo", "--out", tmp_path, "--force")
    assert code == 0 and is_own_figure(figure)


def test_pandas_dtype_warning_never_reaches_the_user(imu_csv, capsys, monkeypatch):
    """A column parsed to different types in different blocks makes pandas warn with its own
    source line; the reader decides about the column itself (it parses or names the cell)."""
    import avar.io.text as text

    original = text.pd.read_csv

    def read_csv(*args, **kwargs):
        warnings.warn("Columns (1: gx) have mixed types. Specify dtype option on import or set low_memory=False.",
                      pd.errors.DtypeWarning, stacklevel=2)
        return original(*args, **kwargs)

    monkeypatch.setattr(text.pd, "read_csv", read_csv)
    code, out, err = cli(capsys, "compute", imu_csv[0], "--column", "gx")
    assert code == 0, err
    assert "mixed types" not in err and "Warning" not in err and "warn" not in err.lower()


def test_any_other_warning_is_one_line_of_ours(imu_csv, capsys, monkeypatch):
    import avar.io.text as text

    original = text._read_chunks

    def read_chunks(*args, **kwargs):
        warnings.warn("a library has something to say\nwith a second line", RuntimeWarning, stacklevel=1)
        return original(*args, **kwargs)

    monkeypatch.setattr(text, "_read_chunks", read_chunks)
    code, out, err = cli(capsys, "compute", imu_csv[0], "--column", "gx")
    assert code == 0, err
    lines = [line for line in err.splitlines() if "something to say" in line]
    assert lines == ["avar: warning: a library has something to say"]
    assert "second line" not in err and ".py" not in err and "RuntimeWarning" not in err
    assert warnings.showwarning is not None and "avar" not in getattr(warnings.showwarning, "__module__", "")


def _cells(text: str) -> list[str]:
    return [cell for line in text.splitlines() for cell in line.split()]


def test_tables_never_print_a_dash_or_nan(imu_csv, capsys, tmp_path):
    path, _ = imu_csv
    runs = [
        ("compute", path, "--column", "gx", "--taus", "all"),
        ("compute", path, "--gyro", "gx", "gy", "gz", "--accel", "ax", "ay", "az"),
        ("fit", path, "--column", "gx", "--wn", "1:4", "--rw", "9:11"),
        ("fit", path, "--gyro", "gx", "gy", "gz", "--accel", "ax", "ay", "az", "--wn-gyro", "1:4", "--rw-acc", "9:11",
         "--per-axis"),
        ("datasets",),
        ("demo", "--out", tmp_path),
    ]
    for arguments in runs:
        code, out, err = cli(capsys, *arguments)
        assert code == 0, (arguments, err)
        cells = _cells(out)
        assert "-" not in cells and "NaN" not in cells and "nan" not in cells, (arguments, out)
