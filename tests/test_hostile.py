"""Edge and hostile inputs: each gives the exact value or an error that names the argument.

Three tables: library calls that must raise (type and message fragment), library
calls that must give exact values, and command lines (exit code and message
fragment, run in-process through ``avar.cli.main``). Two subprocess tests cover
what only a real process shows: a reader that closes the pipe after one line, and
Ctrl-C during a long computation.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import avar
from avar.stability.allan.results import AllanVariance
from tests._support.cli_runner import cli

FMAX = np.finfo(np.float64).max
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
PNG_END = b"IEND\xaeB`\x82"
X = np.random.default_rng(0).standard_normal(4096)


def _av(**changes):
    fields = dict(levels=[1.0, 2.0], averaging_factors=[1, 2], allan=[1.0, 0.5], errors=[0.1, 0.2],
                  n_differences=[7, 5], type="mo", freq=1.0, n=8)
    return AllanVariance(**{**fields, **changes})


def _gen():
    return (i for i in range(1, 4))


RAISES = {
    "masked array": (lambda: avar.avar(np.ma.masked_array(X, mask=X > 2)), ValueError,
                     "x is a masked array with"),
    "masked IMU": (lambda: avar.IMU(np.ma.masked_array(np.ones((10, 2)), mask=[[1, 0]] + [[0, 0]] * 9),
                                    freq=1.0, gyro=[0, 1]), ValueError, "data is a masked array with 1 masked"),
    "ragged list": (lambda: avar.avar([[1, 2], [3]]), ValueError, "x is a ragged sequence"),
    "ragged items": (lambda: avar.avar([1.0, 2.0, [3.0, 4.0], 5.0, 6.0]), ValueError, "x is a ragged sequence"),
    "ragged IMU": (lambda: avar.IMU([[1, 2]] * 5 + [[3]], freq=1.0, gyro=[0, 1]), ValueError,
                   "data is a ragged sequence"),
    "subnormal freq": (lambda: avar.avar(X, freq=5e-324), ValueError, "freq = 5e-324 Hz is too small"),
    "scales as a set": (lambda: avar.avlr(X, wn={1, 2, 3}), TypeError, "wn must be whole numbers as an int, a range"),
    "scales as a generator": (lambda: avar.avlr(X, wn=_gen()), TypeError, "got generator; convert it with list"),
    "scale 2**70": (lambda: avar.avlr(X, wn=2**70), ValueError, "wn holds 1180591620717411303424, too large"),
    "scale range 1..10**7": (lambda: avar.avlr(X, wn=range(1, 10**7)), ValueError,
                             "wn = range(1, 10000000) reaches outside 1..11"),
    "scale range 1..10**12": (lambda: avar.avlr(X, rw=range(1, 10**12)), ValueError,
                              "rw = range(1, 1000000000000) reaches outside"),
    "seed 'abc'": (lambda: avar.avlr(X, wn=range(1, 4), ci=True, B=5, seed="abc"), TypeError,
                   "seed must be None, a non-negative int"),
    "seed -1": (lambda: avar.avlr(X, wn=range(1, 4), ci=True, B=5, seed=-1), ValueError, "seed must be >= 0"),
    "seed 1.5": (lambda: avar.avlr(X, wn=range(1, 4), ci=True, B=5, seed=1.5), TypeError,
                 "seed must be None, a non-negative int"),
    "simulate seed 'abc'": (lambda: avar.WN(sigma2=1.0).simulate(10, seed="abc"), TypeError,
                            "seed must be None"),
    "B 10**12": (lambda: avar.avlr(X, wn=range(1, 4), ci=True, B=10**12), ValueError,
                 "B = 1000000000000 replicates is too many"),
    "moav -eye(8)": (lambda: avar.moav(2, -np.eye(8)), ValueError, "negative variance(s) on its diagonal"),
    "noav -eye(8)": (lambda: avar.noav(2, -np.eye(8)), ValueError, "negative variance(s) on its diagonal"),
    "freq 10**400": (lambda: avar.avar(X, freq=10**400), ValueError, "is beyond the float64 range"),
    "alpha 10**5000": (lambda: avar.avlr(X, wn=range(1, 4), alpha=10**5000), ValueError,
                       "alpha = <int of 16610 bits> is beyond the float64 range"),
    "99000 taus outside": (lambda: avar.avar(X, taus=list(range(10**4, 10**5))), ValueError,
                           "(90000 items)] are outside the valid range"),
    "AllanVariance type 'xx'": (lambda: _av(type="xx"), ValueError, "type must be one of ['mo', 'to']"),
    "AllanVariance negative AV": (lambda: _av(allan=[-1.0, 0.5]), ValueError,
                                  "allan must hold finite values >= 0"),
    "AllanVariance NaN AV": (lambda: _av(allan=[np.nan, 0.5]), ValueError, "allan must hold finite values >= 0"),
    "AllanVariance freq 0": (lambda: _av(freq=0.0), ValueError, "freq must be a finite number > 0"),
}


@pytest.mark.parametrize("case", list(RAISES))
def test_hostile_input_raises_a_clear_error(case):
    call, kind, fragment = RAISES[case]
    with pytest.raises(kind) as info:
        call()
    assert fragment in str(info.value)
    assert len(str(info.value)) < 600  # never grows with the input


def _psd(t: int, seed: int) -> np.ndarray:
    a = np.random.default_rng(seed).standard_normal((t, t))
    c = a @ a.T
    return c / np.abs(c).max()


def _bootstrap_at_tiny_alpha():
    fit = avar.avlr(X, wn=range(1, 4), ci=True, B=20, seed=3, alpha=1e-300)
    from scipy.stats import norm

    z = norm.isf(5e-301)  # finite: about 37.1
    row = fit.ci.loc["WN"]
    expected = (row["Estimate"] - z * row["SD"], row["Estimate"] + z * row["SD"])
    return (row["Lower"], row["Upper"]), expected


NS = np.arange(1, 9)
EXACT = {
    # the AV of a constant is 0, even at the float64 limit
    "constant at float max": (lambda: avar.avar(np.full(256, FMAX)).allan, lambda: np.zeros(7), 0.0),
    "constant at -float max, to": (lambda: avar.avar(np.full(256, -FMAX), type="to").allan,
                                   lambda: np.zeros(7), 0.0),
    "IMU constant at float max": (lambda: avar.avar(avar.IMU(np.column_stack([np.full(256, FMAX), X[:256]]),
                                                          freq=1.0, gyro=[0, 1])).channels["Gyro. X"].allan,
                                  lambda: np.zeros(7), 0.0),
    # moav/noav of covariances near the float64 limit: scaled, not overflowed
    "moav 1.7e308 * I": (lambda: avar.moav(NS, 1.7e308 * np.eye(16)), lambda: avar.av_wn(1.7e308, NS), 1e-13),
    "noav 1.7e308 * I": (lambda: avar.noav(NS, 1.7e308 * np.eye(16)), lambda: avar.av_wn(1.7e308, NS), 1e-13),
    "moav 1e308 * PSD": (lambda: avar.moav(NS, 1e308 * _psd(16, 1)), lambda: 1e308 * avar.moav(NS, _psd(16, 1)),
                         1e-12),
    "noav FMAX * PSD": (lambda: avar.noav(NS, FMAX * _psd(16, 2)), lambda: FMAX * avar.noav(NS, _psd(16, 2)),
                        1e-12),
    # R's covmat_nswn(sigma2, n_total) = diag(sigma2, n_total, n_total)
    "covmat_nswn(1.5, 150)": (lambda: avar.covmat_nswn(1.5, 150), lambda: 1.5 * np.eye(150), 0.0),
    "moav of covmat_nswn(1.5, 150)": (lambda: avar.moav(np.arange(2, 33), avar.covmat_nswn(1.5, 150)),
                                      lambda: avar.av_wn(1.5, np.arange(2, 33)), 1e-13),
    "alpha = 1e-300": (lambda: _bootstrap_at_tiny_alpha()[0], lambda: _bootstrap_at_tiny_alpha()[1], 1e-12),
}


@pytest.mark.parametrize("case", list(EXACT))
def test_hostile_input_gives_the_exact_value(case):
    got, expected, rtol = EXACT[case]
    values, reference = np.asarray(got()), np.asarray(expected())
    assert np.all(np.isfinite(values))
    np.testing.assert_allclose(values, reference, rtol=rtol, atol=0)


# --------------------------------------------------------------------------- the command line
@pytest.fixture(scope="module")
def data_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("hostile") / "data.csv"
    pd.DataFrame({"time": np.arange(8192) / 10.0, "gx": X[:4096].repeat(2),
                  "gy": np.cumsum(X[:4096]).repeat(2)}).to_csv(path, index=False)
    return path


# (arguments with {data} = the input file and {dir} = a fresh folder, files created first, exit code,
#  fragment of stderr, files that must not exist afterwards)
CLI = {
    "existing --output": (["compute", "{data}", "--output", "{dir}/o.csv"], ["o.csv"], 2,
                          "--output '{dir}/o.csv' exists; pass --force", []),
    "existing --plot": (["compute", "{data}", "--plot", "{dir}/p.png"], ["p.png"], 2,
                        "--plot '{dir}/p.png' exists; pass --force", []),
    "existing fit --output": (["fit", "{data}", "--column", "gx", "--wn", "1:3", "--output", "{dir}/f.csv"],
                              ["f.csv"], 2, "exists; pass --force", []),
    "--output is the input": (["compute", "{data}", "--output", "{data}"], [], 2,
                              "is the input file; the input is never overwritten", []),
    "--output is the input, --force": (["compute", "{data}", "--output", "{data}", "--force"], [], 2,
                                       "is the input file", []),
    "--output and --plot the same": (["compute", "{data}", "--output", "{dir}/s.png", "--plot", "{dir}/s.png"],
                                     [], 2, "--output and --plot are the same file", ["s.png"]),
    "--plot without extension": (["compute", "{data}", "--plot", "{dir}/name"], [], 2,
                                 "has no extension; name a figure format", ["name", "name.png"]),
    "--plot a directory": (["compute", "{data}", "--plot", "{dir}"], [], 2, "is a directory", []),
    "--plot bad format, no CSV written": (["compute", "{data}", "--output", "{dir}/o.csv", "--plot",
                                           "{dir}/p.xyz"], [], 2, "has extension '.xyz'", ["o.csv", "p.xyz"]),
    "--plot in a missing folder": (["compute", "{data}", "--plot", "{dir}/none/p.png"], [], 2,
                                   "does not exist", []),
    "--freq inf": (["compute", "{data}", "--freq", "inf"], [], 2, "--freq must be a finite number > 0", []),
    "--freq subnormal": (["compute", "{data}", "--freq", "5e-324"], [], 2, "--freq = 5e-324 Hz is too small", []),
    "--wn -3:2": (["fit", "{data}", "--column", "gx", "--wn", "-3:2"], [], 2,
                  "argument --wn: invalid scale -3 in '-3:2': scale numbers start at 1", []),
    "repeated --wn": (["fit", "{data}", "--column", "gx", "--wn", "1:3", "--wn", "2:4"], [], 2,
                      "--wn is given twice", []),
    "--wn 1:100000000": (["fit", "{data}", "--column", "gx", "--wn", "1:100000000"], [], 1,
                         "wn = range(1, 100000001) reaches outside 1..", []),
    "--wn 1:10000000000": (["fit", "{data}", "--column", "gx", "--wn", "1:10000000000"], [], 1,
                           "reaches outside 1..", []),
    "--wn long list": (["fit", "{data}", "--column", "gx", "--wn", "1:600000,700000:1500000"], [], 2,
                       "lists 1400001 scales, more than 1,000,000", []),
    "--B 10**12": (["fit", "{data}", "--column", "gx", "--wn", "1:3", "--ci", "--B", "1000000000000"], [], 1,
                   "B = 1000000000000 replicates is too many", []),
    "--seed -1": (["fit", "{data}", "--column", "gx", "--wn", "1:3", "--ci", "--seed", "-1"], [], 2,
                  "argument --seed: expected a whole number >= 0, got '-1'", []),
    "demo --out a file": (["demo", "--out", "{dir}/file"], ["file"], 2, "is a file; give a directory", []),
    "demo over an existing figure": (["demo", "--out", "{dir}"], ["avar_demo.png"], 2,
                                     "avar_demo.png' exists; pass --force", []),
    "datasets --plot without a name": (["datasets", "--plot", "{dir}/d.png"], [], 2,
                                       "--plot needs a data set name", ["d.png"]),
}


@pytest.mark.parametrize("case", list(CLI))
def test_hostile_command_line(case, data_file, tmp_path, capsys):
    args, existing, code, fragment, absent = CLI[case]
    fill = {"data": str(data_file), "dir": str(tmp_path)}
    for name in existing:
        (tmp_path / name).write_bytes(b"old")
    got, _, err = cli(capsys, *(a.format(**fill) for a in args))
    assert got == code, err
    assert fragment.format(**fill) in err
    assert "Traceback" not in err and len(err) < 2000
    for name in existing:
        assert (tmp_path / name).read_bytes() == b"old"  # never replaced without --force
    for name in absent:
        assert not (tmp_path / name).exists()
    assert not list(tmp_path.glob(".*.part"))


def test_force_replaces_atomically_and_keeps_the_umask_mode(data_file, tmp_path, capsys):
    out, fig = tmp_path / "o.csv", tmp_path / "p.png"
    out.write_text("old")
    code, stdout, err = cli(capsys, "compute", data_file, "--column", "gx", "--output", out, "--plot", fig, "--force")
    assert code == 0, err
    table = pd.read_csv(out)
    expected = avar.avar(X[:4096].repeat(2), freq=10.0).summary().reset_index()
    np.testing.assert_allclose(table["AVar"], expected["AVar"], rtol=1e-12)
    assert fig.read_bytes().startswith(PNG_MAGIC)
    assert stdout.rstrip().endswith(f"Wrote {fig}")
    mode = 0o666 & ~_umask()  # as for a file opened by the user, not the 0o600 of a temporary file
    assert out.stat().st_mode & 0o777 == fig.stat().st_mode & 0o777 == mode
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.csv", "p.png"]  # no temporary left


def _umask() -> int:
    import os

    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_output_dash_is_stdout(data_file, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, stdout, err = cli(capsys, "compute", data_file, "--column", "gx", "--output", "-")
    assert code == 0, err
    assert not (tmp_path / "-").exists()
    from io import StringIO

    table = pd.read_csv(StringIO(stdout))  # the CSV alone, not the printed table
    assert list(table.columns) == ["Scale", "Time", "AVar", "ADev", "Lower CI", "Upper CI"]
    np.testing.assert_allclose(table["AVar"], avar.avar(X[:4096].repeat(2)).allan, rtol=1e-12)


def test_plot_format_from_the_extension(data_file, tmp_path, capsys):
    code, stdout, err = cli(capsys, "compute", data_file, "--column", "gx", "--plot", tmp_path / "fig.svg")
    assert code == 0, err
    assert (tmp_path / "fig.svg").read_text().lstrip().startswith("<?xml")
    assert f"Wrote {tmp_path / 'fig.svg'}" in stdout


# --------------------------------------------------------------------------- real processes
def test_reader_closing_the_pipe_loses_no_file(tmp_path):
    """``avar compute ... | head -1``: exit 0, no traceback, both files whole."""
    data = tmp_path / "long.csv"
    series = np.random.default_rng(5).standard_normal(40_000)
    pd.DataFrame({"x": series}).to_csv(data, index=False)
    out, fig = tmp_path / "o.csv", tmp_path / "p.png"
    # --taus all prints 20000 rows: far more than a pipe buffer, so printing meets the closed pipe
    process = subprocess.Popen(
        [sys.executable, "-m", "avar", "compute", str(data), "--taus", "all", "--output", str(out), "--plot", str(fig)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )
    try:
        first = process.stdout.readline()
        process.stdout.close()
        err = process.stderr.read().decode()
        code = process.wait(timeout=300)
    finally:
        process.kill()
    assert b"Scale" in first
    assert code == 0, err
    assert "Traceback" not in err and "BrokenPipe" not in err and "Exception ignored" not in err
    table = pd.read_csv(out)
    assert len(table) == 20_000
    np.testing.assert_allclose(table["AVar"].to_numpy()[[0, 99, 19_999]],
                               avar.avar(series, taus=[1.0, 100.0, 20_000.0]).allan, rtol=1e-12)
    image = fig.read_bytes()
    assert image.startswith(PNG_MAGIC) and image.endswith(PNG_END)


def test_ctrl_c_during_a_long_computation_exits_130_with_one_line(tmp_path):
    data = tmp_path / "long.npy"
    np.save(data, np.random.default_rng(6).standard_normal(2_000_000))
    process = subprocess.Popen(
        [sys.executable, "-m", "avar", "compute", str(data), "--taus", "all", "--output", str(tmp_path / "o.csv")],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    try:
        announced = process.stderr.readline()  # printed once the file is read, as the computation starts
        if "compiling the numerical kernels" in announced:  # a cold cache: the first-run notice comes first
            announced = process.stderr.readline()
        assert "column(s) x 2000000 samples" in announced
        process.send_signal(signal.SIGINT)
        # the --taus all computation takes many minutes; the interrupt must end it now
        code = process.wait(timeout=30)
        err = process.stderr.read()
    finally:
        process.kill()
    assert code == 130
    assert err.strip().splitlines() == ["avar: interrupted"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.npy"]


def _exact_moav(values: list[int], m: int):
    from fractions import Fraction

    d = [sum(values[i + m : i + 2 * m]) - sum(values[i : i + m]) for i in range(len(values) - 2 * m + 1)]
    return sum(Fraction(v * v) for v in d) / (2 * m * m * len(d))


@pytest.mark.parametrize("dtype", [np.int64, np.uint64])
def test_integers_spanning_their_whole_range_are_not_converted_lossily(dtype):
    info = np.iinfo(dtype)
    x = np.array([info.min, info.max, info.max, info.min, info.min] * 20, dtype=dtype)
    result = avar.avar(x, taus="all")
    exact = np.array([float(_exact_moav([int(v) for v in x], int(m))) for m in result.averaging_factors])
    np.testing.assert_allclose(result.allan, exact, rtol=0, atol=1e-12 * exact.max())


def test_the_reported_int64_example_is_exact():
    # the centring offset of this series overflowed int64 once, and the AV came out 3x off
    x = np.array([2**63 - 1, -(2**63), 0, 5, 2**62, -(2**62)] * 4, dtype=np.int64)
    result = avar.avar(x, taus="all")
    exact = np.array([float(_exact_moav([int(v) for v in x], int(m))) for m in result.averaging_factors])
    np.testing.assert_allclose(result.allan, exact, rtol=1e-12, atol=0)


def test_cli_int64_npy_near_the_int64_limit_is_exact(tmp_path, capsys):
    # near 2**63 - 1 a float64 conversion rounds every sample to the same value (AV 0)
    steps = np.random.default_rng(5).integers(0, 1000, 64)
    x = (np.iinfo(np.int64).max - steps).astype(np.int64)
    np.save(tmp_path / "big.npy", x)
    code, _, err = cli(capsys, "compute", tmp_path / "big.npy", "--taus", "all", "--output", tmp_path / "o.csv")
    assert code == 0, err
    table = pd.read_csv(tmp_path / "o.csv")
    exact = np.array([float(_exact_moav([int(v) for v in x], m)) for m in range(1, 33)])
    assert exact.min() > 0
    np.testing.assert_allclose(table["AVar"], exact, rtol=1e-12, atol=0)
