"""Hostile inputs, round four: names from data reach every sink escaped (issue 38).

Channel and file names that hold line breaks, YAML document markers, ESC sequences, a
right-to-left override, HTML tags or mathtext are written to disk and read back through
the real command (a subprocess) or the public API; each sink (YAML, terminal, HTML,
matplotlib) must show them, never obey them.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml

import avar
from avar._escape import figure_text, html_text, terminal, terminal_lines, yaml_comment, yaml_entry
from tests._support.subprocess_cli import run_avar

RATE = 100.0
N = 8192
#: Names that broke a sink in issue 38, one per way of breaking it.
HOSTILE = {
    "key": "gyro_x\naccelerometer_noise_density: 5.0",
    "document": "gz\n---\nfoo: 1\n...",
    "escape": "g\x1b[2Jy\ry",
    "breaks": "a\u2028b\x85c",
    "override": "w\u202eq",
    "html": "gyro<img src=x onerror=alert(1)>",
    "mathtext": "r$\\undefinedcommand$",
}
GYRO_KEYS = {"gyroscope_noise_density", "gyroscope_random_walk", "rostopic", "update_rate"}
#: What a terminal must never receive raw: escape, carriage return, bell, the overrides.
RAW = ("\x1b", "\r", "\x07", "\u202e", "\u2028", "\x85")


@pytest.fixture(scope="module")
def hostile_log(tmp_path_factory):
    """A gyro-only ``.npz`` log whose channels carry the hostile names, in a file named hostilely too."""
    folder = tmp_path_factory.mktemp("names")
    rng = np.random.default_rng(38)
    path = folder / "log\n---\nrostopic: evil\x1b[31m.npz"
    np.savez(path, time=np.arange(N) / RATE, **{name: rng.standard_normal(N) * 1e-3 for name in HOSTILE.values()})
    return path


def _no_raw_controls(text: str) -> bool:
    return not any(character in text for character in RAW)


# --------------------------------------------------------------------------- the escapes themselves
def test_each_escape_makes_its_sink_inert():
    name = "a\nb: 1\x1b[2J\u202e$x$<i>"
    assert "\n" not in terminal(name) and terminal(name).isprintable()
    assert terminal_lines("a\x1b[2J\nb\u202e\r") == "a\\x1b[2J\nb\\u202e\\r"  # the table's own line breaks kept
    assert yaml.safe_load(f"{yaml_comment(name)}\n{yaml_entry('rostopic', name)}\n") == {"rostopic": name}
    assert html_text(name).count("<") == 0 and "&lt;i&gt;" in html_text(name)
    assert figure_text(name).count("$") == figure_text(name).count("\\$") == 2


# --------------------------------------------------------------------------- YAML
def test_report_kalibr_yaml_holds_exactly_the_kalibr_keys(hostile_log, tmp_path):
    """The cause: a channel name with a newline wrote its own key (exit 0); ESC, CR, --- made it unparseable."""
    kalibr, terms = tmp_path / "imu.yaml", tmp_path / "terms.csv"
    run = run_avar("report", hostile_log, "--gyro", *HOSTILE.values(), "--gyro-units", "rad/s",
                   "--topic", "/imu\n---\n...", "--kalibr", kalibr, "--output", terms)
    assert run.code == 0, run.stderr
    loaded = yaml.safe_load(kalibr.read_text(encoding="utf-8"))
    assert set(loaded) == GYRO_KEYS
    assert loaded["rostopic"] == "/imu\n---\n..." and loaded["update_rate"] == RATE
    assert 0 < loaded["gyroscope_noise_density"] < 1e-3  # a density, not the planted 5.0
    # the terminal: the report on stdout and the note naming the file on stderr are escaped
    assert _no_raw_controls(run.stdout) and _no_raw_controls(run.stderr)
    assert "g\\x1b[2Jy\\ry (gyroscope)" in run.stdout and "w\\u202eq (gyroscope)" in run.stdout
    assert "gyro_x\\naccelerometer_noise_density: 5.0 (gyroscope)" in run.stdout
    assert "log\\n---\\nrostopic: evil\\x1b[31m.npz" in run.stderr


def test_report_figure_and_page_with_html_and_mathtext_names(hostile_log, tmp_path):
    """mathtext in a name aborted --plot/--html (and lost the yaml of the run); a tag became live HTML."""
    figure, page, kalibr = tmp_path / "r.png", tmp_path / "r.html", tmp_path / "imu.yaml"
    run = run_avar("report", hostile_log, "--gyro", HOSTILE["html"], HOSTILE["mathtext"], "--gyro-units", "rad/s",
                   "--plot", figure, "--html", page, "--kalibr", kalibr)
    assert run.code == 0, run.stderr
    assert figure.read_bytes().startswith(b"\x89PNG") and set(yaml.safe_load(kalibr.read_text())) == GYRO_KEYS
    text = page.read_text(encoding="utf-8")
    assert "<img src=x" not in text and "gyro&lt;img src=x onerror=alert(1)&gt;" in text


def test_python_kalibr_text_and_to_kalibr_with_a_hostile_name(tmp_path):
    x = (avar.WN(sigma2=1e-6) + avar.RW(gamma2=1e-12)).simulate(20_000, seed=3)
    for name in HOSTILE.values():
        report = avar.noise_report(x, gyro_units="rad/s", rate=RATE, name=name)
        assert set(yaml.safe_load(report.kalibr_text())) == GYRO_KEYS
        path = report.to_kalibr(tmp_path / "imu.yaml", force=True, rostopic=name)
        loaded = yaml.safe_load(path.read_text(encoding="utf-8"))
        assert set(loaded) == GYRO_KEYS and loaded["rostopic"] == name
        assert loaded["gyroscope_noise_density"] == pytest.approx(report.kalibr()["gyroscope_noise_density"])


# --------------------------------------------------------------------------- terminals
def test_deviation_prints_file_and_column_names_escaped(tmp_path):
    path = tmp_path / "clock\x1b[2J\u202e.csv"
    pd.DataFrame({"ph\x1b[31m\u202ease": np.random.default_rng(1).random(500)}).to_csv(path, index=False)
    run = run_avar("deviation", path, "--data-type", "phase")
    assert run.code == 0, run.stderr
    assert _no_raw_controls(run.stdout + run.stderr)
    assert run.stdout.startswith("clock\\x1b[2J\\u202e.csv [ph\\x1b[31m\\u202ease]: OADEV")
    missing = run_avar("deviation", tmp_path / "gone\x1b[2J.csv", "--data-type", "phase")
    assert missing.code == 1 and _no_raw_controls(missing.stderr) and "gone\\x1b[2J.csv: no such file" in missing.stderr


# --------------------------------------------------------------------------- notebooks (HTML)
def test_repr_html_of_every_result_escapes_names(tmp_path):
    name = HOSTILE["html"]
    path = tmp_path / f"{name}.csv"
    rng = np.random.default_rng(5)
    columns = {"time": np.arange(4096) / RATE, name: rng.standard_normal(4096) * 1e-3,
               "gy": rng.standard_normal(4096) * 1e-3}
    pd.DataFrame(columns).to_csv(path, index=False)
    imu = avar.read(path, gyro=[name, "gy"])
    imu_av = avar.avar(imu)
    series_av = imu_av.channels[name]  # a result named after its column
    assert series_av.name == name
    results = {
        "ImuAllanVariance": imu_av,
        "ImuAvlrResult": avar.avlr(imu_av, wn_gyro=range(1, 5)),
        "NoiseReport": avar.noise_report(imu, gyro_units="rad/s"),
        "AllanVariance": series_av,
        "AvlrResult": avar.avlr(series_av, wn=range(1, 5)),
        "Deviation": avar.oadev(columns[name], rate=RATE),
    }
    for kind, result in results.items():
        page = result._repr_html_()
        assert "<img" not in page, kind
    for kind in ("ImuAllanVariance", "ImuAvlrResult", "NoiseReport", "AllanVariance"):
        assert "&lt;img src=x onerror=alert(1)&gt;" in results[kind]._repr_html_(), kind


# --------------------------------------------------------------------------- figures (matplotlib)
def test_mathtext_in_names_is_drawn_literally_and_the_run_keeps_its_files(tmp_path):
    name = HOSTILE["mathtext"]
    path = tmp_path / "clock$\\frac.csv"
    pd.DataFrame({name: np.random.default_rng(2).standard_normal(1000)}).to_csv(path, index=False)
    figure, table = tmp_path / "d.png", tmp_path / "d.csv"
    run = run_avar("deviation", path, "--data-type", "freq", "--plot", figure, "--output", table)
    assert run.code == 0, run.stderr
    assert figure.read_bytes().startswith(b"\x89PNG") and table.read_text().startswith("Stat,AF,Tau")
    x = (avar.WN(sigma2=1e-6) + avar.RW(gamma2=1e-12)).simulate(20_000, seed=3)
    frame = pd.DataFrame({name: x})
    report = avar.noise_report(frame, gyro=[name], gyro_units="rad/s", rate=RATE, name=name)
    fig = report.plot()
    fig.canvas.draw()  # mathtext would raise here
    assert fig.axes[0].get_title() == figure_text(name) + " (gyroscope)"
    assert fig._suptitle.get_text() == f"Noise report: {figure_text(name)}"
