"""Tests of avar.imu_avlr: one AVLR model per IMU sensor type, pooled over its axes."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import avar
from avar.fit.avlr import avlr
from avar.fit.results import ImuAvlrResult
from avar.fit.slopes import implied_allan_deviation, per_sample_model
from avar.imu import IMU
from avar.io import datasets

GYRO, ACCEL = "Gyroscope", "Accelerometer"
NAVCHIP_SCALES = dict(
    qn_gyro=range(1, 5), wn_gyro=range(6, 9), rw_gyro=range(10, 14), wn_acc=range(1, 7), rw_acc=range(14, 17)
)
# R avar 0.1.3: avlr(navchip_av, qn_gyro = 1:4, wn_gyro = 6:8, rw_gyro = 10:13, wn_acc = 1:6, rw_acc = 14:16)
R_NAVCHIP = {
    GYRO: {"WN": 5.9458769206190143e-05, "QN": 7.2085527912099747e-06, "RW": 3.0623246616644317e-05},
    ACCEL: {"WN": 0.00052334020863431952, "RW": 6.4220818082411281e-05},
}


@pytest.fixture(scope="module")
def navchip():
    return datasets.load("navchip_av")


@pytest.fixture(scope="module")
def navchip_fit(navchip):
    return avlr(navchip, **NAVCHIP_SCALES)


def test_navchip_matches_r(navchip_fit):
    assert isinstance(navchip_fit, ImuAvlrResult)
    assert navchip_fit.sensor_types == (GYRO, ACCEL)
    for kind, expected in R_NAVCHIP.items():
        got = navchip_fit.estimates[kind]
        assert isinstance(got, pd.Series)
        assert list(got.index) == list(expected)  # R's order WN, QN, RW, DR
        np.testing.assert_allclose(got.to_numpy(), list(expected.values()), rtol=1e-10, atol=0)


def test_imar_single_series_matches_r():
    fit = avlr(datasets.load("imar_av")["Gyro. X"], wn=range(1, 15))
    np.testing.assert_allclose(fit.estimates["WN"], 2.5764356945059155e-05, rtol=1e-10, atol=0)


def test_per_axis_matches_single_channel_avlr(navchip):
    fit = avlr(navchip, per_axis=True, **NAVCHIP_SCALES)
    assert fit.per_axis
    for kind in (GYRO, ACCEL):
        suffix = "_gyro" if kind == GYRO else "_acc"
        selection = {p: NAVCHIP_SCALES.get(p + suffix) for p in ("qn", "wn", "rw", "dr")}
        table = fit.estimates[kind]
        assert isinstance(table, pd.DataFrame)
        assert list(table.index) == ["X", "Y", "Z"]
        for name, av in navchip.channels_of(kind).items():
            single = avlr(av, **selection)
            axis = navchip.axes[list(navchip.channels).index(name)]
            pd.testing.assert_series_equal(table.loc[axis], single.estimates, check_names=False)
            np.testing.assert_array_equal(fit.implied_ad[name], single.implied_ad)
            for process, curve in single.implied_ad_decomp.items():
                np.testing.assert_array_equal(fit.implied_ad_decomp[name][process], curve)
            assert repr(fit.models[name]) == repr(single.model)


def test_joint_fit_is_the_geometric_mean_of_the_axes(navchip, navchip_fit):
    per_axis = avlr(navchip, per_axis=True, **NAVCHIP_SCALES)
    for kind in (GYRO, ACCEL):
        geometric = np.exp(np.log(per_axis.estimates[kind]).mean(axis=0))
        np.testing.assert_allclose(navchip_fit.estimates[kind], geometric[navchip_fit.estimates[kind].index], rtol=1e-13)


def test_implied_curves_and_models(navchip, navchip_fit):
    for name, av in navchip.channels.items():
        kind = navchip.sensor_types[list(navchip.channels).index(name)]
        estimates = navchip_fit.estimates[kind]
        decomposition = navchip_fit.implied_ad_decomp[name]
        assert list(decomposition) == list(estimates.index)
        for process, value in estimates.items():
            np.testing.assert_array_equal(decomposition[process], implied_allan_deviation(process, value, av.levels))
        np.testing.assert_allclose(navchip_fit.implied_ad[name], sum(decomposition.values()), rtol=1e-15)
        assert repr(navchip_fit.models[name]) == repr(per_sample_model(estimates.to_dict(), navchip.freq))
    assert navchip_fit.models["Gyro. X"] is navchip_fit.models["Gyro. Z"]


def test_summary_and_print(navchip_fit):
    table = navchip_fit.summary()
    assert table.index.names == ["Sensor type", "Process"]
    assert list(table.index) == [(GYRO, "WN"), (GYRO, "QN"), (GYRO, "RW"), (ACCEL, "WN"), (ACCEL, "RW")]
    assert list(table.columns) == ["Parameter", "Value", "Scales"]
    assert table.loc[(GYRO, "RW"), "Parameter"] == "gamma [u s^-1/2]"
    assert table.loc[(GYRO, "QN"), "Scales"] == "1-4"
    assert table.loc[(ACCEL, "RW"), "Value"] == navchip_fit.estimates[ACCEL]["RW"]
    text = str(navchip_fit)
    assert "Estimates for gyroscopes:" in text and "Estimates for accelerometers:" in text
    assert text.index("gyroscopes") < text.index("accelerometers")
    assert "NAVCHIP_FLT" in repr(navchip_fit)


def test_per_axis_summary(navchip):
    fit = avlr(navchip, wn_gyro=range(1, 4), wn_acc=2, per_axis=True)
    table = fit.summary()
    assert list(table.columns) == ["Parameter", "X", "Y", "Z", "Scales"]
    assert list(table.index) == [(GYRO, "WN"), (ACCEL, "WN")]
    assert "Axis" in str(fit)


def test_gyro_only_imu_prints_one_table():
    fit = avlr(datasets.load("imar_av"), wn_gyro=range(1, 15))
    assert fit.sensor_types == (GYRO,)
    assert "accelerometers" not in str(fit)
    assert list(fit.summary().index) == [(GYRO, "WN")]


def test_result_is_read_only(navchip_fit):
    with pytest.raises(AttributeError):
        navchip_fit.per_axis = True
    with pytest.raises(TypeError):
        navchip_fit.estimates["Gyroscope"] = None
    with pytest.raises(ValueError):
        navchip_fit.implied_ad["Gyro. X"][0] = 1.0


def test_present_sensor_type_without_process(navchip):
    with pytest.raises(ValueError, match="accelerometer channels but no process is selected.*wn_acc"):
        avlr(navchip, wn_gyro=range(1, 4))
    with pytest.raises(ValueError, match="gyroscope channels but no process is selected.*qn_gyro"):
        avlr(navchip, wn_acc=range(1, 4))


def test_selection_for_absent_sensor_type():
    with pytest.raises(ValueError, match="wn_acc given but the IMU has no accelerometer channels"):
        avlr(datasets.load("imar_av"), wn_gyro=range(1, 4), wn_acc=range(1, 4))


def test_bad_scales_name_the_argument(navchip):
    with pytest.raises(ValueError, match=r"rw_acc has scale\(s\) \[21\] outside 1..20"):
        avlr(navchip, wn_gyro=1, rw_acc=[19, 20, 21])
    with pytest.raises(ValueError, match="wn_gyro repeats a scale"):
        avlr(navchip, wn_gyro=[1, 1], wn_acc=1)


def test_bad_input_types(navchip):
    with pytest.raises(ValueError, match="apply to IMU data only"):
        avlr(np.ones(100), wn_gyro=1)
    with pytest.raises(TypeError, match="per_axis"):
        avlr(navchip, wn_gyro=1, wn_acc=1, per_axis="yes")


def test_imu_input_and_simulated_recovery():
    rng = np.random.default_rng(5)
    sigma = np.array([0.1, 0.1, 0.1, 2.0, 2.0, 2.0])
    freq = 100.0
    # white noise of density sigma / sqrt(Hz): per-sample standard deviation sigma sqrt(freq)
    data = rng.standard_normal((200_000, 6)) * sigma * np.sqrt(freq)
    imu = IMU(data, freq, gyro=[0, 1, 2], accel=[3, 4, 5], name="sim")
    fit = avlr(imu, wn_gyro=range(1, 10), wn_acc=range(1, 10))
    assert fit.imu_av.sensor == "sim"
    assert fit.estimates[GYRO]["WN"] == pytest.approx(0.1, rel=0.02)
    assert fit.estimates[ACCEL]["WN"] == pytest.approx(2.0, rel=0.02)
    same = avlr(avar.avar(imu), wn_gyro=range(1, 10), wn_acc=range(1, 10))
    pd.testing.assert_series_equal(fit.estimates[GYRO], same.estimates[GYRO])


def test_plot_delegates_to_plotting(navchip_fit, monkeypatch):
    import avar.plotting

    seen = {}

    def fake(x, **kwargs):
        seen.update(x=x, kwargs=kwargs)
        return "figure"

    monkeypatch.setattr(avar.plotting, "plot_imu_avlr", fake, raising=False)
    assert navchip_fit.plot(deviation=True) == "figure"
    assert seen == {"x": navchip_fit, "kwargs": {"deviation": True}}


def test_public_avlr_dispatches_imu_data(navchip, navchip_fit):
    # The R call avlr(navchip_av, qn_gyro = 1:4, ...) through the public entry point.
    fit = avar.avlr(navchip, **NAVCHIP_SCALES)
    assert isinstance(fit, ImuAvlrResult)
    for kind, expected in R_NAVCHIP.items():
        np.testing.assert_allclose(fit.estimates[kind].to_numpy(), list(expected.values()), rtol=1e-10, atol=0)
    per_axis = avar.avlr(navchip, per_axis=True, **NAVCHIP_SCALES)
    assert per_axis.estimates[GYRO].shape == (3, 3)
    with pytest.raises(ValueError, match="IMU data take qn_gyro"):
        avar.avlr(navchip, wn=range(1, 5))
    with pytest.raises(ValueError, match="B must be a whole number >= 2"):  # IMU bootstrap: validated like a series'
        avar.avlr(navchip, ci=True, B=1, **NAVCHIP_SCALES)
    with pytest.raises(ValueError, match=r"\['wn_gyro'\] apply to IMU data only"):
        avar.avlr(navchip["Gyro. X"], wn_gyro=range(1, 5))


def test_imu_fit_results_cannot_be_edited(navchip_fit, navchip):
    with pytest.raises(ValueError, match="read-only"):
        navchip_fit.estimates[GYRO]["WN"] = 1.0
    per_axis = avlr(navchip, wn_gyro=range(1, 4), wn_acc=2, per_axis=True)
    with pytest.raises(ValueError, match="read-only"):
        per_axis.estimates[GYRO].iloc[0, 0] = 1.0


def test_imu_fit_needs_two_levels():
    imu = IMU(np.random.default_rng(0).standard_normal((7, 2)), freq=1.0, gyro=[0], accel=[1])
    with pytest.raises(ValueError, match="fewer than 2 levels"):
        avar.avlr(avar.avar(imu), wn_gyro=1, wn_acc=1)


@pytest.mark.parametrize("frame", [False, True])
def test_integers_beyond_2_to_53_are_kept_exactly_by_imu(frame):
    from fractions import Fraction

    info = np.iinfo(np.int64)
    offset = 2**60 + np.random.default_rng(4).integers(0, 5, 40)  # beyond 2**53, spanning little
    full = np.array([info.min, info.max, info.max, info.min] * 10)  # spanning the whole int64 range
    data = np.column_stack([offset, full]).astype(np.int64)
    imu = IMU(pd.DataFrame(data, columns=["g", "a"]) if frame else data, freq=1.0, gyro=[0], accel=[1])
    assert imu.data.dtype == np.int64 and np.array_equal(imu.data, data)
    result = avar.avar(imu, taus="all")
    for j, channel in enumerate(imu.channels):
        values = [int(v) for v in data[:, j]]
        av = result.channels[channel]
        exact = []
        for m in av.averaging_factors.tolist():
            d = [sum(values[i + m : i + 2 * m]) - sum(values[i : i + m]) for i in range(len(values) - 2 * m + 1)]
            exact.append(float(sum(Fraction(v * v) for v in d) / (2 * m * m * len(d))))
        np.testing.assert_allclose(av.allan, exact, rtol=1e-12, atol=1e-12 * max(exact))
