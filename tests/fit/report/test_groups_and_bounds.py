"""The report's groups (IEEE 952 / sensor filtering), its one wording of a bound, and the AD minimum's marker."""

import math

import numpy as np
import pytest

import avar
from avar.fit.report.rows import (
    FILTER_SAMPLES,
    IEEE_952,
    ROW_COLUMNS,
    SENSOR_FILTERING,
    bound_words,
    group_of,
)
from avar.fit.report.sensor_fit import term_bound
from avar.models import AR1, FN, SIN, WN

RATE = 100.0


@pytest.fixture(scope="module")
def report():
    """White noise, a 10 Hz line and a 2-sample Gauss-Markov term (the sensor's filtering), a 0.2 Hz line."""
    model = WN(sigma2=1.0) + SIN(a2=2.0, f=0.1) + AR1(phi=math.exp(-1 / 2.0), sigma2=2.0) + SIN(a2=0.5, f=0.002) \
        + FN(b2=1e-4)
    return avar.noise_report(model.simulate(2**17, seed=4), rate=RATE)


def test_the_filtering_criterion_is_where_the_deviation_peaks():
    # a Gauss-Markov deviation peaks at 1.89 T, a sinusoid's at 0.371 / f0: filtering up to 16 samples
    edge_time = FILTER_SAMPLES / 1.89
    assert group_of("AR1", math.exp(-1 / (0.99 * edge_time))) == SENSOR_FILTERING
    assert group_of("AR1", math.exp(-1 / (1.01 * edge_time))) == IEEE_952
    edge_frequency = 0.371 / FILTER_SAMPLES  # cycles per sample: rate / 43
    assert group_of("SIN", 1.01 * edge_frequency) == SENSOR_FILTERING
    assert group_of("SIN", 0.99 * edge_frequency) == IEEE_952
    assert all(group_of(kind, None) == IEEE_952 for kind in ("QN", "WN", "FN", "RW", "DR"))


def test_the_table_groups_every_term(report):
    table = report.table
    assert list(table.columns) == ROW_COLUMNS and ROW_COLUMNS.index("Group") == ROW_COLUMNS.index("Note") - 1
    group = dict(zip(table["Process"], table["Group"]))
    assert {p: group[p] for p in ("QN", "WN", "FN", "RW", "DR", "MIN")} == dict.fromkeys(
        ("QN", "WN", "FN", "RW", "DR", "MIN"), IEEE_952)
    frequencies = {round(float(table.set_index("Process").loc[f"SIN_{k}.f", "Value"])): k for k in (1, 2)}
    fast, slow = frequencies[10], frequencies[0]
    assert group[f"SIN_{fast}"] == group[f"SIN_{fast}.f"] == SENSOR_FILTERING
    assert group[f"SIN_{slow}"] == IEEE_952
    assert group["AR1_1"] == group["AR1_1.T"] == SENSOR_FILTERING
    assert float(table.set_index("Process").loc["AR1_1.T", "Value"]) == pytest.approx(0.02, rel=0.15)


def test_the_summary_prints_sensor_filtering_apart(report):
    text = str(report).splitlines()
    header = next(k for k, line in enumerate(text) if line.strip().startswith(SENSOR_FILTERING))
    after = "\n".join(text[header:])
    before = "\n".join(text[:header])
    assert "Gauss-Markov 1 sigma" in after and "Angle random walk" not in after and "White noise" in before
    assert "AD minimum" in before


def test_the_legend_has_a_sensor_filtering_section(report):
    labels = [line.get_label() for line in report.plot().axes[0].lines]
    at = labels.index(f"{SENSOR_FILTERING}:")
    assert any(label.startswith("Gauss-Markov 1") for label in labels[at:])
    assert not any(label.startswith("Gauss-Markov") for label in labels[:at])


def test_one_wording_of_a_bound_names_its_quantile(report):
    assert bound_words(0.95) == "one-sided 97.5 % upper bound" and bound_words(0.9) == "one-sided 95 % upper bound"
    table = report.table.set_index("Process")
    assert table.loc["RW", "Status"] == "bound"
    assert table.loc["RW", "Note"] == f"not resolved by the data: {bound_words(0.95)}"
    assert f"({bound_words(0.95)}, not resolved)" in str(report) and "95 % bound" not in str(report)
    # the number is what the words say: the 97.5 % one-sided quantile of the enlarged model's scale
    per_sample = term_bound(report.fits["x"], "RW", 0.975)
    assert float(table.loc["RW", "Upper"]) == pytest.approx(math.sqrt(per_sample * RATE), rel=1e-9)
    lower = term_bound(report.fits["x"], "RW", 0.95)
    assert float(table.loc["RW", "Upper"]) > math.sqrt(max(lower, 0.0) * RATE)


def test_the_minimum_marker_sits_on_the_minimum_row(report):
    row = report.table.set_index("Process").loc["MIN"]
    av = report.avs["x"]
    at = int(np.argmin(np.abs(np.asarray(av.levels) - float(row["Tau (s)"]))))
    assert float(row["Value"]) == pytest.approx(float(av.adev[at]), rel=1e-12)
    star = next(line for line in report.plot().axes[0].lines if line.get_label().startswith("AD minimum"))
    assert float(star.get_xdata()[0]) == float(row["Tau (s)"]) and float(star.get_ydata()[0]) == float(av.adev[at])
