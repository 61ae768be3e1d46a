"""Dynamic deviations: every window equals its statistic alone; level changes and steps are found."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import avar
from avar._kernels.runtime.paths import forced
from avar.stability.shared.registry import CLASSIC


def mixed_noise(n: int, seed: int) -> np.ndarray:
    """White plus random-walk noise (white FM turning to random-walk FM), offset from zero."""
    rng = np.random.default_rng(seed)
    return 1e-9 * (5.0 + rng.standard_normal(n) + 0.05 * np.cumsum(rng.standard_normal(n)))


def assert_window_equals_statistic(res, data, data_type, nan_policy="raise"):
    """Every window's levels are the statistic's of its samples alone (a level the gaps leave without
    a term, which the statistic drops, is NaN with no term)."""
    for w, start in enumerate(res.starts.tolist()):
        alone = getattr(avar, res.estimator)(data[start:start + res.window], rate=res.rate, data_type=data_type,
                                             taus=res.taus, nan_policy=nan_policy)
        kept = np.isin(res.taus, alone.taus)
        assert np.isnan(res.deviation[w, ~kept]).all() and (res.n_terms[w, ~kept] == 0).all()
        np.testing.assert_allclose(res.deviation[w, kept], alone.deviation, rtol=1e-12, atol=0)
        np.testing.assert_array_equal(res.n_terms[w, kept], alone.n)
        np.testing.assert_array_equal(res.alpha[w, kept], alone.alpha)
        np.testing.assert_allclose(res.edf[w, kept], alone.edf, rtol=1e-12)
        np.testing.assert_allclose(res.lci[w, kept], alone.lci, rtol=1e-12)
        np.testing.assert_allclose(res.uci[w, kept], alone.uci, rtol=1e-12)


@pytest.mark.parametrize("statistic", CLASSIC)
@pytest.mark.parametrize("data_type", ["freq", "phase"])
def test_each_window_equals_its_statistic_alone(statistic, data_type):
    """Deviation to 1e-12, and the same term counts, noise, EDF and bounds, window by window."""
    data = mixed_noise(3000, seed=1)
    if data_type == "phase":
        data = np.cumsum(data)  # a random-walk phase with a large frequency offset
    res = avar.dynamic(statistic, data, rate=4.0, data_type=data_type, window=700, step=333,
                       taus="all" if statistic in ("oadev", "mhdev") else "octave")
    assert res.starts.tolist() == list(range(0, 2301, 333))
    assert res.averaging_factors[-1] <= 700 // 4
    assert_window_equals_statistic(res, data, data_type)


@pytest.mark.parametrize("statistic", ["adev", "oadev", "mdev", "ohdev", "mhdev", "totdev"])
@pytest.mark.parametrize("data_type", ["freq", "phase"])
def test_windows_with_gaps_equal_their_statistic(statistic, data_type):
    data = mixed_noise(2000, seed=2)
    data[[3, 401, 402, 900, 1500, 1999]] = np.nan
    res = avar.dynamic(statistic, data, data_type=data_type, window=500, step=250, nan_policy="omit")
    assert_window_equals_statistic(res, data, data_type, nan_policy="omit")
    with pytest.raises(ValueError, match="NaN"):
        avar.dynamic(statistic, data, data_type=data_type, window=500)


def test_dadev_and_dhdev_are_dynamic_oadev_and_ohdev():
    y = mixed_noise(2000, seed=3)
    for short, statistic in ((avar.dadev, "oadev"), (avar.dhdev, "ohdev")):
        a, b = short(y, rate=2.0, window=400, step=100), avar.dynamic(statistic, y, rate=2.0, window=400, step=100)
        assert a.estimator == statistic and a.name == "D" + statistic.upper()
        np.testing.assert_array_equal(a.deviation, b.deviation)
        np.testing.assert_array_equal(a.record.deviation, getattr(avar, statistic)(y, rate=2.0, taus=a.taus).deviation)


def test_white_fm_whose_level_doubles_reads_twice_as_high_within_the_bands():
    """White FM whose level doubles halfway: each window after the change reads twice the level of
    the windows before, within its own bounds."""
    n = 40_000
    y = np.random.default_rng(21).standard_normal(n) * 1e-12
    y[n // 2:] *= 2.0
    res = avar.dadev(y, window=4000, step=1000, confidence=0.99)
    before = res.starts + res.window <= n // 2
    after = res.starts >= n // 2
    level = res.deviation[before].mean(axis=0)
    inside = (res.lci[after] <= 2 * level) & (2 * level <= res.uci[after])
    assert inside.mean() >= 0.95
    np.testing.assert_allclose(res.deviation[after].mean(axis=0)[:6] / level[:6], 2.0, rtol=0.05)
    # the two halves against the whole record: every window leaves its band, below then above
    runs = res.unstable()
    assert runs["Windows"].sum() >= 0.9 * res.n_windows and runs["Change"].isna().all()


def test_a_frequency_step_is_located_within_one_step():
    """A 1e-12 frequency step in white FM of 1e-12: the windows holding it leave the band, and the
    stretch they share places it within one step of where it is."""
    y = np.random.default_rng(22).standard_normal(20_000) * 1e-12
    y[12_345:] += 1e-12
    res = avar.dadev(y, rate=10.0, window=1000, step=100)
    runs = res.unstable()
    worst = runs.loc[runs["Ratio"].idxmax()]
    assert abs(worst["Change"] - 12_345 / 10.0) <= 100 / 10.0
    assert worst["Ratio"] > 2 and worst["Change from"] <= worst["Change"] <= worst["Change to"]
    median = res.unstable(reference="median")
    assert abs(median.loc[median["Ratio"].idxmax(), "Change"] - 1234.5) <= 10.0


def test_a_stationary_record_is_rarely_flagged():
    flagged = sum(len(avar.dadev(np.random.default_rng(seed).standard_normal(20_000), window=1000,
                                 step=500).unstable(confidence=0.99)) for seed in range(10))
    assert flagged <= 6  # 10 records of 39 windows, each flagged with probability about 1 %


def test_times_summary_and_fields():
    y = mixed_noise(1000, seed=4)
    res = avar.dadev(y, rate=2.0, window=200, step=100)
    assert res.n_windows == len(res) == 9
    np.testing.assert_allclose(res.times, (res.starts + 100) / 2.0)  # frequency: samples span tau0
    phase = avar.dadev(np.cumsum(y), rate=2.0, data_type="phase", window=200, step=100)
    np.testing.assert_allclose(phase.times, (phase.starts + 99.5) / 2.0)  # phase: points are instants
    first, last = phase.window_span()
    assert first[1] == 50.0 and last[1] == 149.5
    table = res.summary()
    assert list(table.columns) == ["Time", "Window", "Tau", "m", "N terms", "Alpha", "Min sigma", "Sigma",
                                   "Max sigma", "EDF"]
    assert len(table) == res.deviation.size
    np.testing.assert_array_equal(table["Sigma"].to_numpy().reshape(res.deviation.shape), res.deviation)
    assert "DOADEV" in repr(res) and "9 windows of 200 samples every 100" in res.describe()
    with pytest.raises(ValueError):
        res.deviation[0, 0] = 1.0
    with pytest.raises(AttributeError):
        res.window = 3
    assert isinstance(res.unstable(), pd.DataFrame)


def test_plots():
    res = avar.dadev(mixed_noise(2000, seed=5), window=400, step=100)
    ax = res.plot().axes[0]
    assert ax.get_yscale() == "log" and ax.collections[0].norm.__class__.__name__ == "LogNorm"
    surface = res.plot(kind="surface").axes[0]
    assert surface.name == "3d"
    with pytest.raises(ValueError, match="kind"):
        res.plot(kind="contour")


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        (dict(window=2), ValueError, r"window must be a number of samples in 4 \.\. 1000"),
        (dict(window=1001), ValueError, "window must be"),
        (dict(window=10.5), TypeError, "window must be an integer"),
        (dict(window=True), TypeError, "window must be an integer"),
        (dict(window=100, step=0), ValueError, "step must be a positive"),
        (dict(window=100, step=2.0), TypeError, "step must be an integer"),
        (dict(window=100, taus=[30.0]), ValueError, r"taus \[30.0\] are outside the valid range \[1, 25\] s"),
        (dict(statistic="mtie"), ValueError, "statistic must be one of"),
        (dict(data_type="time"), ValueError, "data_type"),
        (dict(confidence=2.0), ValueError, "confidence"),
    ],
)
def test_errors_name_the_argument(kwargs, error, message):
    arguments = dict(statistic="oadev", window=100)
    arguments.update(kwargs)
    with pytest.raises(error, match=message):
        avar.dynamic(arguments.pop("statistic"), np.arange(1000.0) % 7, **arguments)


def test_defaults_and_unstable_arguments():
    res = avar.dadev(mixed_noise(1000, seed=6))
    assert res.window == 100 and res.step == 10
    with pytest.raises(ValueError, match="confidence"):
        res.unstable(confidence=1.0)
    with pytest.raises(ValueError, match="reference"):
        res.unstable(reference="mean")


@pytest.mark.parametrize("statistic", ["oadev", "adev", "mdev", "hdev", "mhdev"])
@pytest.mark.parametrize("data_type", ["freq", "phase"])
def test_the_numpy_twin_and_the_kernel_give_the_same_windows(statistic, data_type):
    """The window sums of a cold process (the NumPy twin, :mod:`avar.stability.dynamic.small`) and of
    a warm one (the kernel), forced on the same data with gaps: deviations to 1e-12, the same counts."""
    data = mixed_noise(2500, seed=7)
    data[[300, 301, 1700]] = np.nan
    results = {}
    for path in ("numpy", "compiled"):
        with forced(path):
            results[path] = avar.dynamic(statistic, data, data_type=data_type, window=800, step=150,
                                         nan_policy="omit")
    twin, kernel = results["numpy"], results["compiled"]
    np.testing.assert_array_equal(twin.n_terms, kernel.n_terms)
    np.testing.assert_allclose(twin.deviation, kernel.deviation, rtol=1e-12, atol=0)
    assert np.isfinite(twin.deviation).sum() > 0.9 * twin.deviation.size
