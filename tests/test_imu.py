"""Tests of avar.imu: the IMU container and the Allan variance of all its channels."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import avar
import avar.stability.allan.estimator as estimation_module
from avar.imu import IMU
from avar.stability.allan.results import AllanVariance, ImuAllanVariance

GYRO, ACCEL = "Gyroscope", "Accelerometer"
R_NAMES = ("Gyro. X", "Gyro. Y", "Gyro. Z", "Accel. X", "Accel. Y", "Accel. Z")


def simulated(n: int = 20_000, channels: int = 6, seed: int = 0) -> np.ndarray:
    """White noise plus random walk plus a large offset, different per channel."""
    rng = np.random.default_rng(seed)
    white = rng.standard_normal((n, channels)) * np.linspace(0.5, 2.0, channels)
    walk = np.cumsum(rng.standard_normal((n, channels)) * 1e-3, axis=0)
    return white + walk + np.arange(channels) * 1e4


def six_axis(n: int = 20_000, **kwargs) -> IMU:
    return IMU(simulated(n), 100.0, gyro=[0, 1, 2], accel=[3, 4, 5], **kwargs)


# --- construction -----------------------------------------------------------


def test_array_channels_follow_r_naming():
    imu = six_axis(name="sim")
    assert imu.channels == R_NAMES
    assert imu.sensor_types == (GYRO,) * 3 + (ACCEL,) * 3
    assert imu.axes == ("X", "Y", "Z") * 2
    assert imu.name == "sim"
    assert imu.freq == 100.0
    assert imu.n == len(imu) == 20_000
    assert "sim: 6 channels (3 Gyroscope, 3 Accelerometer)" in repr(imu)


def test_data_is_a_read_only_float64_copy():
    x = simulated(100).astype(np.float32)
    imu = IMU(x, 1.0, gyro=[0, 1, 2], accel=[3, 4, 5])
    assert imu.data.dtype == np.float64 and imu.data.shape == (100, 6)
    assert not imu.data.flags.writeable
    with pytest.raises(ValueError):
        imu.data[0, 0] = 1.0
    x[0, 0] = 123.0
    assert imu.data[0, 0] != 123.0
    with pytest.raises(AttributeError):
        imu.freq = 2.0
    np.testing.assert_array_equal(imu["Accel. Y"], x[:, 4].astype(np.float64))


def test_integer_data_and_single_selectors():
    x = np.arange(40).reshape(20, 2) % 7
    imu = IMU(x, 2, gyro=0, accel=1)
    assert imu.channels == ("Gyro. X", "Accel. X")
    assert imu.data.dtype == np.float64


def test_selector_order_assigns_axes():
    imu = IMU(simulated(50, 4), 1.0, gyro=[2, 0], accel=[3, 1], axis=["U", "V"])
    assert imu.channels == ("Gyro. V", "Accel. V", "Gyro. U", "Accel. U")
    assert imu.axes == ("V", "V", "U", "U")


def test_gyro_only_imu():
    imu = IMU(simulated(50, 3), 1.0, gyro=range(3))
    assert imu.sensor_types == (GYRO,) * 3


def test_dataframe_keeps_column_names_and_selects_by_name():
    columns = ["wx", "wy", "wz", "ax", "ay", "az"]
    df = pd.DataFrame(simulated(100), columns=columns)
    imu = IMU(df, 50.0, gyro=["wx", "wy", "wz"], accel=["ax", "ay", "az"], units={"gyro": "rad/s", "accel": "m/s^2"})
    assert imu.channels == tuple(columns)
    assert imu.sensor_types == (GYRO,) * 3 + (ACCEL,) * 3
    assert imu.axes == ("X", "Y", "Z") * 2
    assert dict(imu.units) == {GYRO: "rad/s", ACCEL: "m/s^2"}
    np.testing.assert_array_equal(imu.to_dataframe().to_numpy(), df.to_numpy())


def test_dataframe_types_inferred_from_names():
    df = pd.DataFrame(simulated(100), columns=list(R_NAMES))
    imu = IMU(df, 10.0)
    assert imu.sensor_types == (GYRO,) * 3 + (ACCEL,) * 3
    assert imu.channels == R_NAMES


def test_from_dataframe_takes_the_rate_from_a_time_index():
    index = pd.date_range("2024-01-01", periods=200, freq="4ms")
    df = pd.DataFrame(simulated(200), index=index, columns=list(R_NAMES))
    assert IMU.from_dataframe(df).freq == pytest.approx(250.0)
    assert IMU.from_dataframe(df, freq=10.0).freq == 10.0
    timedelta = df.set_axis(pd.timedelta_range(0, periods=200, freq="10ms"))
    assert IMU.from_dataframe(timedelta, name="td").freq == pytest.approx(100.0)


def test_from_dataframe_errors():
    df = pd.DataFrame(simulated(200), columns=list(R_NAMES))
    with pytest.raises(ValueError, match="pass rate"):
        IMU.from_dataframe(df)
    irregular = df.set_axis(pd.to_datetime(np.cumsum(np.r_[0, np.ones(198), 2]) * 1e9))
    with pytest.raises(ValueError, match="irregular"):
        IMU.from_dataframe(irregular)
    with pytest.raises(TypeError, match="DataFrame"):
        IMU.from_dataframe(simulated(200))


# --- validation ---------------------------------------------------------------


def test_column_that_is_neither_gyro_nor_accel():
    df = pd.DataFrame(simulated(100, 3), columns=["Gyro. X", "Accel. X", "Temp"])
    with pytest.raises(ValueError, match=r"\['Temp'\] are neither gyro nor accel"):
        IMU(df, 1.0)
    with pytest.raises(ValueError, match="neither gyro nor accel"):
        IMU(simulated(100, 3), 1.0, gyro=[0], accel=[1])


def test_column_both_gyro_and_accel():
    with pytest.raises(ValueError, match="both as gyro and as accel"):
        IMU(simulated(100, 2), 1.0, gyro=[0, 1], accel=[1])


def test_duplicate_column_names():
    df = pd.DataFrame(simulated(100, 3), columns=["Gyro. X", "Gyro. X", "Accel. X"])
    with pytest.raises(ValueError, match=r"duplicate column names \['Gyro. X'\]"):
        IMU(df, 1.0)


def test_unknown_column_name_and_index():
    df = pd.DataFrame(simulated(100, 2), columns=["g", "a"])
    with pytest.raises(ValueError, match="'gx' is not a column"):
        IMU(df, 1.0, gyro="gx", accel="a")
    with pytest.raises(ValueError, match="index 2 is out of range"):
        IMU(simulated(100, 2), 1.0, gyro=0, accel=2)
    with pytest.raises(ValueError, match="more than once"):
        IMU(simulated(100, 2), 1.0, gyro=[0, 0], accel=1)
    with pytest.raises(TypeError, match="name or integer index"):
        IMU(simulated(100, 2), 1.0, gyro=[0.5], accel=1)
    with pytest.raises(TypeError):
        IMU(simulated(100, 2), 1.0, gyro=True, accel=1)


def test_nan_in_one_channel_is_named():
    x = simulated(100)
    x[37, 4] = np.nan
    with pytest.raises(ValueError, match=r"channel 'Accel. Y' has 1 non-finite value\(s\) \(1 NaN, 0 inf\); the first is at index 37"):
        IMU(x, 1.0, gyro=[0, 1, 2], accel=[3, 4, 5])
    df = pd.DataFrame(x, columns=list("abcdef"))
    df.iloc[5, 1] = np.inf
    with pytest.raises(ValueError, match="channel 'b'"):
        IMU(df, 1.0, gyro=list("abc"), accel=list("def"))


def test_one_dimensional_data():
    with pytest.raises(ValueError, match="must be 2-D"):
        IMU(np.ones(100), 1.0, gyro=0)
    with pytest.raises(ValueError, match="single Series"):
        IMU(pd.Series(np.ones(100)), 1.0, gyro=0)
    with pytest.raises(ValueError, match="must be 2-D"):
        IMU(np.ones((10, 2, 2)), 1.0, gyro=0)


@pytest.mark.parametrize("freq", [0, -1.0, np.nan, np.inf])
def test_bad_freq(freq):
    with pytest.raises(ValueError, match="rate must be a finite number > 0"):
        IMU(simulated(100, 2), freq, gyro=0, accel=1)
    with pytest.raises(ValueError, match="freq must be a finite number > 0"):  # the spelling given is named
        IMU(simulated(100, 2), freq=freq, gyro=0, accel=1)


def test_freq_type():
    with pytest.raises(TypeError, match="rate"):
        IMU(simulated(100, 2), "100", gyro=0, accel=1)


def test_other_bad_input():
    with pytest.raises(ValueError, match="gyro=\\[...\\] and accel=\\[...\\]"):
        IMU(simulated(100, 2), 1.0)
    with pytest.raises(ValueError, match="at least 4"):
        IMU(simulated(3, 2), 1.0, gyro=0, accel=1)
    with pytest.raises(ValueError, match="no channels"):
        IMU(np.ones((10, 0)), 1.0)
    with pytest.raises(TypeError, match="complex"):
        IMU(np.ones((10, 2), dtype=complex), 1.0, gyro=0, accel=1)
    with pytest.raises(TypeError, match="numeric"):
        IMU(np.full((10, 2), "a"), 1.0, gyro=0, accel=1)
    with pytest.raises(TypeError, match=r"\['s'\] of data are not numeric"):
        IMU(pd.DataFrame({"g": np.ones(10), "s": ["x"] * 10}), 1.0, gyro="g", accel="s")
    with pytest.raises(ValueError, match="4 channels of one sensor type need 4 axis labels"):
        IMU(simulated(100, 4), 1.0, gyro=range(4))
    with pytest.raises(ValueError, match="distinct"):
        IMU(simulated(100, 2), 1.0, gyro=[0, 1], axis=["X", "X"])
    with pytest.raises(ValueError, match="units key"):
        IMU(simulated(100, 2), 1.0, gyro=0, accel=1, units={"baro": "Pa"})
    with pytest.raises(TypeError, match="name must be a string"):
        IMU(simulated(100, 2), 1.0, gyro=0, accel=1, name=3)


# --- avar(imu) ------------------------------------------------------------------


def assert_matches_single_columns(imu: IMU, res: ImuAllanVariance, **kwargs) -> None:
    for j, channel in enumerate(imu.channels):
        single = avar.avar(imu.data[:, j].copy(), freq=imu.freq, **kwargs)
        got = res[channel]
        np.testing.assert_array_equal(got.allan, single.allan)
        np.testing.assert_array_equal(got.levels, single.levels)
        np.testing.assert_array_equal(got.averaging_factors, single.averaging_factors)
        np.testing.assert_array_equal(got.errors, single.errors)
        np.testing.assert_array_equal(got.n_differences, single.n_differences)
        assert (got.type, got.freq, got.n, got.name) == (single.type, single.freq, single.n, channel)


@pytest.mark.parametrize("kind", ["mo", "to"])
@pytest.mark.parametrize("taus", ["octave", "decade", "all", [0.01, 0.5, 3.0]])
def test_avar_of_imu_equals_each_column(kind, taus):
    imu = six_axis(5_000)
    res = avar.avar(imu, type=kind, taus=taus)
    assert_matches_single_columns(imu, res, type=kind, taus=taus)


def test_avar_of_imu_metadata():
    imu = six_axis(name="sim", units={"gyro": "deg/s"})
    res = avar.avar(imu)
    assert isinstance(res, ImuAllanVariance)
    assert (res.sensor, res.freq, res.n) == ("sim", 100.0, 20_000)
    assert tuple(res.channels) == R_NAMES
    assert res.sensor_types == imu.sensor_types and res.axes == imu.axes
    assert res.type == "mo"
    assert dict(res.units) == {GYRO: "deg/s"}
    assert all(isinstance(av, AllanVariance) for av in res.channels.values())
    assert list(res.channels_of(ACCEL)) == ["Accel. X", "Accel. Y", "Accel. Z"]
    assert res.present_types == (GYRO, ACCEL)
    np.testing.assert_array_equal(res["Gyro. X"].levels, 2.0 ** np.arange(1, 14) / 100)


def test_avar_of_dataframe_imu_uses_column_names():
    df = pd.DataFrame(simulated(1000, 2), columns=["w", "f"])
    res = avar.avar(IMU(df, 1.0, gyro="w", accel="f"), type="to")
    assert tuple(res.channels) == ("w", "f")
    assert res.type == "to"


def test_all_channels_in_one_kernel_call(monkeypatch):
    calls = []
    original = estimation_module.allan_variance_columns

    def counting(data, factors, kind):
        calls.append(data.shape)
        return original(data, factors, kind)

    monkeypatch.setattr(estimation_module, "allan_variance_columns", counting)
    avar.avar(six_axis(2_000))
    assert calls == [(2_000, 6)]


def test_imu_avar_grid_and_freq_rejected():
    imu = six_axis(1_000)
    assert avar.avar(imu, type="mo", taus="octave")["Gyro. Z"].allan.shape == (8,)
    with pytest.raises(ValueError, match="carries its own freq"):
        avar.avar(imu, freq=10.0)
    with pytest.raises(ValueError, match="unknown Allan variance type"):
        avar.avar(imu, type="xx")
    with pytest.raises(ValueError, match="outside the valid range"):
        avar.avar(imu, taus=[1e6])


@settings(max_examples=25, deadline=None)
@given(
    n=st.integers(min_value=4, max_value=300),
    channels=st.integers(min_value=1, max_value=4),
    seed=st.integers(min_value=0, max_value=2**32 - 1),
    offset=st.sampled_from([0.0, 1e6, -3.5e9]),
    kind=st.sampled_from(["mo", "to"]),
)
def test_avar_of_imu_equals_columns_property(n, channels, seed, offset, kind):
    x = np.random.default_rng(seed).standard_normal((n, channels)) + offset
    imu = IMU(x, 3.0, gyro=range(channels), axis=["X", "Y", "Z", "W"])
    assert_matches_single_columns(imu, avar.avar(imu, type=kind), type=kind)
