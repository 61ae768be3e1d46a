"""Bias instability B against random walk K: intervals that hold the selection's uncertainty, and the covariance
they rest on.

Known truth: a 2 h, 200 Hz gyro of the ADIS16405-like "ieee" model (N, B and K) whose
selection drops B (seed 2 of ``benchmarks/bench_simulate_recheck.py --truth-seeds``): K
absorbs B's share of the long taus and reads 1.38 times the truth, with a conditional interval
[1.15, 1.72] that misses it; the union with the encompassing model's interval holds it. The
exact covariance's lags beyond the filters' reach (a long Gauss-Markov memory) are checked
against the plain FFT twin, which sums every lag.
"""

import math

import numpy as np
import pandas as pd

import avar
from avar.fit.covariance.exact import exact_covariance
from avar.fit.covariance.structure import structure_covariance
from avar.fit.report.sensor_fit import fit_sensor_model
from avar.fit.report.uncertainty import encompassing_scale, with_level_covariance
from avar.fit.terms import Component

MODEL = {"WN": 5.2e-4, "FN": 1.0e-4, "RW": 1.3e-5}  # rad/s/sqrt(Hz), rad/s, rad/s^2/sqrt(Hz)
UNITS = {"WN": "rad/s/sqrt(Hz)", "FN": "rad/s", "RW": "rad/s^2/sqrt(Hz)"}


def test_a_short_and_a_long_gauss_markov_term_match_the_plain_sum_over_every_lag():
    # the long term's memory (T = 3000 samples) once stretched one trapezoid over the short term's lags
    model = (Component("WN", 1.0), Component("AR1", 0.1, math.exp(-1 / 14)), Component("AR1", 1e-3, math.exp(-1 / 3000)))
    factors = 2 ** np.arange(13)
    exact = exact_covariance(model, 60_000, factors)
    sparse = structure_covariance(model, 60_000, factors)
    spread = np.sqrt(np.outer(np.diag(exact), np.diag(exact)))
    assert np.max(np.abs(sparse - exact) / spread) < 2e-3


def test_flicker_and_a_very_long_gauss_markov_term_keep_the_lag_one_variance():
    # white noise dominates level 1: its variance is 3 / N of the squared AV, whatever the slow terms add
    model = (Component("WN", 1.0), Component("FN", 1e-4), Component("AR1", 1e-6, math.exp(-1 / 50_000)))
    n = 1_000_000
    cov = structure_covariance(model, n, 2 ** np.arange(19))
    assert abs(cov[0, 0] * n / 3.0 - 1.0) < 0.01
    assert np.all(np.linalg.eigvalsh(cov / np.sqrt(np.outer(np.diag(cov), np.diag(cov)))) > -1e-3)


def test_k_interval_holds_the_truth_when_the_selection_drops_b():
    terms = pd.DataFrame([{"Channel": "gx", "Sensor": "Gyroscope", "Term": p, "Process": p, "Status": "present",
                           "Value": v, "Unit": UNITS[p]} for p, v in MODEL.items()])
    report = avar.noise_report(avar.simulate_log(terms, duration="2h", rate=200.0, seed=2))
    fit = report.fits["gx"]
    assert fit.kinds == ("WN", "RW")  # B dropped: the case this guards
    row = report.table[report.table["Process"] == "RW"].iloc[0]
    assert row["Value"] / MODEL["RW"] > 1.2  # K absorbed B's share
    assert row["Lower"] <= MODEL["RW"] <= row["Upper"]
    # conditional on the selected model alone, the interval misses the truth
    k = fit.kinds.index("RW")
    edf = 2.0 * fit.components[k].scale ** 2 / fit.scale_variance(k)
    from scipy.special import chdtri

    conditional_low = math.sqrt(fit.components[k].scale * edf / chdtri(edf, 0.025) * 200.0)
    assert conditional_low > MODEL["RW"]
    wider = encompassing_scale(fit, k)
    assert wider is not None and wider.variance > fit.scale_variance(k)


def test_a_sensor_without_flicker_keeps_its_k_interval():
    m = 2 ** np.arange(16)
    nu = 1.0 / m + 1e-7 * (2.0 * m**2 + 1) / (6.0 * m)  # WN + RW, exact: flicker is rejected outright
    fit = with_level_covariance(fit_sensor_model(m, nu, (2**18 - 2 * m + 1) / m), 2**18)
    assert fit.kinds == ("WN", "RW")
    assert encompassing_scale(fit, 1) is None and encompassing_scale(fit, 0) is None
