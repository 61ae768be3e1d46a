"""Tests of avar.fit.covariance.exact and weights='efficient' of avar.gmwm."""

from __future__ import annotations

import numpy as np
import pytest

from avar.fit.covariance.exact import exact_covariance, increment_autocovariance
from avar.fit.gmwm import gmwm, octave_factors
from avar.models import AR1, DR, FN, QN, RW, WN
from avar.stability.allan.results import AllanVariance

MODELS = [
    WN(sigma2=1.3) + RW(gamma2=0.2),
    QN(q2=0.7) + WN(sigma2=1.0) + RW(gamma2=0.1) + DR(omega=0.3),
    WN(sigma2=1.0) + AR1(phi=0.8, sigma2=0.5) + RW(gamma2=0.05),
    AR1(phi=-0.6, sigma2=1.0),
]


def reference_covariance(model, n, factors):
    """Plain loops: nu_hat(m) = x' A_m x, Cov = 2 tr(A S B S) + 4 mu' A S B mu for Gaussian x ~ N(mu, S)."""
    t = np.arange(1, n + 1)
    cov, mean = np.zeros((n, n)), np.zeros(n)
    for p in model.components:
        if isinstance(p, WN):
            cov += p.sigma2 * np.eye(n)
        elif isinstance(p, QN):  # x = sqrt(q2) (u_{t+1} - u_t), var u = 1
            cov += p.q2 * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
        elif isinstance(p, RW):
            cov += p.gamma2 * np.minimum.outer(t, t)
        elif isinstance(p, DR):
            mean += p.omega * t
        elif isinstance(p, AR1):
            for i in range(n):
                for j in range(n):
                    cov[i, j] += p.sigma2 / (1 - p.phi**2) * p.phi ** abs(i - j)
    forms = []
    for m in factors:
        count = n - 2 * m + 1
        form = np.zeros((n, n))
        for s in range(count):
            v = np.zeros(n)
            v[s + m:s + 2 * m] += 1.0 / m
            v[s:s + m] -= 1.0 / m
            form += np.outer(v, v) / (2 * count)
        forms.append(form)
    return np.array([[2 * np.trace(a @ cov @ b @ cov) + 4 * mean @ a @ cov @ b @ mean for b in forms] for a in forms])


@pytest.mark.parametrize("model", MODELS, ids=repr)
def test_covariance_matches_the_quadratic_form_loops(model):
    factors = np.array([1, 2, 3, 5, 8, 11])
    np.testing.assert_allclose(exact_covariance(model, 23, factors), reference_covariance(model, 23, factors),
                               rtol=1e-10, atol=1e-13 * np.abs(reference_covariance(model, 23, factors)).max())


def test_covariance_matches_simulation():
    model = WN(sigma2=1.0) + AR1(phi=0.9, sigma2=0.1) + RW(gamma2=1e-3)
    factors = np.array([1, 4, 16])
    draws = np.array([[np.mean((np.convolve(x, np.ones(m) / m, "valid")[m:] -
                                np.convolve(x, np.ones(m) / m, "valid")[:-m]) ** 2) / 2 for m in factors]
                      for x in model.simulate_replicates(400, 4000, seed=3)])
    exact = exact_covariance(model, 400, factors)
    sample = np.cov(draws, rowvar=False)
    scale = np.sqrt(np.outer(np.diag(exact), np.diag(exact)))
    # 4000 replicates: variances within ~2.3% (1 SD), correlations within ~0.016
    np.testing.assert_allclose(np.diag(sample), np.diag(exact), rtol=0.1)
    np.testing.assert_allclose(sample / scale, exact / scale, atol=0.07)


def test_increment_autocovariance_of_ar1():
    gamma, mean = increment_autocovariance(AR1(phi=0.5, sigma2=3.0), 50)
    c = 3.0 * 0.5 ** np.arange(gamma.size + 1) / (1 - 0.25)
    assert mean == 0.0
    assert gamma[0] == pytest.approx(2 * c[0] - 2 * c[1])
    assert gamma[3] == pytest.approx(2 * c[3] - c[2] - c[4])
    with pytest.raises(ValueError, match="FN"):
        increment_autocovariance(FN(b2=1.0), 50)


def exact_av(model, n):
    m = octave_factors(n)
    return AllanVariance(levels=m, averaging_factors=m, allan=model.theoretical_av(m), errors=np.zeros(m.size),
                         n_differences=n - 2 * m + 1, type="mo", freq=1.0, n=n)


@pytest.mark.parametrize("model", [
    WN(sigma2=1.0) + RW(gamma2=1e-6),
    WN(sigma2=1.0) + AR1(phi=0.995, sigma2=1e-4) + RW(gamma2=1e-5),
    QN(q2=1.0) + WN(sigma2=1.0) + RW(gamma2=1e-4) + DR(omega=1.3e-4),
], ids=repr)
def test_efficient_weights_recover_exact_theory(model):
    spec = " + ".join(p.name for p in model.components)
    fit = gmwm(exact_av(model, 20_000), spec, weights="efficient")
    np.testing.assert_allclose(fit.estimates.to_numpy(), model.parameter_vector, rtol=1e-6)
    assert fit.objective < 1e-12 and fit.weights == "efficient"


def test_efficient_weights_on_a_series_and_their_limits():
    truth = WN(sigma2=1.0) + RW(gamma2=1e-5)
    x = truth.simulate(20_000, seed=5)
    fit = gmwm(x, "WN + RW", weights="efficient", ci=True, B=10, seed=1)
    assert abs(fit.estimates["WN.sigma2"] - 1.0) < 0.05
    assert fit.ci is not None
    with pytest.raises(ValueError, match="supports WN, QN, RW, DR and AR1"):
        gmwm(x, "WN + FN", weights="efficient")
    with pytest.raises(ValueError, match="maximal-overlap"):
        import avar

        gmwm(avar.avar(x, type="to"), "WN + RW", weights="efficient")
