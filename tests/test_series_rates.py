"""avar.avar on pandas Series: the index gives the rate (float seconds, PeriodIndex, time stamps)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import avar

X = np.random.default_rng(3).standard_normal(4000)


def test_float_seconds_index_gives_the_rate():
    series = pd.Series(X, index=np.arange(X.size) / 250.0)
    res = avar.avar(series)
    assert res.freq == pytest.approx(250.0, rel=1e-12)
    np.testing.assert_allclose(res.allan, avar.avar(X, freq=250.0).allan, rtol=1e-12)
    np.testing.assert_allclose(res.levels, avar.avar(X, freq=250.0).levels, rtol=1e-12)


def test_float_index_with_rounded_stamps_and_its_gaps():
    stamps = np.round(np.arange(X.size) / 300.0, 3)  # stamped to the millisecond
    assert avar.avar(pd.Series(X, index=stamps)).freq == pytest.approx(300.0, rel=1e-4)
    holed = np.arange(X.size) / 100.0
    holed[3000:] += 5.0
    with pytest.raises(ValueError, match=r"x has a time index with 1 gap\(s\).*samples 3000 and 3001"):
        avar.avar(pd.Series(X, index=holed))
    assert avar.avar(pd.Series(X, index=holed), freq=100.0).freq == 100.0  # an explicit rate wins


def test_period_index_gives_the_rate():
    index = pd.period_range("2024-01-01", periods=X.size, freq="20ms")
    assert avar.avar(pd.Series(X, index=index)).freq == pytest.approx(50.0, rel=1e-12)
    hourly = pd.period_range("2024-01-01", periods=X.size, freq="h")
    assert avar.avar(pd.Series(X, index=hourly)).freq == pytest.approx(1 / 3600, rel=1e-12)


def test_integer_index_numbers_samples_not_seconds():
    assert avar.avar(pd.Series(X, index=np.arange(X.size) * 10)).freq == 1.0
