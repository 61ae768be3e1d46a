"""``avar.noise_reports``: several logs of one sensor, pooled terms, the test of agreement and the spread."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

import avar
from avar.fit.report.sessions.agreement import bartlett, level_tests, term_spread
from avar.fit.report.sessions.pooling import pooled_allan

RATE = 100.0
SIGMA2, GAMMA2 = 1e-4, 1e-10          # white noise and random walk, per-sample variances (rad/s)^2
MODEL = avar.WN(sigma2=SIGMA2) + avar.RW(gamma2=GAMMA2)
N = 20_000


def logs_of(seed: int, k: int = 3, n: int = N) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [MODEL.simulate(n, seed=rng) for _ in range(k)]


@pytest.mark.parametrize("seed", [11, 12, 13])
def test_three_logs_of_one_model_agree_and_pool(seed):
    several = avar.noise_reports(logs_of(seed), gyro_units="rad/s", rate=RATE, progress=False)
    assert several.agree and several.disagreements == () and several.n_tests == len(several.agreement)
    assert several.pooled.n_samples == 3 * N
    # the pooled angle random walk: sqrt(sigma2 / rate) rad/s/sqrt(Hz), inside its 95 % interval
    row = several.pooled.table.set_index("Process").loc["WN"]
    truth = math.sqrt(SIGMA2 / RATE)
    assert row["Lower"] <= truth <= row["Upper"]
    # pooling narrows the interval: about sqrt(3) narrower than one log's
    one = several.reports[0].table.set_index("Process").loc["WN"]
    ratio = (one["Upper"] - one["Lower"]) / (row["Upper"] - row["Lower"])
    assert 1.4 < ratio < 2.1


def test_a_log_with_doubled_white_noise_is_named_with_its_channel_and_term():
    logs = logs_of(21)
    logs[1] = avar.WN(sigma2=4 * SIGMA2).simulate(N, seed=5) + avar.RW(gamma2=GAMMA2).simulate(N, seed=6)
    several = avar.noise_reports({"a": logs[0], "b": logs[1], "c": logs[2]}, gyro_units="rad/s", rate=RATE,
                                 progress=False)
    assert not several.agree and several.disagreeing == ("b",)
    (found,) = several.disagreements
    assert found.channel == "x" and "(WN)" in found.term and found.tau == pytest.approx(1 / RATE)
    assert found.ratio == pytest.approx(4.0, rel=0.1)   # its Allan variance at tau0 over the others'
    assert any(w.startswith("b: disagrees with the other logs in channel x") for w in several.warnings)
    assert "b: N = 20000 at 100 Hz; disagrees in x" in str(several)
    spread = several.spread.set_index("Process").loc["WN"]
    assert spread["Max/min"] == pytest.approx(2.0, rel=0.05) and spread["Excess SD (%)"] > 20


def test_two_logs_in_disagreement_are_both_named():
    a, b = logs_of(31, k=2)
    several = avar.noise_reports([a, 3 * b], gyro_units="rad/s", rate=RATE, progress=False)
    assert several.disagreeing == ("log 1", "log 2")


def test_bartlett_statistic_equals_scipys_on_samples():
    """Bartlett's statistic of sample variances with n_i - 1 degrees of freedom is scipy.stats.bartlett's."""
    from scipy.stats import bartlett as scipy_bartlett

    rng = np.random.default_rng(3)
    samples = [rng.normal(0, s, n) for s, n in ((1.0, 30), (1.3, 45), (0.8, 12))]
    values = np.array([[np.var(x, ddof=1)] for x in samples])
    edf = np.array([[x.size - 1.0] for x in samples])
    statistic, p = bartlett(values, edf)
    want = scipy_bartlett(*samples)
    assert statistic[0] == pytest.approx(want.statistic, rel=1e-12) and p[0] == pytest.approx(want.pvalue, rel=1e-9)


def test_the_level_tests_are_calibrated_on_white_noise():
    """Real Allan variances of white noise: each level's p-value is uniform (rate at 10 % near 10 %), and the
    Bonferroni family over the levels stays below its 5 %."""
    rng = np.random.default_rng(0)
    p_values = []
    for _ in range(200):
        avs = [avar.avar(rng.standard_normal(2048), "mo", 1.0) for _ in range(3)]
        tests = level_tests("x", avs, lambda m: 1.0 / np.asarray(m, dtype=float))
        p_values.append(bartlett(tests.values, tests.edf)[1])
    p_values = np.array(p_values)
    well_resolved = p_values[:, tests.edf[0] > 20]          # levels with > 20 degrees of freedom
    rate = float(np.mean(well_resolved < 0.10))
    assert 0.065 < rate < 0.135, rate                         # 200 x 7 correlated tests: sd ~ 0.01-0.02
    family = float(np.mean((p_values < 0.05 / p_values.shape[1]).any(axis=1)))
    assert family <= 0.08, family


def test_term_spread_is_dersimonian_laird_on_the_log_scale():
    values = np.exp([0.0, 0.2, 0.4])
    row = term_spread("gx", "WN", "Angle random walk", "rad/s/sqrt(Hz)", values, np.full(3, 0.05))
    # w = 400, Q = 400 (0.04 + 0 + 0.04) = 32, W - sum w^2 / W = 1200 - 400 = 800, tau^2 = 30 / 800
    assert row["Q"] == pytest.approx(32.0, rel=1e-12)
    assert row["Excess SD (%)"] == pytest.approx(100 * math.sqrt(30 / 800), rel=1e-12)
    assert row["Max/min"] == pytest.approx(math.exp(0.4), rel=1e-12) and row["Logs"] == 3


def test_pooled_allan_variance_is_the_plain_pooled_sum_of_squares():
    rng = np.random.default_rng(4)
    x, y = rng.standard_normal(1000), 2.0 * rng.standard_normal(1500)
    pooled = pooled_allan([avar.avar(x, "mo", 10.0), avar.avar(y, "mo", 10.0)])
    for m, value in zip(pooled.averaging_factors, pooled.allan):
        sums, count = 0.0, 0
        for series in (x, y):
            means = np.convolve(series, np.ones(m) / m, mode="valid")
            diffs = means[m:] - means[:-m]
            sums, count = sums + float(diffs @ diffs), count + diffs.size
        assert value == pytest.approx(sums / (2 * count), rel=1e-10)
    assert pooled.n == 2500 and pooled.averaging_factors.max() <= 500


def test_result_tables_summary_and_text():
    several = avar.noise_reports(logs_of(41), gyro_units="rad/s", rate=RATE, names=["u1", "u2", "u3"],
                                 progress=False)
    table = several.table
    assert list(table.columns[:2]) == ["Log", "Channel"]
    assert list(table["Log"].unique()) == ["pooled", "u1", "u2", "u3"]
    summary = several.summary()
    assert {"Pooled", "Lower", "Upper", "u1", "u2", "u3", "Max/min", "Excess SD (%)"} <= set(summary.columns)
    wn = summary.set_index("Process").loc["WN"]
    values = [wn[name] for name in ("u1", "u2", "u3")]
    assert wn["Max/min"] == pytest.approx(max(values) / min(values), rel=1e-9)
    text = str(several)
    assert text.startswith("Noise reports of 3 logs of one sensor (u1, u2, u3)") and "The logs agree" in text
    assert "Per log:" in text and "Pooled terms:" in text
    assert several.temperature.empty and repr(several).endswith("agree>")


def test_plot_overlays_every_log(monkeypatch):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    several = avar.noise_reports(logs_of(51, n=4000), gyro_units="rad/s", rate=RATE, progress=False)
    figure = several.plot()
    lines = [line.get_label() for ax in figure.axes for line in ax.get_lines()]
    assert sum(label.startswith("log ") for label in lines) >= 3


def test_errors_name_the_logs():
    with pytest.raises(ValueError, match="give at least 2"):
        avar.noise_reports(logs_of(1, k=1), gyro_units="rad/s", rate=RATE)
    frame = pd.DataFrame({"gx": logs_of(2, k=1)[0]})
    other = pd.DataFrame({"gy": logs_of(3, k=1)[0]})
    with pytest.raises(ValueError, match="'b' has the channels \\['gy'\\]"):
        avar.noise_reports({"a": frame, "b": other}, gyro_units="rad/s", rate=RATE, progress=False)
    with pytest.raises(ValueError, match="false_alarm must be a probability"):
        avar.noise_reports(logs_of(4, k=2, n=4000), rate=RATE, false_alarm=1.5, progress=False)


def test_logs_of_different_lengths_pool_on_their_common_levels():
    rng = np.random.default_rng(61)
    short, long = MODEL.simulate(8_000, seed=rng), MODEL.simulate(33_000, seed=rng)
    several = avar.noise_reports([short, long], gyro_units="rad/s", rate=RATE, progress=False)
    assert several.agree and several.pooled.n_samples == 41_000
    common = set(several.reports[0].avs["x"].averaging_factors) & set(several.reports[1].avs["x"].averaging_factors)
    assert set(several.agreement["m"]) == common == set(several.pooled.avs["x"].averaging_factors)


def test_logs_at_different_rates_are_refused():
    a, b = logs_of(62, k=2, n=4000)
    with pytest.raises(ValueError, match="the rates differ by more than 1 %"):
        avar.noise_reports([avar.Recording({"gx": a}, rate=100.0), avar.Recording({"gx": b}, rate=200.0)],
                           progress=False)
