"""Tests of avar.avlr: the slope method, unit conversions and the bootstrap."""

from __future__ import annotations

import dataclasses
import importlib
import io

import numpy as np
import pandas as pd
import pytest
from scipy.stats import norm

from avar.fit.avlr import avlr
from avar.fit.results import AvlrResult
from avar.fit.slopes import (
    check_scale_selections,
    fit_slopes,
    implied_allan_deviation,
    per_sample_model,
    per_sample_process,
)
from avar.models import DR, QN, RW, WN
from avar.stability.allan.estimator import avar
from avar.stability.allan.intervals import relative_errors
from avar.stability.allan.results import AllanVariance, ImuAllanVariance
from avar.stability.shared.grids import averaging_factors
from avar.stability.shared.term_counts import n_differences

# The package re-exports the function avlr under the name of its submodule.
bootstrap_module = importlib.import_module("avar.fit.bootstrap")


def exact_av(model, n=2**16, freq=1.0, type="mo"):
    """An AllanVariance holding the model's theoretical AV on the octave grid."""
    factors = averaging_factors(n)
    return AllanVariance(
        levels=factors / freq,
        averaging_factors=factors,
        allan=model.theoretical_av(factors),
        errors=relative_errors(n, factors),
        n_differences=n_differences(n, factors, type),
        type=type,
        freq=freq,
        n=n,
    )


ALL_SCALES = range(1, 16)  # the octave grid of 2**16 samples has 15 levels


# --------------------------------------------------------------------------- exact theory
@pytest.mark.parametrize("freq", [1.0, 200.0, 0.25])
def test_white_noise_on_exact_theory_is_exact_on_all_scales(freq):
    sigma = 3e-3  # continuous-time noise density (u / sqrt(Hz))
    av = exact_av(WN(sigma2=sigma**2 * freq), freq=freq)
    fit = avlr(av, wn=ALL_SCALES)
    assert fit.estimates["WN"] == pytest.approx(sigma, rel=1e-12)
    np.testing.assert_allclose(fit.implied_ad, av.adev, rtol=1e-12)
    assert fit.model == WN(sigma2=fit.estimates["WN"] ** 2 * freq)
    np.testing.assert_allclose(fit.model.theoretical_av(av.averaging_factors), av.allan, rtol=1e-12)


@pytest.mark.parametrize("freq", [1.0, 200.0])
def test_quantization_noise_on_exact_theory_is_exact(freq):
    q = 2e-4  # u s
    av = exact_av(QN(q2=q**2 * freq**2), freq=freq)
    fit = avlr(av, qn=[2, 5, 9])
    assert fit.estimates["QN"] == pytest.approx(q, rel=1e-12)
    np.testing.assert_allclose(fit.implied_ad_decomp["QN"], av.adev, rtol=1e-12)
    np.testing.assert_allclose(fit.model.theoretical_av(av.averaging_factors), av.allan, rtol=1e-12)


@pytest.mark.parametrize("freq", [1.0, 200.0])
def test_drift_on_exact_theory_is_exact(freq):
    omega = 5e-3  # u / s
    av = exact_av(DR(omega=omega / freq), freq=freq)
    fit = avlr(av, dr=ALL_SCALES)
    assert fit.estimates["DR"] == pytest.approx(omega, rel=1e-12)
    # implied AD omega tau / sqrt(2) (R 0.1.3 draws omega tau / 2, off by sqrt(2))
    np.testing.assert_allclose(fit.implied_ad, av.adev, rtol=1e-12)
    np.testing.assert_allclose(fit.model.theoretical_av(av.averaging_factors), av.allan, rtol=1e-12)


@pytest.mark.parametrize("freq", [1.0, 200.0])
def test_random_walk_on_exact_theory_is_off_by_the_closed_form_factor(freq):
    gamma = 1e-4 * np.sqrt(200.0)  # u / sqrt(s)
    av = exact_av(RW(gamma2=gamma**2 / freq), freq=freq)
    scales = np.arange(1, 9)
    m = av.averaging_factors[scales - 1].astype(float)
    # AV_rw(m) = (2 m^2 + 1) / (2 m^2) * gamma^2 tau / 3, so the estimate is gamma times
    # the geometric mean of sqrt((2 m^2 + 1) / (2 m^2)) over the scales used
    factor = np.exp(np.mean(0.5 * np.log((2 * m**2 + 1) / (2 * m**2))))
    fit = avlr(av, rw=scales)
    assert fit.estimates["RW"] == pytest.approx(gamma * factor, rel=1e-12)
    assert factor > 1.005  # the test distinguishes the factor from 1
    # at large m the factor vanishes: the implied AV tends to the model's AV
    large = avlr(av, rw=[15])
    assert large.estimates["RW"] == pytest.approx(gamma, rel=1e-9)


def test_composite_fit_pieces_add_up_and_keep_R_order():
    model = WN(1.0) + QN(1e-2) + RW(1e-8) + DR(1e-9)
    av = exact_av(model)
    fit = avlr(av, dr=[15], rw=[13], wn=[5], qn=[1])
    assert list(fit.estimates.index) == ["WN", "QN", "RW", "DR"]
    assert list(fit.implied_ad_decomp) == ["WN", "QN", "RW", "DR"]
    assert [p.name for p in fit.model.components] == ["WN", "QN", "RW", "DR"]
    np.testing.assert_allclose(fit.implied_ad, sum(fit.implied_ad_decomp.values()), rtol=1e-15)
    assert fit.implied_ad.shape == (15,)
    for process, parameter in fit.estimates.items():
        np.testing.assert_allclose(
            fit.implied_ad_decomp[process], implied_allan_deviation(process, parameter, av.levels), rtol=1e-15
        )
    np.testing.assert_array_equal(fit.scales_used["RW"], [13])


# --------------------------------------------------------------------------- building blocks
def test_fit_slopes_pools_series_like_R():
    tau = 2.0 ** np.arange(1, 11)
    adevs = [0.5 / np.sqrt(tau), 2.0 / np.sqrt(tau), 1.0 / np.sqrt(tau) * np.linspace(0.9, 1.1, 10)]
    selection = [1, 2, 3, 4]
    pooled = fit_slopes([tau, tau, tau], adevs, {"WN": selection})
    manual = np.exp(np.mean(np.concatenate([np.log(a[:4]) + np.log(tau[:4]) / 2 for a in adevs])))
    assert pooled["WN"] == pytest.approx(manual, rel=1e-14)
    singles = [fit_slopes(tau, a, {"WN": selection})["WN"] for a in adevs]
    assert pooled["WN"] == pytest.approx(np.prod(singles) ** (1 / 3), rel=1e-14)
    # every process law: AD = c theta tau^b
    for process, law in {"QN": np.sqrt(3) * 0.1 / tau, "RW": 0.1 * np.sqrt(tau / 3), "DR": 0.1 * tau / np.sqrt(2)}.items():
        assert fit_slopes(tau, law, {process: range(3, 9)})[process] == pytest.approx(0.1, rel=1e-13)


def test_fit_slopes_rejects_bad_input():
    tau = np.array([1.0, 2.0, 4.0])
    with pytest.raises(ValueError, match="finite positive"):
        fit_slopes(tau, np.array([1.0, 0.0, 1.0]), {"WN": [1, 2]})
    with pytest.raises(ValueError, match="matching 1-D arrays"):
        fit_slopes(tau, np.ones(4), {"WN": [1]})
    with pytest.raises(ValueError, match="unknown process"):
        fit_slopes(tau, np.ones(3), {"XX": [1]})


def test_check_scale_selections_names_the_argument_with_suffix():
    assert list(check_scale_selections({"wn": 3, "rw": np.array([5.0, 4.0])}, 5)) == ["WN", "RW"]
    np.testing.assert_array_equal(check_scale_selections({"rw": [5.0, 4.0]}, 5)["RW"], [4, 5])
    with pytest.raises(ValueError, match=r"rw_gyro has scale\(s\) \[9\] outside 1..5"):
        check_scale_selections({"WN": [1], "RW": [9]}, 5, suffix="_gyro")
    with pytest.raises(ValueError, match="at least one process: .* wn_acc"):
        check_scale_selections({"WN": None}, 5, suffix="_acc")


def test_unit_conversions_match_the_theory():
    f = 50.0
    expected = {"WN": WN(sigma2=2.0), "QN": QN(q2=100.0), "RW": RW(gamma2=8e-4), "DR": DR(omega=4e-3)}
    for process, model in expected.items():
        converted = per_sample_process(process, 0.2, f)
        assert type(converted) is type(model)
        np.testing.assert_allclose(converted.parameter_vector, model.parameter_vector, rtol=1e-14)
    both = per_sample_model({"WN": 0.2, "DR": 0.2}, f)
    assert [p.name for p in both.components] == ["WN", "DR"]
    np.testing.assert_allclose(both.parameter_vector, [2.0, 4e-3], rtol=1e-14)
    tau = np.array([1.0, 10.0, 100.0])
    m = tau * f
    for process, model_av in {
        "WN": per_sample_process("WN", 0.2, f).theoretical_av(m),
        "QN": per_sample_process("QN", 0.2, f).theoretical_av(m),
        "DR": per_sample_process("DR", 0.2, f).theoretical_av(m),
    }.items():
        np.testing.assert_allclose(implied_allan_deviation(process, 0.2, tau) ** 2, model_av, rtol=1e-13)
    rw_av = per_sample_process("RW", 0.2, f).theoretical_av(m)
    np.testing.assert_allclose(implied_allan_deviation("RW", 0.2, tau) ** 2 * (1 + 1 / (2 * m**2)), rw_av, rtol=1e-13)
    with pytest.raises(ValueError, match="unknown process"):
        per_sample_process("AR1", 0.2, f)
    with pytest.raises(ValueError, match="freq must be"):
        per_sample_process("WN", 0.2, -1.0)


# --------------------------------------------------------------------------- simulated data
def test_unit_conversion_round_trip_at_200_hz():
    freq, n = 200.0, 10**6
    x = (WN(sigma2=1e-4) + RW(gamma2=1e-8)).simulate(n, seed=0)
    av = avar(x, freq=freq)
    wn, rw = range(1, 6), range(10, 14)
    fit = avlr(av, wn=wn, rw=rw)
    assert fit.estimates["WN"] == pytest.approx(1e-2 / np.sqrt(freq), rel=0.03)
    assert fit.estimates["RW"] == pytest.approx(1e-4 * np.sqrt(freq), rel=0.10)
    wn_factors = av.averaging_factors[:5]
    np.testing.assert_allclose(fit.model.theoretical_av(wn_factors), av.allan[:5], rtol=0.10)
    refit = avlr(avar(fit.model.simulate(n, seed=1), freq=freq), wn=wn, rw=rw)
    assert refit.estimates["WN"] == pytest.approx(fit.estimates["WN"], rel=0.03)
    assert refit.estimates["RW"] == pytest.approx(fit.estimates["RW"], rel=0.10)


def test_series_input_uses_avar_defaults_and_time_index():
    x = WN(1).simulate(4096, seed=3)
    fit = avlr(x, wn=range(1, 6))
    assert fit.av.type == "mo" and fit.av.freq == 1.0 and len(fit.av) == 11
    assert fit.estimates["WN"] == avlr(avar(x), wn=range(1, 6)).estimates["WN"]
    series = pd.Series(x, index=pd.date_range("2024-01-01", periods=4096, freq="100ms"))
    assert avlr(series, wn=range(1, 6)).av.freq == pytest.approx(10.0)


# --------------------------------------------------------------------------- bootstrap
def test_bootstrap_intervals_use_the_normal_quantile():
    x = WN(1).simulate(10_000, seed=4)
    for alpha in (0.05, 0.1):
        fit = avlr(x, wn=range(1, 13), ci=True, B=50, alpha=alpha, seed=5)
        table = fit.ci
        assert list(table.columns) == ["Estimate", "SD", "Lower", "Upper"]
        half_width = (table["Upper"] - table["Lower"]) / (2 * table["SD"])
        np.testing.assert_allclose(half_width, norm.ppf(1 - alpha / 2), rtol=1e-12)
        np.testing.assert_allclose((table["Upper"] + table["Lower"]) / 2, table["Estimate"], rtol=1e-12)
        assert fit.confidence == pytest.approx(1 - alpha) and fit.replicates == 50


def test_bootstrap_is_bias_corrected_seeded_and_in_data_units():
    freq = 200.0
    x = (WN(sigma2=1e-4) + RW(gamma2=1e-8)).simulate(50_000, seed=6)
    fit = avlr(avar(x, freq=freq), wn=range(1, 6), rw=range(10, 14), ci=True, B=40, seed=7)
    again = avlr(avar(x, freq=freq), wn=range(1, 6), rw=range(10, 14), ci=True, B=40, seed=7)
    pd.testing.assert_frame_equal(fit.ci, again.ci)
    other = avlr(avar(x, freq=freq), wn=range(1, 6), rw=range(10, 14), ci=True, B=40, seed=8)
    assert not fit.ci.equals(other.ci)
    # simulated at 200 Hz (R simulated at 1 Hz): replicate means stay near the estimate
    relative_shift = (fit.ci["Estimate"] - fit.estimates).abs() / fit.estimates
    assert relative_shift["WN"] < 0.01 and relative_shift["RW"] < 0.2
    assert fit.ci.loc["WN", "SD"] / fit.estimates["WN"] < 0.02
    assert (fit.ci["Lower"] < fit.estimates).all() and (fit.estimates < fit.ci["Upper"]).all()
    assert fit.ci.loc["WN", "Lower"] < 1e-2 / np.sqrt(freq) < fit.ci.loc["WN", "Upper"]


def test_bootstrap_removes_a_known_bias():
    # On scales 1-2 (m = 2, 4) the RW slope estimate is high by the closed-form factor
    # exp(mean(log sqrt(1 + 1 / (2 m^2)))) = 1.038; the refits of the fitted model are high by
    # the same factor, so 2 theta - mean(theta*) brings the estimate back to within 0.2%.
    gamma = 0.01
    fit = avlr(exact_av(RW(gamma2=gamma**2)), rw=[1, 2], ci=True, B=20, seed=3)
    assert fit.estimates["RW"] / gamma - 1 == pytest.approx(0.0378, abs=0.001)
    assert fit.ci.loc["RW", "Estimate"] == pytest.approx(gamma, rel=0.002)
    draws = bootstrap_module.bootstrap_estimates(fit.model, fit.av, fit.scales_used, 20, seed=3)["RW"]
    assert fit.ci.loc["RW", "Estimate"] == pytest.approx(2 * fit.estimates["RW"] - draws.mean(), rel=1e-12)
    assert fit.ci.loc["RW", "SD"] == pytest.approx(draws.std(ddof=1), rel=1e-12)


def test_bootstrap_recomputes_the_same_estimator_type():
    x = WN(1).simulate(10_000, seed=9)
    sd = {
        kind: avlr(avar(x, type=kind), wn=range(1, 13), ci=True, B=60, seed=10).ci.loc["WN", "SD"]
        for kind in ("mo", "to")
    }
    assert sd["to"] > 1.2 * sd["mo"]  # the tau-overlap estimator is noisier


def test_bootstrap_coverage_of_white_noise():
    repetitions, hits = 50, 0
    rng = np.random.default_rng(12345)
    for _ in range(repetitions):
        x = rng.standard_normal(10_000)
        table = avlr(x, wn=range(1, 13), ci=True, B=100, seed=rng).ci
        hits += table.loc["WN", "Lower"] <= 1.0 <= table.loc["WN", "Upper"]
    assert hits / repetitions >= 0.80


def test_progress_bar_only_on_a_terminal(monkeypatch, capsys):
    monkeypatch.setattr(bootstrap_module, "PROGRESS_MIN_SAMPLES", 1)
    x = WN(1).simulate(2000, seed=1)
    avlr(x, wn=[1, 2], ci=True, B=5, seed=1)
    assert capsys.readouterr().err == ""

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    terminal = Terminal()
    monkeypatch.setattr(bootstrap_module.sys, "stderr", terminal)
    avlr(x, wn=[1, 2], ci=True, B=5, seed=1)
    assert "avlr bootstrap" in terminal.getvalue() and "5/5" in terminal.getvalue()


def test_bootstrap_in_several_chunks_matches_one_chunk_statistically(monkeypatch):
    x = WN(1).simulate(4096, seed=2)
    monkeypatch.setattr(bootstrap_module, "CHUNK_SAMPLES", 3 * 4096)  # chunks of 3 replicates
    fit = avlr(x, wn=range(1, 11), ci=True, B=200, seed=3)
    assert np.isfinite(fit.ci.to_numpy()).all()
    assert fit.ci.loc["WN", "SD"] == pytest.approx(avlr(x, wn=range(1, 11), ci=True, B=200, seed=4).ci.loc["WN", "SD"], rel=0.25)


# --------------------------------------------------------------------------- result object
def test_result_display_and_immutability():
    x = (WN(1) + RW(1e-6)).simulate(2**14, seed=1)
    fit = avlr(x, wn=range(1, 6), rw=[11, 12, 13])
    assert isinstance(fit, AvlrResult)
    assert list(fit.summary().columns) == ["Parameter", "Value"]
    text = str(fit)
    assert "WN on scales 1-5" in text and "RW on scales 11-13" in text
    assert f"{fit.estimates['WN']:.6g}" in text and "sigma" in text and "Per-sample model" in text
    assert repr(fit).startswith("<AvlrResult WN=")
    assert "<table" in fit._repr_html_()
    with pytest.raises(dataclasses.FrozenInstanceError):
        fit.ci = None
    with pytest.raises(ValueError):
        fit.implied_ad[0] = 0.0
    with pytest.raises(TypeError):
        fit.scales_used["WN"] = np.array([1])
    with_ci = avlr(x, wn=range(1, 6), ci=True, B=10, seed=1)
    assert list(with_ci.summary().columns) == ["Parameter", "Value", "Bias-corrected", "SD", "Lower", "Upper"]
    assert "95% normal intervals" in str(with_ci) and "B = 10" in str(with_ci)


# --------------------------------------------------------------------------- validation
@pytest.mark.parametrize(
    "kwargs, error, match",
    [
        ({}, ValueError, "select at least one process"),
        ({"wn": [0, 1]}, ValueError, r"wn has scale\(s\) \[0\] outside 1..11"),
        ({"rw": [11, 12]}, ValueError, r"rw has scale\(s\) \[12\] outside 1..11"),
        ({"qn": [1.5, 2]}, ValueError, "qn must hold whole numbers"),
        ({"dr": []}, ValueError, "dr selects no scale"),
        ({"wn": [1, 1, 2]}, ValueError, "wn repeats a scale"),
        ({"wn": "1:3"}, TypeError, "wn must be scale numbers"),
        ({"wn": [1], "ci": True, "B": 1}, ValueError, "B must be a whole number >= 2"),
        ({"wn": [1], "ci": True, "B": 10.5}, ValueError, "B must be a whole number"),
        ({"wn": [1], "alpha": 0.0}, ValueError, r"alpha must be in \(0, 1\)"),
        ({"wn": [1], "alpha": 1.0}, ValueError, r"alpha must be in \(0, 1\)"),
        ({"wn": [1], "alpha": -0.5}, ValueError, r"alpha must be in \(0, 1\)"),
        ({"wn": [1], "ci": "yes"}, TypeError, "ci must be True or False"),
    ],
)
def test_bad_arguments_raise(kwargs, error, match):
    x = WN(1).simulate(4096, seed=0)  # 11 octave levels
    with pytest.raises(error, match=match):
        avlr(x, **kwargs)


def test_allan_variance_with_fewer_than_two_levels_is_rejected():
    one_level = avar(WN(1).simulate(6, seed=0))
    assert len(one_level) == 1
    with pytest.raises(ValueError, match="AVLR needs at least 2 levels"):
        avlr(one_level, wn=[1])
    with pytest.raises(ValueError, match="x has 2 sample"):
        avlr([1.0, 2.0], wn=[1])
    imu = ImuAllanVariance(sensor="test", freq=1.0, n=10, channels={}, sensor_types=(), axes=())
    with pytest.raises(ValueError, match="IMU data take qn_gyro"):  # single-series scales on IMU data
        avlr(imu, wn=[1])


def test_fit_results_cannot_be_edited():
    x = WN(sigma2=1.0).simulate(4096, seed=5)
    fit = avlr(x, wn=range(1, 6), ci=True, B=10, seed=1)
    with pytest.raises(ValueError, match="read-only"):
        fit.estimates["WN"] = 99.0
    with pytest.raises(ValueError, match="read-only"):
        fit.ci.iloc[0, 0] = -1.0
    with pytest.raises(ValueError, match="read-only"):
        fit.implied_ad[0] = 0.0


def test_scale_selections_must_be_flat_and_sane():
    x = WN(sigma2=1.0).simulate(4096, seed=6)
    with pytest.raises(ValueError, match="flat list"):
        avlr(x, wn=[[1, 2], [3, 4]])
    with pytest.raises(ValueError, match="too large"):
        avlr(x, wn=[1e30])
