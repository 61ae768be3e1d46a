"""The empirical Allan variance avar.avar against references, theory and NIST."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from scipy.stats import norm

import avar
from avar.stability.shared.grids import averaging_factors
from tests._support.reference import allan_mo_loop, allan_to_loop, exact_allan

NIST = [892, 809, 823, 798, 671, 644, 883, 903, 677]

REAL_DTYPES = [np.float64, np.float32, np.float16, np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint16, np.uint32]


@st.composite
def series(draw):
    n = draw(st.one_of(st.integers(4, 3000), st.sampled_from([4, 5, 8, 64, 1024, 2048, 2999])))
    dtype = draw(st.sampled_from(REAL_DTYPES))
    info = np.iinfo(dtype) if np.dtype(dtype).kind in "iu" else None
    if info is not None:
        elements = st.integers(max(info.min, -10_000), min(info.max, 10_000))
    else:
        # magnitudes whose squares underflow float64 are refused by avar() (test_extreme_magnitudes): flush them to 0
        elements = st.floats(-1e4, 1e4, allow_nan=False, allow_infinity=False,
                             width=np.dtype(dtype).itemsize * 8).map(lambda v: v if abs(v) > 1e-100 else 0.0)
    return draw(hnp.arrays(dtype, n, elements=elements))


def assert_matches_reference(result, x, reference):
    x64 = np.asarray(x, dtype=np.float64)
    scale = float(np.max(np.abs(x64))) if x64.size else 0.0
    for m, value in zip(result.averaging_factors, result.allan):
        expected = reference(x64, int(m))
        # The reference's own rounding: ~eps * max|x| per cluster mean.
        atol = 1e-14 * scale * np.sqrt(expected) + 1e-28 * scale**2
        assert value == pytest.approx(expected, rel=1e-12, abs=atol), (m, value, expected)


@settings(max_examples=60, deadline=None)
@given(series(), st.sampled_from(["octave", "decade"]))
def test_mo_matches_definition(x, taus):
    result = avar.avar(x, type="mo", taus=taus)
    assert_matches_reference(result, x, allan_mo_loop)


@settings(max_examples=60, deadline=None)
@given(series(), st.sampled_from(["octave", "decade"]))
def test_to_matches_definition(x, taus):
    result = avar.avar(x, type="to", taus=taus)
    assert_matches_reference(result, x, allan_to_loop)


@pytest.mark.parametrize("type, reference", [("mo", allan_mo_loop), ("to", allan_to_loop)])
@pytest.mark.parametrize("n", [4, 7, 33, 64, 101])
def test_every_scale_of_short_series(type, reference, n):
    x = np.random.default_rng(n).standard_normal(n) * 3 + 1
    result = avar.avar(x, type=type, taus="all")
    assert result.averaging_factors.tolist() == list(range(1, n // 2 + 1))
    assert_matches_reference(result, x, reference)


def test_constant_series_is_exactly_zero():
    for type in ("mo", "to"):
        result = avar.avar(np.full(1000, 3.7), type=type, taus="all")
        assert np.all(result.allan == 0.0)


def adversarial_series():
    rng = np.random.default_rng(2024)
    n = 20_000
    t = np.arange(n)
    return {
        "white noise": rng.standard_normal(n),
        "random walk": np.cumsum(rng.standard_normal(n)),
        "offset 1e6 + 1e-3 noise": 1e6 + 1e-3 * rng.standard_normal(n),
        "drift 1e-3 + 1e-6 noise": 1e-3 * t + 1e-6 * rng.standard_normal(n),
    }


@pytest.mark.parametrize("name", list(adversarial_series()))
@pytest.mark.parametrize("type", ["mo", "to"])
def test_agrees_with_exact_rational_arithmetic(name, type):
    x = adversarial_series()[name]
    result = avar.avar(x, type=type)
    exact = exact_allan(x, result.averaging_factors, type)
    np.testing.assert_allclose(result.allan, exact, rtol=1e-10, atol=0)


def test_nist_sp1065_data_set():
    mo = avar.avar(NIST, type="mo", taus=[1, 2])
    to = avar.avar(NIST, type="to", taus=[1, 2])
    np.testing.assert_allclose(mo.adev, [91.22945, 85.95287], rtol=1e-6)
    np.testing.assert_allclose(to.adev, [91.22945, 115.8082], rtol=1e-6)
    assert mo.n_differences.tolist() == [8, 6]
    assert to.n_differences.tolist() == [8, 3]


def test_shift_and_scale_properties():
    x = np.random.default_rng(1).standard_normal(5000).cumsum()
    base = avar.avar(x)
    np.testing.assert_allclose(avar.avar(x + 12345.678).allan, base.allan, rtol=1e-10)
    np.testing.assert_allclose(avar.avar(-3.5 * x).allan, 3.5**2 * base.allan, rtol=1e-12)
    np.testing.assert_allclose(avar.avar(1e-30 * x).allan, 1e-60 * base.allan, rtol=1e-12)


def test_levels_are_averaging_factors_over_freq():
    x = np.random.default_rng(3).standard_normal(3000)
    for freq in (1.0, 100.0, 0.25, 333.3):
        result = avar.avar(x, freq=freq, taus="decade")
        np.testing.assert_array_equal(result.levels, result.averaging_factors / freq)
        assert result.freq == freq


def test_octave_grid_matches_r_and_largest_scale_of_power_of_two_is_not_zero():
    x = np.random.default_rng(4).standard_normal(1024)
    result = avar.avar(x)
    assert result.averaging_factors.tolist() == [2, 4, 8, 16, 32, 64, 128, 256, 512]
    assert result.n_differences[-1] == 1
    # R 0.1.3 drops the last difference and reports exactly 0 here.
    assert result.allan[-1] > 0
    assert result.allan[-1] == pytest.approx(allan_mo_loop(x, 512), rel=1e-12)


def test_r_compatible_errors_and_bands():
    n = 10_000
    result = avar.avar(np.random.default_rng(5).standard_normal(n))
    m = result.averaging_factors
    np.testing.assert_allclose(result.errors, 1 / np.sqrt(2 * (n / m - 1)), rtol=1e-15)
    np.testing.assert_allclose(result.adev, np.sqrt(result.allan), rtol=1e-15)
    np.testing.assert_allclose(result.lci, result.adev * (1 - 2 * result.errors), rtol=1e-15)
    np.testing.assert_allclose(result.uci, result.adev * (1 + 2 * result.errors), rtol=1e-15)
    np.testing.assert_array_equal(result.n_differences, n - 2 * m + 1)


def test_grids():
    assert averaging_factors(9).tolist() == [2, 4]  # J = floor(log2 9) - 1 = 2
    assert averaging_factors(16).tolist() == [2, 4, 8]
    assert averaging_factors(17).tolist() == [2, 4, 8]
    assert averaging_factors(4).tolist() == [2]
    assert averaging_factors(1000, taus="decade").tolist() == [1, 2, 4, 10, 20, 40, 100, 200, 400]
    assert averaging_factors(11, taus="all").tolist() == [1, 2, 3, 4, 5]
    assert averaging_factors(100, freq=2.0, taus=np.array([0.5, 1.0, 1.2, 25.0])).tolist() == [1, 2, 50]


def test_inputs_lists_series_and_dtypes_agree():
    x = np.random.default_rng(6).integers(-100, 100, 777)
    expected = avar.avar(x.astype(np.float64)).allan
    np.testing.assert_array_equal(avar.avar(list(x)).allan, avar.avar(x).allan)
    np.testing.assert_array_equal(avar.avar(pd.Series(x)).allan, avar.avar(x).allan)
    # integers are centred on a whole number, floats on their mean: the same values to rounding
    for values in (list(x), pd.Series(x), x.astype(np.int16), x.astype(np.float32)):
        np.testing.assert_allclose(avar.avar(values).allan, expected, rtol=1e-13)


def test_series_with_time_index_gives_the_rate():
    index = pd.date_range("2024-01-01", periods=1000, freq="10ms")
    x = pd.Series(np.random.default_rng(7).standard_normal(1000), index=index)
    result = avar.avar(x)
    assert result.freq == pytest.approx(100.0)
    np.testing.assert_allclose(result.levels, result.averaging_factors / 100.0)
    by_timedelta = avar.avar(pd.Series(x.to_numpy(), index=pd.timedelta_range(0, periods=1000, freq="500ms")))
    assert by_timedelta.freq == pytest.approx(2.0)
    assert avar.avar(x, freq=5.0).freq == 5.0  # an explicit freq wins


def test_irregular_time_index_is_an_error():
    index = pd.DatetimeIndex(pd.date_range("2024-01-01", periods=100, freq="1s").tolist()[:-1] + [pd.Timestamp("2024-01-02")])
    with pytest.raises(ValueError, match="irregular time index"):
        avar.avar(pd.Series(np.arange(100.0), index=index))


@pytest.mark.parametrize(
    "x, kwargs, error, message",
    [
        ([1.0, 2.0, np.nan, 4.0, np.nan], {}, ValueError, r"2 non-finite value\(s\) \(2 NaN, 0 inf\); the first is at index 2"),
        ([1.0, np.inf, 3.0, 4.0], {}, ValueError, r"1 non-finite value\(s\) \(0 NaN, 1 inf\); the first is at index 1"),
        ([1.0, 2.0, 3.0], {}, ValueError, "has 3 sample.*at least 4"),
        (np.ones((10, 2)), {}, ValueError, "1-D.*avar.IMU"),
        (np.float64(3.0), {}, ValueError, "1-D"),
        (["a", "b", "c", "d"], {}, TypeError, "numeric"),
        (np.ones(10, dtype=complex), {}, TypeError, "complex"),
        ("abcd", {}, TypeError, "string"),
        (pd.DataFrame({"a": np.ones(10)}), {}, TypeError, "DataFrame.*avar.IMU"),
        (np.ones(10), {"freq": 0}, ValueError, "freq must be a finite number > 0"),
        (np.ones(10), {"freq": -2.0}, ValueError, "freq must be a finite number > 0"),
        (np.ones(10), {"freq": np.inf}, ValueError, "freq must be a finite number > 0"),
        (np.ones(10), {"freq": "100"}, TypeError, "freq must be a positive real number"),
        (np.ones(10), {"type": "oa"}, ValueError, "unknown Allan variance type 'oa'"),
        (np.ones(10), {"taus": "weekly"}, ValueError, "unknown tau grid"),
        (np.ones(10), {"taus": [0.2]}, ValueError, r"outside the valid range \[1, 5\] s"),
        (np.ones(10), {"taus": [6.0]}, ValueError, r"averaging factors 1..5"),
        (np.ones(10), {"taus": [np.nan]}, ValueError, "finite"),
        (np.ones(10), {"taus": []}, TypeError, "non-empty"),
    ],
)
def test_bad_input_is_named(x, kwargs, error, message):
    with pytest.raises(error, match=message):
        avar.avar(x, **kwargs)


def test_result_is_immutable_and_printable():
    result = avar.avar(np.random.default_rng(8).standard_normal(4096), freq=10.0)
    with pytest.raises(ValueError):
        result.allan[0] = 1.0
    with pytest.raises(AttributeError):
        result.freq = 2.0
    summary = result.summary()
    assert list(summary.columns) == ["Time", "AVar", "ADev", "Lower CI", "Upper CI"]
    np.testing.assert_array_equal(summary["AVar"], result.allan)
    np.testing.assert_array_equal(summary["Time"], result.levels)
    text = str(result)
    assert "maximal overlap" in text and "N = 4096" in text and "10 Hz" in text
    assert len(text.splitlines()) == len(result) + 2
    assert "<table" in result._repr_html_()
    assert "AllanVariance" in repr(result)


def test_reused_workspace_is_safe_across_threads_and_lengths():
    from concurrent.futures import ThreadPoolExecutor

    rng = np.random.default_rng(9)
    series = [rng.standard_normal(n).cumsum() for n in (5000, 20_000, 777, 20_000, 3000, 60_000)] * 3
    expected = [avar.avar(x).allan for x in series]  # one at a time
    with ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(lambda x: avar.avar(x).allan, series))
    for got, want in zip(results, expected):
        np.testing.assert_array_equal(got, want)


def test_integers_beyond_2_to_53_are_exact():
    base = [0, 1, 3, 0, 7, 2]
    expected = avar.avar(np.array(base), taus="all").allan
    # float64(2**62 + 1) == float64(2**62): without the exact integer shift the AV would be 0.
    np.testing.assert_allclose(avar.avar(np.array(base, dtype=np.int64) + 2**62, taus="all").allan, expected, rtol=1e-14)
    np.testing.assert_allclose(
        avar.avar(np.array(base, dtype=np.uint64) + np.uint64(2**63), taus="all").allan, expected, rtol=1e-14
    )


def test_extreme_magnitudes():
    np.testing.assert_allclose(avar.avar([1e150, -1e150, 1e150, -1e150, 1e150], taus=[1]).allan, [2e300], rtol=1e-15)
    with pytest.raises(ValueError, match="below the float64 range"):  # squares underflow: never a silent 0
        avar.avar([1e-320, 0.0, 1e-320, 0.0, 5e-324, 0.0], taus=[1])
    with pytest.raises(ValueError, match="overflows float64"):
        avar.avar([1e300, -1e300, 1e300, -1e300, 1e300], taus=[1])


def test_decreasing_time_index_is_named():
    index = pd.date_range("2024-01-01", periods=10, freq="1s")[::-1]
    with pytest.raises(ValueError, match="does not increase strictly"):
        avar.avar(pd.Series(np.arange(10.0), index=index))


def test_numpy_integer_length():
    assert averaging_factors(np.int64(100)).tolist() == [2, 4, 8, 16, 32]


# --------------------------------------------------------------------------- ci="chi2"
@pytest.mark.parametrize("type, estimator", [("mo", "oadev"), ("to", "adev")])
def test_chi2_band_is_chi2_bounds_of_the_edf(type, estimator):
    from avar.stability.uncertainty.edf import chi2_bounds, estimator_edf
    from avar.stability.uncertainty.noise_id import identify_noise

    x = np.random.default_rng(5).standard_normal(4096) * 0.3 + 2.0
    res = avar.avar(x, type=type, freq=50.0, ci="chi2")
    phase = np.concatenate(([0.0], np.cumsum(x - x.mean()))) / 50.0
    alpha = identify_noise(phase, res.averaging_factors, estimator)
    edf = estimator_edf(estimator, alpha, res.averaging_factors, 4097)
    one_sigma = 2 * norm.cdf(1.0) - 1  # the default: one standard deviation of a normal variable
    lci, uci = chi2_bounds(res.adev, edf, one_sigma)
    assert res.ci == "chi2" and res.confidence == one_sigma
    np.testing.assert_array_equal(res.alpha, alpha)
    np.testing.assert_array_equal(res.edf, edf)
    np.testing.assert_array_equal(res.lci, lci)
    np.testing.assert_array_equal(res.uci, uci)
    assert (res.alpha[:6] == 0).all()  # white FM (white noise series)
    # the same Allan variance and R errors as ci="r"
    r_band = avar.avar(x, type=type, freq=50.0)
    np.testing.assert_array_equal(res.allan, r_band.allan)
    np.testing.assert_array_equal(res.errors, r_band.errors)
    # positive at every level, also the largest (m = N / 2) where R's band goes negative
    assert r_band.lci[-1] < 0
    assert (res.lci > 0).all() and (res.lci <= res.adev).all() and (res.adev <= res.uci).all()
    # few terms at m = N / 2: a wide band (edf ~ 1)
    assert res.uci[-1] / res.adev[-1] > 1.5


def test_chi2_band_values_white_fm_non_overlapping():
    # "to" at m = 1024 of N = 4096: 3 differences of independent means, white FM with F = infinity:
    # edf = 2 M**2 / (3 M - 1) = 18 / 8 exactly
    from scipy.stats import chi2

    from avar.stability.uncertainty.edf import estimator_edf

    x = np.random.default_rng(2).standard_normal(4096)
    res = avar.avar(x, type="to", taus=[1024.0], ci="chi2")
    assert estimator_edf("adev", [0], [1024], 4097)[0] == pytest.approx(18 / 8, rel=1e-12)
    assert res.edf[0] == estimator_edf("adev", res.alpha, [1024], 4097)[0]

    q = norm.cdf(-1.0)  # one sigma, two-sided
    assert res.lci[0] == pytest.approx(res.adev[0] * np.sqrt(res.edf[0] / chi2.isf(q, res.edf[0])), rel=1e-14)


def test_chi2_confidence_and_default_r_band_unchanged():
    x = np.random.default_rng(8).standard_normal(2000)
    narrow = avar.avar(x, ci="chi2")
    wide = avar.avar(x, ci="chi2", confidence=0.95)
    assert wide.confidence == 0.95
    assert (wide.lci < narrow.lci).all() and (wide.uci > narrow.uci).all()
    default = avar.avar(x)
    assert default.ci == "r" and default.alpha is None and default.edf is None and default.confidence is None
    np.testing.assert_array_equal(default.lci, default.adev * (1 - 2 * default.errors))
    np.testing.assert_array_equal(default.uci, default.adev * (1 + 2 * default.errors))
    assert list(default.summary().columns) == ["Time", "AVar", "ADev", "Lower CI", "Upper CI"]
    table = narrow.summary()
    assert list(table.columns) == ["Time", "AVar", "ADev", "Lower CI", "Upper CI", "Alpha", "EDF"]
    np.testing.assert_array_equal(table["Lower CI"], narrow.lci)
    np.testing.assert_array_equal(table["EDF"], narrow.edf)
    assert "chi-squared 0.683 band" in narrow.describe()
    with pytest.raises(ValueError):
        narrow.edf[0] = 1.0


def test_chi2_band_of_imu_channels():
    from avar.imu import IMU

    rng = np.random.default_rng(4)
    data = np.column_stack([rng.standard_normal(3000), np.cumsum(rng.standard_normal(3000))])
    res = avar.avar(IMU(data, freq=10, gyro=[0], accel=[1], name="imu"), ci="chi2", confidence=0.9)
    for j, channel in enumerate(res.channels.values()):
        alone = avar.avar(data[:, j], freq=10.0, ci="chi2", confidence=0.9)
        np.testing.assert_array_equal(channel.lci, alone.lci)
        np.testing.assert_array_equal(channel.alpha, alone.alpha)
        assert channel.ci == "chi2" and (channel.lci > 0).all()
    gyro, accel = res.channels.values()
    assert gyro.alpha[0] == 0 and accel.alpha[0] == -2  # white FM, random-walk FM
    assert list(res.summary().columns)[-2:] == ["Alpha", "EDF"]


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"ci": "normal"}, "ci must be 'r'"),
        ({"ci": "chi2", "confidence": 1.5}, r"confidence must be a number in \(0, 1\)"),
        ({"ci": "chi2", "confidence": True}, r"confidence must be a number in \(0, 1\)"),
        ({"confidence": 0.9}, "confidence applies to ci='chi2' only"),
    ],
)
def test_ci_validation(kwargs, message):
    with pytest.raises(ValueError, match=message):
        avar.avar(np.arange(100.0), **kwargs)
