"""One vocabulary (docs/conventions.md), in Python and on the command line.

``alpha`` is only the power-law noise exponent, ``confidence`` a probability, ``rate`` the
sampling rate in Hz, ``taus`` the averaging times of every result, ``n_samples`` a record's length
and ``n_terms`` a level's term count; units are spelled one way everywhere. R's spellings survive in
the R-compatible ``avar``, ``avlr`` and ``IMU``; the other old spellings warn until 0.3.0 and give
the same numbers as the new ones.
"""

from __future__ import annotations

import argparse
import inspect
import re
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import avar
from avar.cli.main import build_parser
from avar.fit.report.noise_terms import ACCEL, GYRO, UNIT_SPELLINGS, check_unit
from tests._support.cli_runner import cli

ROOT = Path(__file__).resolve().parents[1]
#: R-compatible callables that keep R's ``freq=`` (R's ``avar`` object included: AllanVariance and kin).
R_FREQ = {"avar", "avlr", "IMU", "AllanVariance", "ImuAllanVariance", "RobustAllanVariance"}
#: The one function that documents ``alpha`` as 1 - confidence (R's ``avlr(..., alpha)``).
R_ALPHA = {"avlr"}
#: Public names whose ``rate=`` spelling is not there yet: stability/ is another owner's (see docs/conventions.md).
RATE_PENDING: dict[str, str] = {}
#: Results with levels, and the class that holds them.
RESULTS_WITH_TAUS = ["AllanVariance", "ImuAllanVariance", "RobustAllanVariance", "Deviation", "AvlrResult",
                     "ImuAvlrResult", "GmwmResult", "ImuGmwmResult", "AutoScales"]
HIDDEN_ALIASES = {"--freq", "--alpha", "--units", "--kalibr-axis"}
SECTION = re.compile(r"^(?P<indent>[ \t]*)(?P<title>Parameters|Attributes|Other Parameters)\n(?P=indent)-{3,}\n", re.M)


def public_callables() -> list[str]:
    return [name for name in avar.__all__ if callable(getattr(avar, name))]


#: A description that sends the reader to another function's: "As :func:`avar.oadev`."
REFERENCE = re.compile(r"^\s*As :func:`~?avar\.(\w+)`")


def documented(obj, depth: int = 0) -> dict[str, str]:
    """Parameter/attribute name -> its description, from the numpydoc sections of ``obj``'s docstring.

    A class's entries include those of its base classes (a result that extends another); a
    description "As :func:`avar.NAME`" is the one of that function.
    """
    entries: dict[str, str] = {}
    if inspect.isclass(obj):
        for base in reversed(obj.__mro__[1:-1]):
            entries.update(documented(base, depth))
    entries.update(_own_entries(obj))
    if depth < 4:
        for name, text in entries.items():
            match = REFERENCE.match(text)
            if match and hasattr(avar, match[1]):
                entries[name] = documented(getattr(avar, match[1]), depth + 1).get(name, text)
    return entries


def _own_entries(obj) -> dict[str, str]:
    doc = inspect.getdoc(obj) if not inspect.isclass(obj) else (obj.__doc__ and inspect.cleandoc(obj.__doc__)) or ""
    if inspect.isclass(obj) and "__init__" in vars(obj) and vars(obj)["__init__"].__doc__:
        doc += "\n\n" + inspect.cleandoc(vars(obj)["__init__"].__doc__)
    entries: dict[str, str] = {}
    for match in SECTION.finditer(doc):
        body = doc[match.end():]
        end = re.search(r"^\S.*\n-{3,}\n", body, re.M)
        body = body[:end.start()] if end else body
        names: list[str] = []
        for line in body.splitlines():
            if line and not line[0].isspace():
                names = [n.strip() for n in line.split(":")[0].split(",")]
                for name in names:
                    entries.setdefault(name, "")
            elif names:
                for name in names:
                    entries[name] += " " + line.strip()
    return entries


def parameters(obj) -> dict[str, inspect.Parameter]:
    try:
        return dict(inspect.signature(obj).parameters)
    except (TypeError, ValueError):  # a builtin without a signature
        return {}


def is_hidden_alias(parameter: inspect.Parameter) -> bool:
    """A deprecated alias: keyword-only, default None (and, checked by the caller, undocumented)."""
    return parameter.kind is inspect.Parameter.KEYWORD_ONLY and parameter.default is None


# --------------------------------------------------------------------------- Python: signatures and docstrings
@pytest.mark.parametrize("name", public_callables())
def test_alpha_is_the_noise_exponent_only(name):
    obj = getattr(avar, name)
    docs, params = documented(obj), parameters(obj)
    if name in R_ALPHA:
        assert "confidence" in params and "alpha" in params and "confidence" in docs.get("alpha", "")
        return
    if "alpha" in docs:
        text = docs["alpha"].lower()
        assert "noise" in text or "exponent" in text, f"{name}: alpha documented as {docs['alpha']!r}"
    elif "alpha" in params:  # the deprecated 1 - confidence: undocumented, keyword-only, None
        assert is_hidden_alias(params["alpha"]), f"{name}: alpha is neither documented nor a hidden alias"
        assert "confidence" in params and "confidence" in docs, f"{name}: alpha without confidence"
    for entry, text in docs.items():  # no other name documents a significance level
        if entry != "alpha":
            assert not re.search(r"\b1 - (the )?confidence\b", text), f"{name}.{entry}: {text!r}"


@pytest.mark.parametrize("name", public_callables())
def test_freq_only_where_r_has_it(name):
    obj = getattr(avar, name)
    params, docs = parameters(obj), documented(obj)
    if name in RATE_PENDING and "rate" not in params:
        pytest.xfail(RATE_PENDING[name])
    if "freq" not in params:
        return
    if name in R_FREQ:
        if name in ("avar", "avlr", "IMU"):
            assert "rate" in params and "rate" in docs, f"{name}: R's freq= without rate="
        return
    assert is_hidden_alias(params["freq"]) and "freq" not in docs, f"{name}: a public freq= parameter"
    assert "rate" in params and "rate" in docs


@pytest.mark.parametrize("name", RESULTS_WITH_TAUS)
def test_results_expose_taus(name):
    cls = getattr(avar, name)
    assert isinstance(inspect.getattr_static(cls, "taus", None), property) or "taus" in parameters(cls)
    assert "taus" in documented(cls), f"{name}: taus is not documented"


@pytest.fixture(scope="module")
def results():
    """One instance of every result with levels, made by the library."""
    x = avar.WN(sigma2=1.0).simulate(4096, seed=1)
    imu = avar.IMU(np.column_stack([x, x[::-1]]), rate=10.0, gyro=[0], accel=[1])
    av, imu_av = avar.avar(x, freq=10.0), avar.avar(imu)
    return {
        "AllanVariance": av, "ImuAllanVariance": imu_av, "RobustAllanVariance": avar.robust_avar(x, 10.0),
        "Deviation": avar.oadev(x, rate=10.0), "AvlrResult": avar.avlr(av, wn=range(1, 5)),
        "ImuAvlrResult": avar.avlr(imu_av, wn_gyro=range(1, 5), wn_acc=range(1, 5)),
        "GmwmResult": avar.gmwm(x, "WN"), "ImuGmwmResult": avar.gmwm(imu, model_gyro="WN", model_acc="WN"),
        "AutoScales": avar.auto_scales(av),
    }


def test_every_result_has_taus_in_seconds_and_the_old_names_alias_the_new(results):
    for name, result in results.items():
        assert isinstance(result, getattr(avar, name))
        taus = np.asarray(result.taus)
        assert taus.ndim == 1 and taus.size and np.all(np.diff(taus) > 0), name
    av, imu_av = results["AllanVariance"], results["ImuAllanVariance"]
    assert av.taus is av.levels and av.n_samples == av.n == 4096
    np.testing.assert_array_equal(av.taus, av.averaging_factors / 10.0)
    np.testing.assert_array_equal(imu_av.taus, imu_av["Gyro. X"].levels)
    assert imu_av.n_samples == imu_av.n == 4096
    assert results["AvlrResult"].taus is av.levels and results["AutoScales"].taus is results["AutoScales"].levels
    np.testing.assert_array_equal(results["ImuGmwmResult"].taus, results["ImuGmwmResult"].imu_av.taus)
    dev = results["Deviation"]
    assert dev.n_terms is dev.n and dev.n_samples == 4096
    outliers = results["RobustAllanVariance"].outliers
    assert outliers.n_samples == outliers.n == 4096


# --------------------------------------------------------------------------- Python: old spellings warn, same numbers
X = avar.WN(sigma2=1e-4).simulate(20_000, seed=2) + avar.RW(gamma2=1e-9).simulate(20_000, seed=3)


def warns(call, *names):
    """``call()`` under a DeprecationWarning that names every one of ``names``; its value."""
    with pytest.warns(DeprecationWarning) as caught:
        value = call()
    text = " ".join(str(w.message) for w in caught if issubclass(w.category, DeprecationWarning))
    for name in names:
        assert name in text, f"{name!r} not in {text!r}"
    assert "0.3.0" in text
    return value


def silent(call):
    """``call()`` with every warning an error: the new spellings warn of nothing."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return call()


def test_gmwm_alpha_warns_and_equals_confidence():
    old = warns(lambda: avar.gmwm(X, "WN + RW", ci=True, B=10, seed=4, alpha=0.1), "alpha=", "confidence")
    new = silent(lambda: avar.gmwm(X, "WN + RW", ci=True, B=10, seed=4, confidence=0.9))
    pd.testing.assert_frame_equal(old.ci, new.ci)
    assert new.confidence == 0.9 and old.confidence == 0.9
    assert warns(lambda: new.alpha, "alpha", "confidence") == pytest.approx(0.1)
    with pytest.raises(TypeError, match="confidence.*alpha"):
        avar.gmwm(X, "WN", confidence=0.9, alpha=0.1)


def test_noise_report_alpha_and_freq_warn_and_equal_confidence_and_rate():
    old = warns(lambda: avar.noise_report(X, gyro_units="deg/s", freq=50.0, alpha=0.1), "alpha=", "confidence",
                "freq=", "rate=")
    new = silent(lambda: avar.noise_report(X, gyro_units="deg/s", rate=50.0, confidence=0.9))
    pd.testing.assert_frame_equal(old.table, new.table)
    assert (new.rate, new.n_samples, new.confidence) == (50.0, X.size, 0.9)
    assert (new.freq, new.n) == (new.rate, new.n_samples)
    assert warns(lambda: new.alpha, "alpha", "confidence") == pytest.approx(0.1)
    with pytest.raises(TypeError, match="rate.*freq"):
        avar.noise_report(X, rate=50.0, freq=50.0)


def test_avlr_keeps_r_alpha_and_freq_without_a_warning():
    new = silent(lambda: avar.avlr(X, wn=range(1, 6), ci=True, B=10, seed=5, confidence=0.9, rate=50.0))
    old = silent(lambda: avar.avlr(X, wn=range(1, 6), ci=True, B=10, seed=5, alpha=0.1, freq=50.0))
    pd.testing.assert_frame_equal(old.ci, new.ci)
    assert new.av.freq == 50.0 and new.confidence == 0.9
    assert warns(lambda: new.alpha, "alpha", "confidence") == pytest.approx(0.1)
    with pytest.raises(TypeError, match="confidence.*alpha"):
        avar.avlr(X, wn=range(1, 6), confidence=0.9, alpha=0.1)
    with pytest.raises(TypeError, match="rate.*freq"):
        avar.avlr(X, wn=range(1, 6), rate=50.0, freq=50.0)
    with pytest.raises(ValueError, match="rate applies to a series"):
        avar.avlr(avar.avar(X), wn=range(1, 6), rate=50.0)


def test_imu_keeps_r_freq_without_a_warning():
    data = np.column_stack([X, X[::-1]])
    new = silent(lambda: avar.IMU(data, rate=50.0, gyro=[0], accel=[1]))
    old = silent(lambda: avar.IMU(data, freq=50.0, gyro=[0], accel=[1]))
    assert new.rate == old.rate == new.freq == 50.0 and new.n_samples == new.n == X.size
    np.testing.assert_array_equal(avar.avar(new)["Gyro. X"].allan, avar.avar(old)["Gyro. X"].allan)
    with pytest.raises(TypeError, match="rate.*freq"):
        avar.IMU(data, 50.0, gyro=[0], accel=[1], freq=50.0)
    with pytest.raises(ValueError, match="freq must be a finite number"):  # the spelling given is named
        avar.IMU(data, freq=-1.0, gyro=[0], accel=[1])


def test_read_and_recording_freq_warn_and_equal_rate(tmp_path):
    path = tmp_path / "x.csv"
    pd.DataFrame({"gx": X}).to_csv(path, index=False)
    new = silent(lambda: avar.read(path, rate=50.0))
    old = warns(lambda: avar.read(path, freq=50.0), "freq=", "rate=")
    assert new.rate == old.rate == new.freq == 50.0 and new.n_samples == X.size
    np.testing.assert_array_equal(new["gx"], old["gx"])
    with pytest.raises(ValueError, match="rate must be a finite number"):
        avar.read(path, rate=0.0)
    with pytest.raises(TypeError, match="rate.*freq"):
        avar.read(path, rate=50.0, freq=50.0)
    made = silent(lambda: avar.Recording({"gx": X}, rate=50.0))
    again = warns(lambda: avar.Recording({"gx": X}, freq=50.0), "freq=", "rate=")
    assert made.rate == again.rate == 50.0 and made.rate_source == "given"


def test_noise_report_takes_the_recording_and_the_imu_as_read(tmp_path):
    path = tmp_path / "log.csv"
    frame = pd.DataFrame({"time": np.arange(X.size) / 50.0, "gyro_x": X, "acc_x": X[::-1].copy()})
    frame.to_csv(path, index=False, float_format="%.17g")
    recording = avar.read(path)
    imu = avar.read(path, gyro="gyro_x", accel="acc_x")
    assert isinstance(recording, avar.Recording) and isinstance(imu, avar.IMU)
    from_recording = silent(lambda: avar.noise_report(recording, gyro_units="dps", accel_units="g", topic="/imu"))
    from_imu = silent(lambda: avar.noise_report(imu, gyro_units="deg/s", accel_units="g"))
    from_frame = silent(lambda: avar.noise_report(frame[["gyro_x", "acc_x"]], gyro_units="deg/s", accel_units="g",
                                                  rate=recording.rate))
    for report in (from_imu, from_frame):
        pd.testing.assert_frame_equal(report.table, from_recording.table)
    assert from_recording.source == str(path) and from_recording.name == str(path) and from_recording.topic == "/imu"
    assert from_imu.name == "log" and from_imu.source is None
    assert "SimpleNamespace" not in (ROOT / "src/avar/cli/imu/report.py").read_text()


def test_units_are_one_table_in_python():
    assert {"deg/s", "dps", "rad/s", "deg/h"} <= set(UNIT_SPELLINGS[GYRO])
    assert {"g", "m/s^2", "mg"} <= set(UNIT_SPELLINGS[ACCEL])
    for kind, spellings in UNIT_SPELLINGS.items():
        for spelling in spellings:
            assert check_unit(spelling.upper(), kind, "x") == check_unit(spelling, kind, "x")


# --------------------------------------------------------------------------- the command line: the parsers
def subparsers() -> dict[str, argparse.ArgumentParser]:
    root = build_parser()
    return dict(next(a for a in root._actions if isinstance(a, argparse._SubParsersAction)).choices)


SUBPARSERS = subparsers()
#: Subcommands that take a sampling rate, a confidence level, data units.
TAKES_RATE = {"compute", "fit", "report", "deviation", "clock-report", "simulate"}
TAKES_CONFIDENCE = {"fit", "report", "deviation", "clock-report"}
TAKES_UNITS = {"compute", "fit", "report"}


def options(parser: argparse.ArgumentParser) -> dict[str, argparse.Action]:
    return {o: a for a in parser._actions for o in a.option_strings if not isinstance(a, argparse._HelpAction)}


@pytest.mark.parametrize("command", sorted(SUBPARSERS))
def test_every_subcommand_describes_itself_and_every_option(command):
    parser = SUBPARSERS[command]
    assert parser.description and len(parser.description) > 20, f"avar {command} --help has no description"
    help_text = parser.format_help()
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        if action.help == argparse.SUPPRESS:
            assert set(action.option_strings) <= HIDDEN_ALIASES, f"{command}: {action.option_strings} hidden"
            continue
        assert action.help and len(action.help) > 10, f"avar {command} {action.option_strings or action.dest}"
        if action.option_strings and not action.required:
            assert "default" in action.help, f"avar {command} {action.option_strings[0]}: no default in its help"
    for hidden in sorted(HIDDEN_ALIASES):
        assert not re.search(rf"(?<![\w-]){re.escape(hidden)}\b", help_text), f"avar {command} --help shows {hidden}"
    given = options(parser)
    assert ("--rate" in given) == (command in TAKES_RATE)
    assert ("--confidence" in given) == (command in TAKES_CONFIDENCE)
    assert ({"--gyro-units", "--accel-units"} <= set(given)) == (command in TAKES_UNITS)
    if "--rate" in given:
        assert "Hz" in given["--rate"].help and "--freq" in given  # R's name stays an alias
    if "--confidence" in given:
        assert "probability" in given["--confidence"].help


def test_an_option_means_the_same_in_every_subcommand():
    meaning: dict[str, dict] = {}
    for command, parser in SUBPARSERS.items():
        for option, action in options(parser).items():
            key = (action.dest, action.type, type(action).__name__, action.nargs,
                   tuple(action.choices) if action.choices else None)
            meaning.setdefault(option, {}).setdefault(key, []).append(command)
    differing = {option: keys for option, keys in meaning.items() if len(keys) > 1}
    assert not differing, differing


@pytest.mark.parametrize("command", sorted(TAKES_UNITS))
def test_every_subcommand_takes_the_units_python_takes(command):
    parser = SUBPARSERS[command]
    for option, kind in (("--gyro-units", GYRO), ("--accel-units", ACCEL)):
        for spelling in UNIT_SPELLINGS[kind]:
            for typed in (spelling, spelling.upper()):
                args = parser.parse_args(["x.csv", option, typed])
                assert getattr(args, option[2:].replace("-", "_")) == check_unit(typed, kind, "x")


# --------------------------------------------------------------------------- the command line: real runs
@pytest.fixture(scope="module")
def log(tmp_path_factory):
    """A 50 Hz log with a time column, two gyroscopes and an accelerometer."""
    path = tmp_path_factory.mktemp("vocabulary") / "imu.csv"
    pd.DataFrame({"time": np.arange(X.size) / 50.0, "gx": X, "gy": X[::-1].copy(), "ax": X[::2].repeat(2)}).to_csv(
        path, index=False, float_format="%.17g")
    return path


def run(capsys, *args) -> tuple[int, str, str]:
    return cli(capsys, *args)


def test_fit_alpha_is_a_deprecated_confidence(log, capsys, tmp_path):
    old, new = tmp_path / "old.csv", tmp_path / "new.csv"
    common = [log, "--column", "gx", "--wn", "1:6", "--ci", "--B", "10", "--seed", "2"]
    code, _, err = run(capsys, "fit", *common, "--alpha", "0.1", "--output", old)
    assert code == 0, err
    assert "--alpha is deprecated" in err and "--confidence 0.9" in err and "0.3.0" in err
    code, _, err = run(capsys, "fit", *common, "--confidence", "0.9", "--output", new)
    assert code == 0 and "deprecated" not in err, err
    assert old.read_text() == new.read_text()
    code, _, err = run(capsys, "fit", *common, "--alpha", "0.1", "--confidence", "0.9")
    assert code == 2 and "--confidence" in err and "--alpha" in err


def test_report_alpha_is_a_deprecated_confidence_and_the_numbers_are_the_librarys(log, capsys, tmp_path):
    old, new = tmp_path / "old.csv", tmp_path / "new.csv"
    common = [log, "--gyro", "gx", "--gyro-units", "DPS"]
    code, _, err = run(capsys, "report", *common, "--alpha", "0.1", "--output", old)
    assert code == 0, err
    assert "--alpha is deprecated" in err and "--confidence 0.9" in err
    code, _, err = run(capsys, "report", *common, "--confidence", "0.9", "--output", new)
    assert code == 0 and "deprecated" not in err, err
    assert old.read_text() == new.read_text()
    expected = avar.noise_report(avar.read(log, columns=["gx"]), gyro_units="deg/s", confidence=0.9)
    got = pd.read_csv(new)
    np.testing.assert_allclose(got.loc[got["Process"] == "WN", "Value"], expected.table.loc[
        expected.table["Process"] == "WN", "Value"].astype(float), rtol=1e-12)


def test_freq_is_an_alias_of_rate(log, capsys, tmp_path):
    by_rate, by_freq = tmp_path / "rate.csv", tmp_path / "freq.csv"
    code, _, err = run(capsys, "compute", log, "--column", "gx", "--rate", "25", "--output", by_rate)
    assert code == 0 and "(--rate)" in err, err
    code, _, err = run(capsys, "compute", log, "--column", "gx", "--freq", "25", "--output", by_freq)
    assert code == 0 and "(--freq)" in err and "deprecated" not in err, err
    assert by_rate.read_text() == by_freq.read_text()
    code, _, err = run(capsys, "compute", log, "--rate", "25", "--freq", "25")
    assert code == 2 and "--rate" in err and "--freq" in err
    code, _, err = run(capsys, "deviation", log, "--column", "gx", "--data-type", "freq", "--rate", "-1")
    assert code == 2 and "--rate must be a finite number > 0" in err


def test_fit_units_is_deprecated_for_gyro_and_accel_units(log, capsys, tmp_path):
    old, new = tmp_path / "old.csv", tmp_path / "new.csv"
    common = [log, "--gyro", "gx", "gy", "--accel", "ax", "--wn", "1:5"]
    code, _, err = run(capsys, "fit", *common, "--units", "gyro=deg/s", "--units", "accel=g", "--output", old)
    assert code == 0, err
    assert "--units is deprecated" in err and "--gyro-units" in err
    code, _, err = run(capsys, "fit", *common, "--gyro-units", "dps", "--accel-units", "g", "--output", new)
    assert code == 0 and "deprecated" not in err, err
    assert old.read_text() == new.read_text() and "deg/s" in new.read_text()


def test_compute_takes_units_for_an_imu_and_refuses_two_for_one_series(log, capsys, tmp_path):
    code, _, err = run(capsys, "compute", log, "--gyro", "gx", "--accel", "ax", "--gyro-units", "deg/sec",
                       "--accel-units", "milli-g", "--plot", tmp_path / "imu.png")
    assert code == 0, err
    code, _, err = run(capsys, "compute", log, "--column", "gx", "--gyro-units", "dps", "--accel-units", "g")
    assert code == 2 and "not both" in err
    code, _, err = run(capsys, "compute", log, "--column", "gx", "--gyro-units", "rpm")
    assert code == 2 and "--gyro-units" in err and "dps" in err
