"""How accurate can the rate random walk K be from 2 h? The Cramér–Rao bound, next to a Whittle MLE.

The series are those of ``noise_report_real.py`` (2 h at 200 Hz, rad/s): white
noise N = 1.2e-4 rad/s/sqrt(Hz), flicker B = 1e-4 rad/s (one-sided PSD
B^2 / (pi f)), random walk K = 1.2e-5 rad/s^2/sqrt(Hz); (b) adds a Gauss-Markov
term (sigma 1.5e-4 rad/s, T = 2 s), (c) rounds to an LSB of 0.4 sigma of the
white samples. The question: what is the smallest spread of K-hat that ANY
(asymptotically) efficient, unbiased estimator can reach from one such series,
with N, B (and sigma, T in (b)) unknown too?

Model. The samples x_t are Gaussian (the rounding of (c) is taken as white noise
of variance LSB^2 / 12 per sample, so N there is sqrt(N^2 + LSB^2 / (12 f))).
The first differences d_t = x_t - x_{t-1} are stationary: the random walk's are
its white increments. Their per-sample two-sided spectrum at nu = f / f_s
(cycles per sample, var d = integral over -1/2..1/2), D(nu) = 4 sin^2(pi nu):

    white        D N^2 f_s                          (samples N sqrt(f_s) z: one-sided 2 N^2)
    flicker      D B^2 / (2 pi nu)                  (one-sided B^2 / (pi f) as generated,
                                                     band-limited by the generator: no aliasing)
    random walk  K^2 / f_s                          (increments K / sqrt(f_s) z)
    Gauss-Markov D sigma^2 (1 - phi^2) / (1 - 2 phi cos(2 pi nu) + phi^2),  phi = exp(-1 / (T f_s))

Fisher information (Whittle). With theta = log of (N^2, B^2, K^2[, sigma^2, T]),

    I_ij = sum_{k=1}^{n/2} w_k  d log S(nu_k) / d theta_i  d log S(nu_k) / d theta_j,
    nu_k = k / n (the Fourier frequencies k / (n dt)), w_k = 1 (1/2 at Nyquist).

The weight is 1, not 1/2: each Fourier ordinate 0 < k < n/2 is complex, two
real degrees of freedom, its periodogram S times an exponential variable. (The
1/2 belongs to a sum over all n ordinates, or over the n real coefficients of a
DST.) The check printed first: for white noise alone this gives
var(N^2-hat) = 2 N^4 / n, the exact result; a weight of 1/2 would double it.
For the log-parameters, d log S / d log theta_i is just term i's share of S
(T by differentiating the AR(1) spectrum). Then sd(K-hat) / K = sd(log K^2) / 2
(delta method), the same for B and N, and for an efficient, unbiased, normal
estimator the median |K-hat / K - 1| = 0.6745 sd / K. Over 100 seeds that median
is itself uncertain (sd about 0.079 sd(K)/K): the table gives the chance that
an efficient estimator's median over 100 seeds exceeds 10 %.

Second route. For n = 4096 differences over the same 2 h (f_s = 0.569 Hz, the
same physical parameters, so the random walk, flicker and white noise still
cross at the same Fourier indices, about 17 and 800, which is where K's
information is) the exact Gaussian information 1/2 tr(S^-1 dS S^-1 dS) of the
Toeplitz covariance of d is computed and compared with Whittle's on the same n:
the flicker's covariance is the exact one of the generator (a circulant on 2n
samples), the Gauss-Markov one stationary. The exact bound on K is about 2 %
tighter than Whittle's there (2-3 %); the same correction is expected at full rate, as
K's information sits in the same few lowest ordinates.

Monte Carlo. The series of ``noise_report_real.py`` (its generators and seeds
1000, 1001, ...), and the MLE of the Gaussian likelihood of the orthonormal
DST-I coefficients c_k of d, taken independent with variances S(k / (2 (n + 1))):
exact for white noise plus random walk (the DST-I diagonalizes the covariance of
differenced white noise, tridiag(-1, 2, -1), exactly), and for the generator's
flicker the expected c_k^2 differs from S by 4e-15 to 7e-15 (rad/s)^2 at the lowest
ordinates, under 1 % of the random walk's level there. The plain periodogram of d is
not usable: its leakage from the differenced white noise, 2 N^2 f_s / n, is 5.5
times the random walk's level. The first 2^14 ordinates (below 1.1 Hz) enter
one by one, the rest as means of 64 (their spectrum is flat within 0.4 % over a
block; a mean of 64 ordinates is S chi^2_64 / 64): 39,000 terms instead of 1.44e6,
at no cost to any parameter (the bound on that grid is printed beside the full
one; the estimates agree with the unbinned MLE's to 1e-4). Binning matters: using
the first 2^17 ordinates alone would cost K 1 % in (a) and 4 % in (b), through
B. scipy L-BFGS-B on the log-parameters, started at twice the truth (T at 0.6
times). ``avar.noise_report`` runs on the same series for comparison (its K
counted where ``present``): with 100 seeds these are the series and the numbers
of ``noise_report_real.py 100 abc``.

Usage::

    PYTHONPATH=src python benchmarks/k_information_bound.py [SEEDS [SCENARIOS [FIRST_SEED]]]

(default 20 seeds from 1000, scenarios abc; SEEDS = 0: the bounds only; e.g. ``300 a 1100``
for seeds the 100 of ``noise_report_real.py`` do not use)
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
from noise_report_real import FREQ, GAUSS_MARKOV, N_SAMPLES, TRUTH, gyro

DURATION = N_SAMPLES / FREQ  # s
LSB = 0.4 * TRUTH["WN"] * math.sqrt(FREQ)  # rad/s, as in noise_report_real.py (c)
MEDIAN_ABS = 0.6744897501960817  # median of |Z|, Z standard normal
FIRST, WIDTH = 2**14, 64  # the MLE: the first DST ordinates one by one, then means of 64
SCENARIOS = {
    "a": ("white + flicker + random walk", False, 0.0),
    "b": ("(a) + Gauss-Markov sigma 1.5e-4 rad/s, T = 2 s", True, 0.0),
    "c": ("(a) quantized, LSB 0.4 sigma", False, LSB**2 / 12),
}


def truth_of(name: str) -> tuple[list[str], np.ndarray]:
    """Parameter names and true values: N^2 (with the rounding's white noise in (c)), B^2, K^2[, sigma^2, T]."""
    _, gauss_markov, extra = SCENARIOS[name]
    names = ["N^2", "B^2", "K^2"]
    theta = [TRUTH["WN"] ** 2 + extra / FREQ, TRUTH["FN"] ** 2, TRUTH["RW"] ** 2]
    if gauss_markov:
        names += ["sigma^2", "T"]
        theta += [GAUSS_MARKOV["sigma"] ** 2, GAUSS_MARKOV["T"]]
    return names, np.array(theta)


def spectrum(nu: np.ndarray, fs: float, theta: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """Per-sample two-sided spectrum S(nu) of d and dS / d log theta_i for each parameter."""
    delta = 4.0 * np.sin(np.pi * nu) ** 2
    terms = [delta * theta[0] * fs, delta * theta[1] / (2.0 * np.pi * nu), np.full_like(nu, theta[2] / fs)]
    grads = list(terms)
    if theta.size > 3:
        sigma2, corr_time = theta[3], theta[4]
        phi = math.exp(-1.0 / (corr_time * fs))
        cosine = np.cos(2.0 * np.pi * nu)
        den = 1.0 - 2.0 * phi * cosine + phi * phi
        terms.append(delta * sigma2 * (1.0 - phi * phi) / den)
        grads.append(terms[-1])
        d_shape = (-2.0 * phi * den - (1.0 - phi * phi) * (2.0 * phi - 2.0 * cosine)) / den**2  # d/d phi
        grads.append(delta * sigma2 * d_shape * (-phi * math.log(phi)))  # d phi / d log T = -phi log phi
    return sum(terms), grads


def binned(values: np.ndarray) -> np.ndarray:
    """The first FIRST values as they are, then means over blocks of WIDTH (a partial last block dropped)."""
    rest = values[FIRST:]
    rest = rest[: rest.size // WIDTH * WIDTH].reshape(-1, WIDTH).mean(axis=1)
    return np.concatenate([values[:FIRST], rest])


def dst_design(n: int) -> tuple[np.ndarray, np.ndarray]:
    """The MLE's frequencies and weights on the DST-I grid of n differences: ``binned`` grid, weight 1/2 per ordinate."""
    nu = binned(np.arange(1, n + 1) / (2.0 * (n + 1)))
    weight = np.where(np.arange(nu.size) < FIRST, 0.5, 0.5 * WIDTH)
    return nu, weight


def whittle_information(n: int, fs: float, theta: np.ndarray, grid: str = "fourier") -> np.ndarray:
    """Whittle information for log theta from n differences: Fourier ordinates k / n (weight 1),
    the DST-I grid k / (2 (n + 1)), k = 1..n (weight 1/2), or the MLE's binned DST grid (``grid="binned"``)."""
    if grid == "fourier":
        k = np.arange(1, n // 2 + 1)
        nu = k / n
        weight = np.where(2 * k == n, 0.5, 1.0)
    elif grid == "dst":
        nu = np.arange(1, n + 1) / (2.0 * (n + 1))
        weight = np.full(n, 0.5)
    else:
        nu, weight = dst_design(n)
    total, grads = spectrum(nu, fs, theta)
    scores = np.array(grads) / total
    return (scores * weight) @ scores.T


def flicker_autocovariance(samples: int, b: float, fs: float) -> np.ndarray:
    """c(tau) of ``noise_report_real.flicker``: a circulant on 2 samples, one-sided PSD b^2 / (pi f), no DC."""
    size = 2 * samples
    f = np.fft.rfftfreq(size, d=1.0 / fs)
    half = np.zeros_like(f)
    half[1:] = b * b / (math.pi * f[1:]) * fs / 2.0
    return np.fft.irfft(half, n=size)  # (1 / size) sum_j psd_j fs cos(2 pi j tau / size), Nyquist halved


def differenced(c: np.ndarray, n: int) -> np.ndarray:
    """Autocovariance of d at lags 0..n-1 from that of x: 2 c(tau) - c(tau - 1) - c(tau + 1)."""
    tau = np.arange(n)
    return 2.0 * c[tau] - c[np.abs(tau - 1)] - c[tau + 1]


def exact_information(n: int, fs: float, theta: np.ndarray) -> np.ndarray:
    """Exact Gaussian information 1/2 tr(S^-1 dS_i S^-1 dS_j) of n differences (log theta)."""
    from scipy.linalg import cho_factor, cho_solve, toeplitz

    white = np.zeros(n)
    white[:2] = [2.0 * theta[0] * fs, -theta[0] * fs]
    columns = [white, differenced(flicker_autocovariance(n + 1, math.sqrt(theta[1]), fs), n)]
    walk = np.zeros(n)
    walk[0] = theta[2] / fs
    columns.append(walk)
    if theta.size > 3:
        phi = math.exp(-1.0 / (theta[4] * fs))
        lags = np.arange(n + 1)
        columns.append(differenced(theta[3] * phi**lags, n))
        columns.append(differenced(-theta[3] * lags * phi**lags * math.log(phi), n))  # d / d log T
    covariance = toeplitz(sum(columns[:4]))
    inverse = cho_solve(cho_factor(covariance), np.eye(n))
    products = []
    for i, column in enumerate(columns):
        if i == 2:  # the random walk's derivative is (K^2 / fs) times the identity
            products.append(inverse * column[0])
        elif i == 0:  # tridiagonal
            product = column[0] * inverse
            product[:, :-1] += column[1] * inverse[:, 1:]
            product[:, 1:] += column[1] * inverse[:, :-1]
            products.append(product)
        else:
            products.append(inverse @ toeplitz(column))
    return np.array([[0.5 * np.sum(a * b.T) for b in products] for a in products])


def relative_sd(information: np.ndarray, names: list[str]) -> dict[str, float]:
    """sd(estimate) / truth of N, B, K (half the sd of log N^2 ...), sigma and T, from the inverse information."""
    sd_log = np.sqrt(np.diag(np.linalg.inv(information)))
    labels = {"N^2": "N", "B^2": "B", "K^2": "K", "sigma^2": "sigma", "T": "T"}
    return {labels[name]: (s if name == "T" else 0.5 * s) for name, s in zip(names, sd_log)}


def white_check() -> None:
    n = N_SAMPLES - 1
    theta = np.array([TRUTH["WN"] ** 2, 0.0, 0.0])
    nu = np.arange(1, n // 2 + 1) / n
    weight = np.where(2 * np.arange(1, n // 2 + 1) == n, 0.5, 1.0)
    total = 4.0 * np.sin(np.pi * nu) ** 2 * theta[0] * FREQ
    information = np.sum(weight * (total / total) ** 2)
    print(f"white noise alone, n = {n}: Whittle sd(N^2-hat)/N^2 = {1 / math.sqrt(information):.6e}, "
          f"exact sqrt(2/n) = {math.sqrt(2 / n):.6e} (a weight 1/2 per Fourier ordinate would give "
          f"{math.sqrt(2 / information):.6e})")


def cross_check(n: int = 4096) -> dict[str, float]:
    """Exact against Whittle information for n differences over the same 2 h; returns exact / Whittle of sd(K)."""
    fs = n / DURATION
    print(f"\nexact time-domain information against Whittle, n = {n} differences over {DURATION:.0f} s "
          f"(f_s = {fs:.4g} Hz, same N, B, K, sigma, T); relative sd of each estimate:")
    ratios = {}
    for name in ("a", "b"):
        names, theta = truth_of(name)
        start = time.perf_counter()
        exact = relative_sd(exact_information(n, fs, theta), names)
        fourier = relative_sd(whittle_information(n, fs, theta), names)
        sine = relative_sd(whittle_information(n, fs, theta, grid="dst"), names)
        print(f"  ({name}) {time.perf_counter() - start:.0f} s")
        print(f"    {'':<8}" + "".join(f"{label:>9}" for label in exact))
        for label, row in (("exact", exact), ("Whittle", fourier), ("W. DST", sine)):
            print(f"    {label:<8}" + "".join(f"{row[key]:>9.4f}" for key in exact))
        print(f"    {'W./exact':<8}" + "".join(f"{fourier[key] / exact[key]:>9.3f}" for key in exact))
        ratios[name] = exact["K"] / fourier["K"]
    return ratios


def bounds(chosen: str, ratios: dict[str, float]) -> None:
    n = N_SAMPLES - 1
    print(f"\nCramér–Rao bound (Whittle), {N_SAMPLES} samples at {FREQ:g} Hz ({DURATION / 3600:g} h): "
          "sd = sd(estimate)/truth, med = 0.6745 sd = implied median |estimate/truth - 1|")
    print(f"  {'':<4} {'sd(K)':>7} {'med K':>7} {'exact~':>7} {'K alone':>8} {'DST':>7} {'MLE grid':>9} "
          f"{'sd(B)':>7} {'med B':>7} {'sd(N)':>8} {'med N':>8} {'P>10%':>6}")
    for name in chosen:
        names, theta = truth_of(name)
        information = whittle_information(n, FREQ, theta)
        rel = relative_sd(information, names)
        alone = 0.5 / math.sqrt(information[2, 2])
        sine = relative_sd(whittle_information(n, FREQ, theta, grid="dst"), names)["K"]
        grid = relative_sd(whittle_information(n, FREQ, theta, grid="binned"), names)["K"]
        corrected = rel["K"] * ratios.get(name, ratios.get("a", 1.0))
        draws = np.random.default_rng(7).standard_normal((20000, 100))
        above = np.mean(np.median(np.abs(draws), axis=1) * corrected > 0.10)
        print(f"  ({name}) {100 * rel['K']:>6.2f}% {100 * MEDIAN_ABS * rel['K']:>6.2f}% "
              f"{100 * MEDIAN_ABS * corrected:>6.2f}% {100 * alone:>7.2f}% {100 * sine:>6.2f}% {100 * grid:>8.2f}% "
              f"{100 * rel['B']:>6.2f}% {100 * MEDIAN_ABS * rel['B']:>6.2f}% "
              f"{100 * rel['N']:>7.3f}% {100 * MEDIAN_ABS * rel['N']:>7.3f}% {above:>6.2f}"
              + (f"   sigma sd {100 * rel['sigma']:.2f}%, T sd {100 * rel['T']:.2f}%" if "T" in rel else ""))
    print("  exact~: med K times the exact/Whittle ratio of sd(K) at n = 4096 ((c) uses (a)'s); K alone: sd(K) with "
          "N, B (sigma, T) known; DST: sd(K) on the DST-I grid; MLE grid: sd(K) from the MLE's binned DST ordinates;\n"
          "  P>10%: chance that the median |K-hat/K - 1| over 100 seeds of an efficient, unbiased normal estimator "
          "with sd(K) = exact~ / 0.6745 exceeds 10 %")


# ------------------------------------------------------------------------------------ Monte Carlo
def whittle_mle(x: np.ndarray, start: np.ndarray) -> np.ndarray:
    """MLE of (N^2, B^2, K^2[, sigma^2, T]) from the orthonormal DST-I coefficients of d, ``binned``."""
    from scipy.fft import dst
    from scipy.optimize import minimize

    d = np.diff(x)
    power = binned(dst(d, type=1, norm="ortho") ** 2)
    nu, weight = dst_design(d.size)
    weight = weight / weight.sum()

    def objective(z: np.ndarray) -> tuple[float, np.ndarray]:
        total, grads = spectrum(nu, FREQ, np.exp(z))
        ratio = power / total
        return (np.sum(weight * (np.log(total) + ratio)),
                np.array([np.sum(weight * (1.0 - ratio) * g / total) for g in grads]))

    found = minimize(objective, np.log(start), jac=True, method="L-BFGS-B",
                     options={"ftol": 1e-15, "gtol": 1e-10, "maxiter": 2000})
    return np.exp(found.x)


def report_k(x: np.ndarray) -> float:
    """K from ``avar.noise_report`` (NaN unless ``present``)."""
    import avar

    table = avar.noise_report(x, gyro_units="rad/s", rate=FREQ).table
    row = table[table["Process"] == "RW"].iloc[0]
    return float(row["Value"]) if row["Status"] == "present" else math.nan


def monte_carlo(name: str, seeds: int, first_seed: int = 1000) -> dict[str, float]:
    _, gauss_markov, extra = SCENARIOS[name]
    names, theta = truth_of(name)
    start = theta * np.where(np.array(names) == "T", 0.6, 2.0)
    errors, reported = [], []
    for seed in range(seeds):
        rng = np.random.default_rng(first_seed + seed)  # noise_report_real.py's seeds from 1000
        x = gyro(rng, gauss_markov=gauss_markov)
        if extra:
            x = np.round(x / LSB) * LSB
        estimate = whittle_mle(x, start)
        errors.append(np.sqrt(estimate[:3] / theta[:3]) - 1.0)
        reported.append(report_k(x) / TRUTH["RW"] - 1.0)
    errors, reported = np.array(errors), np.array(reported)
    present = reported[np.isfinite(reported)]
    return {"K med": np.median(np.abs(errors[:, 2])), "K sd": errors[:, 2].std(ddof=1), "K bias": errors[:, 2].mean(),
            "B med": np.median(np.abs(errors[:, 1])), "N med": np.median(np.abs(errors[:, 0])),
            "report K med": np.median(np.abs(present)) if present.size else math.nan,
            "report K sd": present.std(ddof=1) if present.size > 1 else math.nan, "report present": present.size}


def main() -> None:
    seeds = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    chosen = sys.argv[2] if len(sys.argv) > 2 else "abc"
    first_seed = int(sys.argv[3]) if len(sys.argv) > 3 else 1000
    print(f"truth: N {TRUTH['WN']:.3g} rad/s/sqrt(Hz), B {TRUTH['FN']:.3g} rad/s, K {TRUTH['RW']:.3g} rad/s^2/sqrt(Hz)"
          f"; (b) sigma {GAUSS_MARKOV['sigma']:.3g} rad/s, T {GAUSS_MARKOV['T']:g} s; (c) LSB {LSB:.3g} rad/s")
    white_check()
    ratios = cross_check()
    bounds(chosen, ratios)
    if not seeds:
        return
    print(f"\nMonte Carlo, {seeds} seeds per scenario (noise_report_real.py's generators, seeds "
          f"{first_seed}..{first_seed + seeds - 1}): "
          "median |estimate/truth - 1|, sd and mean of K-hat/K - 1")
    print(f"  {'':<4} {'MLE K med':>10} {'K sd':>7} {'K bias':>7} {'B med':>7} {'N med':>8} "
          f"{'report K med':>13} {'K sd':>7} {'present':>8} {'time':>6}")
    for name in chosen:
        start = time.perf_counter()
        row = monte_carlo(name, seeds, first_seed)
        print(f"  ({name}) {100 * row['K med']:>9.2f}% {100 * row['K sd']:>6.2f}% {100 * row['K bias']:>+6.2f}% "
              f"{100 * row['B med']:>6.2f}% {100 * row['N med']:>7.3f}% {100 * row['report K med']:>12.2f}% "
              f"{100 * row['report K sd']:>6.2f}% {row['report present']:>8d} {time.perf_counter() - start:>5.0f}s",
              flush=True)


if __name__ == "__main__":
    main()
