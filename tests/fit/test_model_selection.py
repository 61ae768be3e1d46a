"""Tests of avar.select_model: ranking candidate models by a penalized GMWM objective."""

from __future__ import annotations

import numpy as np
import pytest

import avar
from avar.fit.gmwm import gmwm
from avar.fit.gmwm.selection import select_model
from avar.models import RW, WN


@pytest.fixture(scope="module")
def series():
    return (WN(sigma2=1.0) + RW(gamma2=1e-5)).simulate(30_000, seed=13)


@pytest.fixture(scope="module")
def table(series):
    return select_model(series, ["WN", "WN + RW", "WN + RW + AR1", "RW"])


def test_true_model_ranks_first(table):
    assert table.index[0] == 1
    assert table["Model"].iloc[0].startswith("WN(") and " + RW(" in table["Model"].iloc[0]
    assert table["Rank"].tolist() == [1, 2, 3, 4]
    assert np.all(np.diff(table["Criterion"].to_numpy()) >= 0)
    # single-process models cannot fit a curve with two slopes: behind, RW alone far behind
    assert table.loc[0, "Criterion"] > 2 * table.loc[1, "Criterion"]
    assert table.loc[3, "Criterion"] > 1e3 * table.loc[1, "Criterion"]


def test_criterion_is_objective_on_common_weights_plus_2p(series, table):
    # independent recomputation of each criterion from the fitted model it reports
    av = gmwm(series, "WN").av
    m = av.averaging_factors.astype(float)
    edf = (av.n - 2 * m + 1) / m
    scale = av.allan * np.sqrt(2.0 / edf)
    for position in range(4):
        fitted = eval(table.loc[position, "Model"], {"WN": avar.WN, "RW": avar.RW, "AR1": avar.AR1})  # its repr
        implied = fitted.theoretical_av(av.averaging_factors)
        objective = sum(((av.allan[j] - implied[j]) / scale[j]) ** 2 for j in range(m.size))
        p = fitted.parameter_vector.size
        assert table.loc[position, "Parameters"] == p
        assert table.loc[position, "Objective"] == pytest.approx(objective, rel=1e-6)
        assert table.loc[position, "Criterion"] == pytest.approx(objective + 2 * p, rel=1e-6)
    # nested models share the weights: the richer one never fits worse
    assert table.loc[2, "Objective"] <= table.loc[1, "Objective"] <= table.loc[0, "Objective"]


def test_penalty_and_exports(series):
    heavy = select_model(series, ["WN + RW", "WN + RW + AR1"], penalty=np.log(30_000))
    assert heavy.index[0] == 0
    assert avar.select_model is select_model


@pytest.mark.parametrize(
    ("candidates", "kwargs", "match"),
    [
        ("WN + RW", {}, "two or more models"),
        (["WN"], {}, "two or more models"),
        (["WN", "WN + RW"], {"penalty": -1.0}, "penalty must be"),
        (["WN", "XX"], {}, "unknown process"),
    ],
)
def test_bad_inputs(series, candidates, kwargs, match):
    with pytest.raises(ValueError, match=match):
        select_model(series, candidates, **kwargs)
