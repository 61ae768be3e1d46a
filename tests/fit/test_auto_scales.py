"""Tests of the automatic scale selection and of AVLR on automatic scales."""

from __future__ import annotations

import numpy as np
import pytest

import avar
from avar.fit.auto_scales import auto_scales, local_slopes
from avar.models import RW, WN


def reference_slopes(tau, adev, errors):
    """Plain loop: central differences, one-sided at both ends."""
    n = len(tau)
    slopes, ses = [], []
    for j in range(n):
        lo, hi = (0, 1) if j == 0 else (n - 2, n - 1) if j == n - 1 else (j - 1, j + 1)
        span = np.log(tau[hi]) - np.log(tau[lo])
        slopes.append((np.log(adev[hi]) - np.log(adev[lo])) / span)
        ses.append(np.hypot(errors[hi], errors[lo]) / span)
    return np.array(slopes), np.array(ses)


@pytest.fixture(scope="module")
def series():
    # white noise meets the random walk at m = sqrt(3 / 1e-6) = 1732
    return (WN(sigma2=1.0) + RW(gamma2=1e-6)).simulate(200_000, seed=4)


def test_local_slopes_match_a_plain_loop(series):
    av = avar.avar(series)
    slopes, se = local_slopes(av.levels, av.adev, av.errors)
    expected_slopes, expected_se = reference_slopes(av.levels, av.adev, av.errors)
    np.testing.assert_allclose(slopes, expected_slopes, rtol=1e-12)
    np.testing.assert_allclose(se, expected_se, rtol=1e-12)
    tau = 2.0 ** np.arange(6)
    np.testing.assert_allclose(local_slopes(tau, 3 * tau**0.5, np.full(6, 0.1))[0], 0.5, rtol=1e-12)


def test_each_process_gets_the_scales_where_it_dominates(series):
    av = avar.avar(series)
    sel = auto_scales(av)
    wn, rw = sel.scales["WN"], sel.scales["RW"]
    m_wn, m_rw = av.averaging_factors[wn - 1], av.averaging_factors[rw - 1]
    assert m_wn.max() < 1732 < m_rw.min()  # on each side of the crossing
    assert wn[0] == 1 and len(wn) >= 7 and len(rw) >= 2
    # the selected levels are at least 80% pure in the true model
    for scales, process in ((wn, WN(sigma2=1.0)), (rw, RW(gamma2=1e-6))):
        m = av.averaging_factors[scales - 1]
        share = process.theoretical_av(m) / (WN(sigma2=1.0) + RW(gamma2=1e-6)).theoretical_av(m)
        assert np.all(share > 0.75)
    assert set(sel.scales) == {"WN", "RW"}
    assert "WN: scales 1-" in sel.describe()


def test_avlr_auto_uses_and_reports_the_automatic_scales(series):
    av = avar.avar(series)
    sel = auto_scales(av).selection()
    fit = avar.avlr(av, auto=True)
    manual = avar.avlr(av, wn=sel["WN"], rw=sel["RW"])
    assert list(fit.scales_used) == ["WN", "RW"]
    np.testing.assert_array_equal(fit.scales_used["WN"], sel["WN"])
    np.testing.assert_array_equal(fit.estimates.to_numpy(), manual.estimates.to_numpy())
    assert fit.estimates["WN"] == pytest.approx(1.0, rel=0.02)
    assert fit.estimates["RW"] == pytest.approx(1e-3, rel=0.25)
    only_wn = avar.avlr(av, wn="auto")
    assert list(only_wn.scales_used) == ["WN"]
    mixed = avar.avlr(av, wn="auto", rw=[13, 14])
    np.testing.assert_array_equal(mixed.scales_used["RW"], [13, 14])


def test_avlr_auto_for_an_imu_pools_each_sensor_type():
    model = WN(sigma2=1.0) + RW(gamma2=1e-6)
    data = np.column_stack([model.simulate(100_000, seed=k) for k in range(4)])
    imu = avar.IMU(data, freq=10.0, gyro=[0, 1], accel=[2, 3])
    fit = avar.avlr(imu, auto=True)
    assert set(fit.scales_used["Gyroscope"]) == {"WN", "RW"}
    assert fit.estimates["Gyroscope"]["WN"] == pytest.approx(np.sqrt(1.0 / 10.0), rel=0.02)
    explicit = avar.avlr(imu, wn_gyro="auto", wn_acc=range(1, 4))
    np.testing.assert_array_equal(explicit.scales_used["Accelerometer"]["WN"], [1, 2, 3])


def test_auto_errors(series):
    av = avar.avar(WN(sigma2=1).simulate(10_000, seed=1))
    with pytest.raises(ValueError, match="rw='auto'"):
        avar.avlr(av, rw="auto")
    with pytest.raises(TypeError, match="or 'auto'"):
        avar.avlr(av, wn="automatic")
    with pytest.raises(ValueError, match="purity"):
        auto_scales(av, purity=0.0)
    with pytest.raises(ValueError, match="z must"):
        auto_scales(av, z=-1)
    with pytest.raises(TypeError, match="auto must be"):
        avar.avlr(av, auto="yes")
