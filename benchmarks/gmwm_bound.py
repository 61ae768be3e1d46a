"""Cramér–Rao lower bounds for the scenarios of ``gmwm_vs_avlr.py``, next to GMWM and AVLR.

For each scenario (N = 10**5) the first differences d_t = x_t - x_{t-1} are
stationary (RW increments are white with variance gamma2, DR adds the constant
mean omega, WN, QN and AR1 are differenced). Their spectral densities
(per sample, var d = int_{-1/2}^{1/2} S(f) df, s(f) = sin^2(pi f)):

    WN(sigma2)       4 s sigma2
    QN(q2)           16 s^2 q2        (x = sqrt(q2) (u_{t+1} - u_t), var u = 1: d is
                                        sqrt(q2) times a second difference; AV 3 q2 / m^2)
    RW(gamma2)       gamma2
    AR1(phi, sigma2) 4 s sigma2 / (1 - 2 phi cos(2 pi f) + phi^2)   (sigma2: innovation variance)

Fisher information. With the n = N - 1 differences, the orthonormal DST-I
basis (frequencies f_k = k / (2 (n + 1)), k = 1..n) diagonalizes
tridiag(-1, 2, -1) exactly, hence the covariance of RW increments plus
differenced WN: for WN + RW (+ DR) the coefficients c = DST-I(d) are
independent N(omega q_k, S(f_k)), q = DST-I(1), and the bound below is the exact
Gaussian one; for QN (corners of its 5-band matrix) and AR1 it is the usual
Whittle approximation, on a grid twice as fine with half the weight:

    I_ab = 1/2 sum_{k=1}^{n} d_a log S_k  d_b log S_k
         (= sum over the Fourier frequencies j / n, 0 < j < n / 2, asymptotically),
    I_omega = sum_k q_k^2 / S_k  (-> n / S(0), S(0) = gamma2: column ``CRB n/S(0)``),

omega being orthogonal to the rest. The bound on the relative SD is
sqrt((I^-1)_aa) / theta_a. (QN is uniform, not Gaussian: its bound is that of
the Gaussian process with the same spectrum.) The plain periodogram of d is not
usable here: its O(1 / n) leakage from the differenced white noise (about
2 sigma2 / n) exceeds gamma2 at the few frequencies where the random walk lives.

Also printed, all asymptotic at the truth from the exact covariance Sigma of
the maximal-overlap AV estimates (:mod:`avar.fit.covariance.exact`), J = d nu / d theta:

* ``gmwm diag (pred)``: the sandwich (J'WJ)^-1 J'W Sigma W J (J'WJ)^-1 of the
  default weights W = diag(edf_j / (2 nu_j^2)) on the octave grid;
* ``gmwm eff``: (J' Sigma^-1 J)^-1, the best any weighting of the octave AV can do;
* ``gmwm eff q``: the same on a quarter-octave grid (m = round(2^(i/4)), unique).

Monte Carlo (SERIES series per scenario, point estimates only): relative RMSE
of ``avar.gmwm`` (default weights and ``weights="efficient"``, on the same
series), ``avar.avlr`` on the scales of ``gmwm_vs_avlr.py``, and of a reference
efficient estimator, the MLE of the DST-domain likelihood (column ``whittle``;
scipy L-BFGS on the log / atanh scale, started at the truth, omega profiled out
by weighted least squares). ``validate`` checks the information of (a), where
that likelihood is exact: the sample variance of the score at the truth must
match I (the information identity) and the MLE's RMSE approach the bound.

Usage::

    PYTHONPATH=src python benchmarks/gmwm_bound.py [SERIES [SEED [SCENARIOS]]]

    PYTHONPATH=src python benchmarks/gmwm_bound.py validate [SERIES [SEED]]

(SERIES = 0: bounds only; default 100 series, seed 2026, scenarios abc.
``validate``: the Fisher information check of (a), default 400 series.)
"""

from __future__ import annotations

import sys
import time

import numpy as np
import pandas as pd
from gmwm_vs_avlr import AVLR_PARAMETERS, SCENARIOS, N

import avar
from avar.fit.covariance.exact import exact_covariance
from avar.fit.gmwm import octave_factors
from avar.models import AR1, DR, QN, RW, WN


def frequencies(n: int) -> np.ndarray:
    """Frequencies k / (2 (n + 1)), k = 1..n, of the DST-I basis of n differences."""
    return np.arange(1, n + 1) / (2.0 * (n + 1))


def mean_loadings(n: int) -> np.ndarray:
    """The DST-I (orthonormal) of a vector of n ones: how a mean of d enters the coefficients."""
    from scipy.fft import dst

    return dst(np.ones(n), type=1, norm="ortho")


def spectrum(model, f: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """S_d(f) of the model and dS / d theta for each covariance parameter (DR omega excluded)."""
    s = np.sin(np.pi * f) ** 2
    total = np.zeros_like(f)
    grads = []
    for p in model.components:
        if isinstance(p, WN):
            total += 4 * s * p.sigma2
            grads.append(4 * s)
        elif isinstance(p, QN):
            total += 16 * s**2 * p.q2
            grads.append(16 * s**2)
        elif isinstance(p, RW):
            total += p.gamma2
            grads.append(np.ones_like(f))
        elif isinstance(p, AR1):
            den = 1 - 2 * p.phi * np.cos(2 * np.pi * f) + p.phi**2
            total += 4 * s * p.sigma2 / den
            grads.append(-4 * s * p.sigma2 * (2 * p.phi - 2 * np.cos(2 * np.pi * f)) / den**2)
            grads.append(4 * s / den)
        elif not isinstance(p, DR):
            raise ValueError(f"no spectrum for {p.name}")
    return total, grads


def covariance_labels(model) -> list[str]:
    return [name for name in model.parameter_names if name != "DR.omega"]


def crb(model, n_samples: int) -> pd.DataFrame:
    """Cramér–Rao bound on the relative SD of every parameter (DST-I information; asymptotic for omega too)."""
    n = n_samples - 1
    total, grads = spectrum(model, frequencies(n))
    scores = np.array(grads) / total
    information = 0.5 * scores @ scores.T
    truth = pd.Series(model.parameter_vector, index=model.parameter_names)
    labels = covariance_labels(model)
    out = pd.Series(np.sqrt(np.diag(np.linalg.inv(information))), index=labels) / truth[labels]
    asymptotic = out.copy()
    if "DR.omega" in truth.index:
        s0 = sum(p.gamma2 for p in model.components if isinstance(p, RW))
        asymptotic["DR.omega"] = np.sqrt(s0 / n) / abs(truth["DR.omega"])
        out["DR.omega"] = 1.0 / np.sqrt(np.sum(mean_loadings(n) ** 2 / total)) / abs(truth["DR.omega"])
    return pd.DataFrame({"CRB rel SD": out[truth.index], "CRB n/S(0)": asymptotic[truth.index]})


def av_jacobian(model, factors: np.ndarray) -> np.ndarray:
    """d nu / d theta (central differences of the closed forms), shape (scales, parameters)."""
    theta = model.parameter_vector
    spec = avar.fit.gmwm.model.parse_model(model)
    out = np.empty((factors.size, theta.size))
    for i in range(theta.size):
        step = 1e-6 * abs(theta[i])
        up, down = theta.copy(), theta.copy()
        up[i] += step
        down[i] -= step
        out[:, i] = (spec.model(up).theoretical_av(factors) - spec.model(down).theoretical_av(factors)) / (2 * step)
    return out


def gmwm_asymptotic(model, n: int, factors: np.ndarray, diagonal: bool) -> np.ndarray:
    """Asymptotic relative SD of the GMWM at the truth: default diagonal weights or efficient ones."""
    sigma = exact_covariance(model, n, factors)
    jac = av_jacobian(model, factors)
    if diagonal:
        nu = model.theoretical_av(factors)
        weight = np.diag((n - 2 * factors + 1) / factors / (2 * nu**2))
        bread = np.linalg.inv(jac.T @ weight @ jac)
        cov = bread @ jac.T @ weight @ sigma @ weight @ jac @ bread
    else:
        cov = np.linalg.inv(jac.T @ np.linalg.solve(sigma, jac))
    return np.sqrt(np.diag(cov)) / np.abs(model.parameter_vector)


def quarter_octaves(n: int) -> np.ndarray:
    top = octave_factors(n)[-1]
    return np.unique(np.round(2.0 ** (np.arange(0, 4 * np.log2(top) + 1) / 4)).astype(np.int64))


# ----------------------------------------------------------------------------------- Whittle MLE
def whittle_mle(x: np.ndarray, truth) -> np.ndarray:
    """MLE of the DST-domain Gaussian likelihood (exact for WN + RW + DR), in parameter order.

    c = DST-I(d) (orthonormal) has independent N(omega q_k, S(f_k)) coordinates
    for d = RW increments + differenced WN (exactly: T = tridiag(-1, 2, -1) is
    diagonal in that basis), approximately otherwise. omega is profiled out by
    weighted least squares, omega_hat = sum q c / S / sum q^2 / S.
    """
    from scipy.fft import dst
    from scipy.optimize import minimize

    d = np.diff(x)
    n = d.size
    f = frequencies(n)
    coefficients = dst(d, type=1, norm="ortho")
    loadings = mean_loadings(n)
    spec = avar.fit.gmwm.model.parse_model(truth)
    labels = truth.parameter_names
    has_mean = "DR.omega" in labels
    cov_index = [i for i, name in enumerate(labels) if name != "DR.omega"]
    theta0 = truth.parameter_vector
    free0 = spec.free(theta0)[cov_index]
    is_phi = np.array([labels[i].endswith(".phi") for i in cov_index])

    def unpack(free):
        theta = theta0.copy()
        theta[cov_index] = np.where(is_phi, np.tanh(free), np.exp(free))
        return theta

    def residuals(total):
        if not has_mean:
            return coefficients, 0.0
        omega = np.sum(loadings * coefficients / total) / np.sum(loadings**2 / total)
        return coefficients - omega * loadings, omega

    def objective(free):
        total, grads = spectrum(spec.model(unpack(free)), f)
        ratio = residuals(total)[0] ** 2 / total
        dtheta = np.where(is_phi, 1 - np.tanh(free) ** 2, np.exp(free))
        grad = np.array([np.sum((1 - ratio) * g / total) for g in grads]) * dtheta
        return 0.5 * np.sum(np.log(total) + ratio) / n, 0.5 * grad / n

    found = minimize(objective, free0, jac=True, method="L-BFGS-B",
                     options={"ftol": 1e-15, "gtol": 1e-12, "maxiter": 5000})
    theta = unpack(found.x)
    if has_mean:
        theta[labels.index("DR.omega")] = residuals(spectrum(spec.model(theta), f)[0])[1]
    return theta


def monte_carlo(name: str, series: int, rng: np.random.Generator) -> pd.DataFrame:
    truth, spec, scales = SCENARIOS[name]
    labels = list(truth.parameter_names)
    true = pd.Series(truth.parameter_vector, index=labels)
    rows: dict[str, list] = {"whittle": [], "gmwm": [], "gmwm eff": [], "avlr": []}
    for _ in range(series):
        x = truth.simulate(N, seed=rng)
        rows["whittle"].append(pd.Series(whittle_mle(x, truth), index=labels))
        rows["gmwm"].append(avar.gmwm(x, spec).estimates)
        rows["gmwm eff"].append(avar.gmwm(x, spec, weights="efficient").estimates)
        slope = avar.avlr(x, **scales)
        rows["avlr"].append(pd.Series({label: to_sample(slope.estimates[process])
                                       for process, (label, to_sample) in AVLR_PARAMETERS.items()
                                       if process in slope.estimates.index}))
    out = {}
    for method, draws in rows.items():
        draws = pd.DataFrame(draws)
        error = draws / true[draws.columns] - 1
        out[f"{method} RMSE"] = np.sqrt((error**2).mean())
        if method == "whittle":
            out["whittle bias"] = error.mean()
    return pd.DataFrame(out).reindex(labels)


def validate(series: int, seed: int) -> None:
    """Check the Fisher information of (a) on simulated series: score covariance and MLE RMSE.

    For WN + RW the DST-I likelihood is the exact Gaussian likelihood of the
    differences, so E[score score'] = I exactly, at any N (the information
    identity), and the MLE's RMSE tends to the bound.
    """
    from scipy.fft import dst

    truth = SCENARIOS["a"][0]
    rng = np.random.default_rng(seed)
    n = N - 1
    f = frequencies(n)
    total, grads = spectrum(truth, f)
    grads = np.array(grads)
    information = 0.5 * (grads / total) @ (grads / total).T
    scores, estimates = [], []
    for _ in range(series):
        x = truth.simulate(N, seed=rng)
        c2 = dst(np.diff(x), type=1, norm="ortho") ** 2
        scores.append(0.5 * grads @ ((c2 - total) / total**2))
        estimates.append(whittle_mle(x, truth))
    scores = np.array(scores)
    error = np.array(estimates) / truth.parameter_vector - 1
    labels = list(truth.parameter_names)
    print(f"\nFisher information check, (a) {truth!r}, N = {N}, {series} series")
    print(pd.DataFrame({
        "I_aa": np.diag(information),
        "var(score)": scores.var(axis=0, ddof=1),
        "+- SE": scores.var(axis=0, ddof=1) * np.sqrt(2 / (series - 1)),
        "CRB rel SD": np.sqrt(np.diag(np.linalg.inv(information))) / truth.parameter_vector,
        "MLE rel RMSE": np.sqrt((error**2).mean(axis=0)),
        "MLE rel SD": error.std(axis=0, ddof=1),
        "MLE bias": error.mean(axis=0),
    }, index=labels).to_string(float_format=lambda v: f"{v:.4g}"))
    cross = np.corrcoef(scores, rowvar=False)[0, 1]
    print(f"corr of the scores: {cross:.3f} (theory "
          f"{information[0, 1] / np.sqrt(information[0, 0] * information[1, 1]):.3f})")


def main() -> None:
    if len(sys.argv) > 1 and sys.argv[1] == "validate":
        validate(int(sys.argv[2]) if len(sys.argv) > 2 else 400, int(sys.argv[3]) if len(sys.argv) > 3 else 7)
        return
    series = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 2026
    rng = np.random.default_rng(seed)
    pd.set_option("display.width", 250)
    pd.set_option("display.max_columns", 30)
    for name in sys.argv[3] if len(sys.argv) > 3 else SCENARIOS:
        truth = SCENARIOS[name][0]
        start = time.perf_counter()
        octave, quarter = octave_factors(N), quarter_octaves(N)
        table = pd.DataFrame({
            "true": truth.parameter_vector,
            "gmwm diag (pred)": gmwm_asymptotic(truth, N, octave, diagonal=True),
            "gmwm eff": gmwm_asymptotic(truth, N, octave, diagonal=False),
            "gmwm eff q": gmwm_asymptotic(truth, N, quarter, diagonal=False),
        }, index=list(truth.parameter_names))
        table = table.join(crb(truth, N))
        if series:
            table = table.join(monte_carlo(name, series, rng))
            table["avlr/2"] = table["avlr RMSE"] / 2
            table["avlr/2 vs CRB"] = np.where(table["avlr RMSE"].isna(), "-",
                                              np.where(table["avlr/2"] < table["CRB rel SD"], "impossible", "room"))
        print(f"\n({name}) {truth!r}: N = {N}, {series} series, "
              f"{time.perf_counter() - start:.0f} s; relative SD / RMSE")
        print(table.to_string(float_format=lambda v: f"{v:.4g}"), flush=True)


if __name__ == "__main__":
    main()
