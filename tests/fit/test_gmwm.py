"""Tests of avar.gmwm: exact theory, simulations with known truth, constraints, IMU, bad inputs."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pandas as pd
import pytest

import avar
from avar.fit.gmwm import gmwm, octave_factors
from avar.fit.gmwm.results import GmwmResult, ImuGmwmResult
from avar.imu import IMU
from avar.models import AR1, DR, QN, RW, WN, Process
from avar.stability.allan.results import AllanVariance

N = 20_000  # exact-theory tests: the weights='full' bootstrap simulates 200 series of N


def exact_av(model, n=N, freq=1.0):
    """An AllanVariance holding the model's theoretical AV on the octave grid (plus m = 1)."""
    m = octave_factors(n)
    return AllanVariance(levels=m / freq, averaging_factors=m, allan=model.theoretical_av(m),
                         errors=np.zeros(m.size), n_differences=n - 2 * m + 1, type="mo", freq=freq, n=n)


TRUTHS = {
    "WN + RW": WN(sigma2=1.0) + RW(gamma2=1e-6),
    "WN + AR1 + RW": WN(sigma2=1.0) + AR1(phi=0.995, sigma2=1e-4) + RW(gamma2=1e-5),
    "QN + WN + RW + DR": QN(q2=1.0) + WN(sigma2=1.0) + RW(gamma2=1e-4) + DR(omega=1.3e-4),
    "WN + AR1 + AR1": WN(sigma2=1.0) + AR1(phi=0.9, sigma2=0.05) + AR1(phi=0.999, sigma2=1e-5),
}


@pytest.mark.parametrize("weights", ["diagonal", "identity", "full"])
@pytest.mark.parametrize("spec", list(TRUTHS))
def test_exact_theory_is_recovered(spec, weights):
    truth = TRUTHS[spec]
    fit = gmwm(exact_av(truth), spec, weights=weights, seed=1)
    np.testing.assert_allclose(fit.estimates.to_numpy(), truth.parameter_vector, rtol=1e-6)
    assert fit.objective < 1e-12
    assert fit.converged


def test_implied_av_is_the_sum_of_the_closed_forms():
    truth = TRUTHS["WN + AR1 + RW"]
    fit = gmwm(truth.simulate(20_000, seed=4), "WN + AR1 + RW")
    m = fit.av.averaging_factors
    # independent reference: the closed forms of avar.theory, summed by hand
    wn, ar1, rw = fit.model.components
    reference = wn.sigma2 / m + avar.av_ar1(m, ar1.phi, ar1.sigma2) + (2 * m**2 + 1) * rw.gamma2 / (6 * m)
    np.testing.assert_allclose(fit.implied_av, reference, rtol=1e-12)
    np.testing.assert_allclose(sum(fit.decomposition.values()), fit.implied_av, rtol=1e-12)
    assert list(fit.decomposition) == ["WN", "AR1", "RW"]


def test_simulation_with_known_truth():
    truth = WN(sigma2=2.0) + RW(gamma2=1e-5)
    estimates = np.array([gmwm(truth.simulate(20_000, seed=s), "WN + RW").estimates.to_numpy()
                          for s in range(6)])
    relative = estimates / truth.parameter_vector - 1
    # WN: relative SE about sqrt(2 / N) ~ 1%; RW about 30% at this length
    assert np.all(np.abs(relative[:, 0]) < 0.05)
    assert abs(np.median(relative[:, 1])) < 0.3


def test_octave_grid_includes_m_1_and_matches_avar():
    x = WN(sigma2=1.0).simulate(5000, seed=2)
    fit = gmwm(x, "WN")
    assert fit.av.averaging_factors.tolist() == (2 ** np.arange(12)).tolist()
    np.testing.assert_allclose(fit.av.allan[1:], avar.avar(x).allan, rtol=1e-12)


def test_constraints_hold_on_a_model_too_large():
    # pure white noise fitted with WN + AR1 + RW: the terms share the white noise
    # (an AR1 with phi near 0 is white) but stay admissible, and the total fits 1 / m
    fit = gmwm(WN(sigma2=1.0).simulate(10_000, seed=5), "WN + AR1 + RW")
    wn, ar1, rw = fit.model.components
    assert wn.sigma2 > 0 and ar1.sigma2 > 0 and rw.gamma2 > 0
    assert abs(ar1.phi) < 1
    m = fit.av.averaging_factors
    np.testing.assert_allclose(fit.implied_av[:6], 1.0 / m[:6], rtol=0.05)


def test_two_ar1_are_ordered_by_correlation_time():
    truth = WN(sigma2=1.0) + AR1(phi=0.999, sigma2=1e-5) + AR1(phi=0.9, sigma2=0.05)  # slow one first
    fit = gmwm(exact_av(truth), [WN, AR1, AR1])
    assert list(fit.estimates.index) == ["WN.sigma2", "AR1_1.phi", "AR1_1.sigma2", "AR1_2.phi", "AR1_2.sigma2"]
    np.testing.assert_allclose(fit.estimates.to_numpy(), [1.0, 0.9, 0.05, 0.999, 1e-5], rtol=1e-6)
    assert list(fit.decomposition) == ["WN", "AR1_1", "AR1_2"]


def test_model_forms_agree():
    x = (WN(sigma2=1.0) + RW(gamma2=1e-5)).simulate(20_000, seed=6)
    by_string = gmwm(x, "wn+RW").estimates
    by_classes = gmwm(x, [avar.WN, avar.RW]).estimates
    by_values = gmwm(x, WN(sigma2=0.5) + RW(gamma2=1e-4)).estimates
    np.testing.assert_allclose(by_classes, by_string, rtol=1e-8)
    np.testing.assert_allclose(by_values, by_string, rtol=1e-6)
    assert gmwm(x, avar.WN).estimates.index.tolist() == ["WN.sigma2"]


@dataclass(frozen=True, repr=False)
class FlatNoise(Process):
    """A process the estimator has never seen: AV(m) = b2 (a flat line, like flicker noise)."""

    b2: float
    name: ClassVar[str] = "FLATTEST"

    def _av(self, m):
        return np.full(np.shape(m), self.b2, dtype=np.float64)


def test_any_process_subclass_is_estimated():
    truth = WN(sigma2=1.0) + FlatNoise(b2=1e-3) + RW(gamma2=1e-7)
    fit = gmwm(exact_av(truth), "WN + FLATTEST + RW")
    np.testing.assert_allclose(fit.estimates.to_numpy(), [1.0, 1e-3, 1e-7], rtol=1e-6)
    assert fit.estimates.index[1] == "FLATTEST.b2"


def test_continuous_units():
    truth = WN.from_continuous(0.1, 100.0) + RW.from_continuous(0.01, 100.0) + AR1(phi=0.99, sigma2=1e-4)
    fit = gmwm(exact_av(truth, freq=100.0), "WN + RW + AR1")
    cont = fit.continuous
    assert cont["WN.sigma [u s^1/2]"] == pytest.approx(0.1, rel=1e-6)
    assert cont["RW.gamma [u s^-1/2]"] == pytest.approx(0.01, rel=1e-6)
    assert cont["AR1.T [s]"] == pytest.approx(-1 / (100.0 * np.log(0.99)), rel=1e-6)
    assert cont["AR1.sigma_s [u]"] == pytest.approx(np.sqrt(1e-4 / (1 - 0.99**2)), rel=1e-5)


def test_bootstrap_intervals():
    truth = WN(sigma2=1.0) + RW(gamma2=1e-5)
    x = truth.simulate(20_000, seed=7)
    fit = gmwm(x, "WN + RW", ci=True, B=30, seed=3)
    table = fit.summary()
    assert list(table.columns) == ["Estimate", "SE", "Lower", "Upper"]
    assert np.all(table["Lower"] < table["Estimate"]) and np.all(table["Estimate"] < table["Upper"])
    assert np.all(table["Lower"] > 0) and np.all(table["SE"] > 0)
    # the WN interval is about +-2 sqrt(2 / N) wide relative, and covers the truth here
    assert table.loc["WN.sigma2", "Lower"] < 1.0 < table.loc["WN.sigma2", "Upper"]
    assert 0.005 < table.loc["WN.sigma2", "SE"] < 0.03
    again = gmwm(x, "WN + RW", ci=True, B=30, seed=3)
    pd.testing.assert_frame_equal(again.ci, fit.ci)
    assert fit.confidence == 0.95 and fit.replicates == 30


def test_result_is_immutable_and_printable():
    fit = gmwm(WN(sigma2=1.0).simulate(4000, seed=8), "WN")
    assert isinstance(fit, GmwmResult)
    with pytest.raises(ValueError):
        fit.estimates.iloc[0] = 2.0
    with pytest.raises(ValueError):
        fit.implied_av[0] = 2.0
    assert "GMWM fit of WN" in str(fit) and repr(fit).startswith("<GmwmResult")
    assert fit.model.simulate(10, seed=1).shape == (10,)


def test_imu_is_fitted_channel_by_channel():
    rng = np.random.default_rng(9)
    gyro = (WN(sigma2=1.0) + RW(gamma2=1e-5)).simulate_replicates(20_000, 2, seed=rng)
    acc = WN(sigma2=4.0).simulate(20_000, seed=rng)
    imu = IMU(np.column_stack([gyro.T, acc]), freq=50.0, gyro=[0, 1], accel=[2])
    fit = gmwm(imu, model_gyro="WN + RW", model_acc="WN")
    assert isinstance(fit, ImuGmwmResult)
    assert list(fit.fits) == list(imu.channels)
    for j, name in enumerate(imu.channels):
        channel = avar.avar(imu.data[:, j], freq=50.0, taus=octave_factors(20_000) / 50.0)
        alone = gmwm(channel, "WN + RW" if j < 2 else "WN")
        np.testing.assert_allclose(fit[name].estimates, alone.estimates, rtol=1e-7)
    assert fit.summary().index.names == ["Channel", "Parameter"]
    with pytest.raises(ValueError, match="model_acc"):
        gmwm(imu, model_gyro="WN + RW")
    with pytest.raises(ValueError, match="model_gyro and model_acc"):
        gmwm(imu, "WN")


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"model": "WN + XYZ"}, ValueError, "unknown process 'XYZ'"),
        ({"model": 3}, TypeError, "model must be"),
        ({"model": [WN, 2]}, TypeError, "model items"),
        ({"model": None}, ValueError, "model is required"),
        ({"model": "WN", "weights": "optimal"}, ValueError, "weights must be one of"),
        ({"model": "WN", "ci": 1}, TypeError, "ci must be True or False"),
        ({"model": "WN", "B": 1}, ValueError, "B must be"),
        ({"model": "WN", "confidence": 1.5}, ValueError, r"confidence must be in \(0, 1\)"),
        ({"model": "WN", "model_gyro": "WN"}, ValueError, "IMU data only"),
    ],
)
def test_bad_inputs(kwargs, error, match):
    with pytest.raises(error, match=match):
        gmwm(WN(sigma2=1.0).simulate(1000, seed=1), **kwargs)


def test_too_few_scales_and_zero_variance():
    with pytest.raises(ValueError, match="only 3 scales"):
        gmwm(WN(sigma2=1.0).simulate(8, seed=1), "QN + WN + RW + DR")
    with pytest.raises(ValueError, match="zero or not finite"):
        gmwm(np.full(1000, 3.0), "WN")
    with pytest.raises(ValueError, match="own levels"):
        gmwm(exact_av(WN(sigma2=1.0)), "WN", taus="decade")


def test_a_one_column_recording_is_fitted_at_its_rate():
    import avar

    x = (avar.WN(sigma2=1.0) + avar.RW(gamma2=1e-5)).simulate(2**15, seed=8)
    direct = avar.gmwm(avar.avar(x, freq=50.0, taus=2 ** np.arange(0, 15) / 50.0), "WN + RW")
    recorded = avar.gmwm(avar.Recording({"gx": x}, rate=50.0, rate_source="given"), "WN + RW")
    np.testing.assert_allclose(recorded.estimates, direct.estimates, rtol=1e-10)
    with pytest.raises(ValueError, match="Recording of 2 columns"):
        avar.gmwm(avar.Recording({"a": x, "b": x}, rate=50.0, rate_source="given"), "WN + RW")
