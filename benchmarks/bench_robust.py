"""The robust Allan variance: speed against avar.avar, and accuracy against other robust estimators.

Speed: a 2 h, 200 Hz channel (1.44 M samples; white noise + random walk + 5 %
spikes of 20 sigma): median times of ``avar.avar``, ``avar.robust_avar`` and
``avar.count_outliers`` on the same data, and the ratio robust / ordinary.

Accuracy (the evidence behind the method): simulated white noise + random
walk (sigma = 1, gamma = 0.01 per sample), 5 % spikes of +-20 sigma at random
times; each estimator's AV divided by the ordinary AV of the same series
without the spikes, level by level, over seeds (median and largest |ratio - 1|):

* ``ordinary``: ``avar.avar`` of the spiky series;
* ``robust``: ``avar.robust_avar`` (the library's choice: intact or filled per level);
* ``filled``: the ordinary AV of the series with the flagged samples
  interpolated, without subtracting the fill's excess (the library's
  filled levels subtract it);
* ``intact``: only differences free of flagged samples (``avar.avar(...,
  nan_policy="omit")`` with them as NaN; the library's estimator at every level);
* ``M-wavelet``: an M-estimator of the Haar wavelet variance in the style of
  Mondal & Percival (2012): the biweight location of log(W_t(m)**2), made
  consistent for Gaussian W by the location of log(chi2_1) under the same
  biweight, written here in NumPy;
* clean data: ``robust`` and ``ordinary`` on the series without spikes
  against the closed form AV (Fisher consistency and the spread across seeds).

Spike sizes: the worst |ratio - 1| over the levels with N / 2m >= 100, for
5 % spikes of 6 to 20 sigma, at thresholds 4 (the default) and 5.

Real logs (optional: ``--realdata DIR`` or the environment variable
``AVAR_REALDATA``, a folder of ``.npz`` files holding ``data`` (N, C) and
``columns``): per channel, ``count_outliers`` at 6 robust SD and the range of
robust / ordinary AV. Only numbers are printed; the logs stay where they are.

Usage::

    PYTHONPATH=src:benchmarks nice python benchmarks/bench_robust.py [--seeds 20] [--n 131072] [--realdata DIR]
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import numpy as np
from scipy import integrate, optimize
from timing import median_time

import avar

BIWEIGHT_C = 5.0  # biweight tuning constant on the log(chi2_1) scale (sd of log chi2_1: 2.22)


def white_plus_walk(n: int, rng: np.random.Generator, gamma: float = 0.01) -> np.ndarray:
    return rng.standard_normal(n) + np.cumsum(gamma * rng.standard_normal(n))


def with_spikes(x: np.ndarray, rng: np.random.Generator, rate: float = 0.05, size: float = 20.0) -> np.ndarray:
    spiky = x.copy()
    count = int(round(rate * x.size))
    spiky[rng.choice(x.size, count, replace=False)] += size * rng.choice([-1.0, 1.0], count)
    return spiky


def biweight_psi(u: np.ndarray, c: float) -> np.ndarray:
    return np.where(np.abs(u) < c, u * (1 - (u / c) ** 2) ** 2, 0.0)


def log_chi2_location(c: float) -> float:
    """mu0 with E psi(log chi2_1 - mu0) = 0: the biweight location of log(Z**2)."""
    density = lambda z: np.exp(z / 2 - np.exp(z) / 2) / np.sqrt(2 * np.pi)  # noqa: E731
    moment = lambda mu: integrate.quad(lambda z: biweight_psi(np.array(z - mu), c) * density(z), -40, 8,  # noqa: E731
                                       limit=200)[0]
    return optimize.brentq(moment, -3.0, 1.0)


def m_wavelet(x: np.ndarray, factors: np.ndarray, c: float = BIWEIGHT_C) -> np.ndarray:
    """Biweight M-estimate of mean(W**2) per level, W = (ybar_{t+m} - ybar_t) / sqrt(2)."""
    mu0 = log_chi2_location(c)
    sums = np.concatenate(([0.0], np.cumsum(x - x.mean())))
    out = []
    for m in factors:
        means = (sums[m:] - sums[:-m]) / m
        logs = np.log((means[m:] - means[:-m]) ** 2 / 2 + 1e-300)
        mu = np.median(logs) - np.log(0.454936423119572) + mu0  # start: the median of log chi2_1 is log 0.4549
        for _ in range(50):
            u = logs - mu - mu0
            weights = np.where(np.abs(u) < c, (1 - (u / c) ** 2) ** 2, 0.0)
            new = np.sum(weights * (logs - mu0)) / np.sum(weights)
            if abs(new - mu) < 1e-10:
                break
            mu = new
        out.append(np.exp(mu))
    return np.array(out)


def speed(n: int) -> None:
    rng = np.random.default_rng(0)
    x = with_spikes(white_plus_walk(n, rng), rng)
    t_avar = median_time(lambda: avar.avar(x, freq=200.0), 3)
    t_robust = median_time(lambda: avar.robust_avar(x, rate=200.0), 3)
    t_count = median_time(lambda: avar.count_outliers(x), 3)
    print(f"speed, N = {n} (2 h at 200 Hz), 5 % spikes: avar {t_avar:.3f} s, robust_avar {t_robust:.3f} s "
          f"({t_robust / t_avar:.1f}x avar), count_outliers {t_count:.3f} s")


def accuracy(n: int, seeds: int) -> None:
    factors = avar.avar(np.arange(n, dtype=float)).averaging_factors
    useful = n / (2 * factors) >= 100
    names = ["ordinary", "robust", "filled", "intact", "M-wavelet"]
    ratios = {name: [] for name in names}
    clean_ratios = {"ordinary": [], "robust": []}
    theory = avar.av_wn(1.0, factors) + avar.av_rw(0.01**2, factors)
    for seed in range(seeds):
        rng = np.random.default_rng(1000 + seed)
        clean = white_plus_walk(n, rng)
        spiky = with_spikes(clean, rng)
        reference = avar.avar(clean).allan
        res = avar.robust_avar(spiky)
        keep = np.ones(n, dtype=bool)
        keep[res.outliers.indices] = False
        filled = spiky.copy()
        filled[~keep] = np.interp(res.outliers.indices, np.flatnonzero(keep), spiky[keep])
        gappy = spiky.copy()
        gappy[~keep] = np.nan
        intact = np.full(factors.size, np.nan)
        with_gaps = avar.avar(gappy, nan_policy="omit")
        intact[np.searchsorted(factors, with_gaps.averaging_factors)] = with_gaps.allan
        estimates = {"ordinary": avar.avar(spiky).allan, "robust": res.allan, "filled": avar.avar(filled).allan,
                     "intact": intact, "M-wavelet": m_wavelet(spiky, factors)}
        for name in names:
            ratios[name].append(estimates[name] / reference)
        clean_ratios["ordinary"].append(reference / theory)
        clean_ratios["robust"].append(avar.robust_avar(clean).allan / theory)
    print(f"\naccuracy, N = {n}, {seeds} seeds, 5 % spikes of 20 sigma: AV / AV of the clean series, per level m")
    print("(levels with N / 2m >= 100 marked *; cells: median ratio - 1, and the largest |ratio - 1|)")
    print(f"{'m':>6} " + " ".join(f"{name:>20}" for name in names))
    for j, m in enumerate(factors):
        cells = []
        for name in names:
            r = np.array(ratios[name])[:, j] - 1
            cells.append("n/a" if np.isnan(r).all() else f"{np.nanmedian(r):+.3f} ({np.nanmax(np.abs(r)):.3f})")
        print(f"{m:>5}{'*' if useful[j] else ' '} " + " ".join(f"{c:>20}" for c in cells))
    worst = {name: np.nanmax(np.abs(np.array(ratios[name])[:, useful] - 1)) for name in names}
    print("largest |ratio - 1| over the * levels: " + ", ".join(f"{k} {v:.3f}" for k, v in worst.items()))
    print("\nclean series (no spikes): AV / closed form, mean and sd over seeds, per * level")
    for name, values in clean_ratios.items():
        values = np.array(values)[:, useful]
        print(f"{name:>9}: mean " + " ".join(f"{v:.3f}" for v in values.mean(axis=0)))
        print(f"{'':>9}  sd   " + " ".join(f"{v:.3f}" for v in values.std(axis=0)))


def spike_sizes(n: int, seeds: int) -> None:
    factors = avar.avar(np.arange(n, dtype=float)).averaging_factors
    useful = n / (2 * factors) >= 100
    print("\nspike size: worst |AV / clean AV - 1| over the * levels, 5 % spikes")
    for size in (6.0, 8.0, 12.0, 20.0):
        cells = []
        for threshold in (4.0, 5.0):
            worst = 0.0
            for seed in range(seeds):
                rng = np.random.default_rng(2000 + seed)
                clean = white_plus_walk(n, rng)
                spiky = with_spikes(clean, rng, size=size)
                ratio = avar.robust_avar(spiky, threshold=threshold).allan / avar.avar(clean).allan
                worst = max(worst, float(np.abs(ratio[useful] - 1).max()))
            cells.append(f"threshold {threshold:g}: {worst:.3f}")
        print(f"  {size:4.0f} sigma: " + ", ".join(cells))


def real_logs(folder: Path) -> None:
    print(f"\nreal logs in {folder}: outliers at 6 robust SD, and robust / ordinary AV (min, max) per channel")
    for path in sorted(folder.glob("*.npz")):
        archive = np.load(path)
        data, columns = archive["data"], archive["columns"]
        for j, column in enumerate(columns):
            x = np.asarray(data[:, j], dtype=np.float64)
            found = avar.count_outliers(x)
            ratio = avar.robust_avar(x).allan / avar.avar(x).allan
            print(f"  {path.name} {column}: {found.count} outliers ({100 * found.fraction:.3f} %), "
                  f"robust / ordinary {ratio.min():.4f} .. {ratio.max():.4f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--n", type=int, default=2**17, help="length of the accuracy simulations")
    parser.add_argument("--speed-n", type=int, default=1_440_000)
    parser.add_argument("--realdata", default=os.environ.get("AVAR_REALDATA"),
                        help="folder of real .npz logs (default: $AVAR_REALDATA; skipped when absent)")
    args = parser.parse_args()
    speed(args.speed_n)
    accuracy(args.n, args.seeds)
    spike_sizes(args.n, max(1, args.seeds // 4))
    if args.realdata and Path(args.realdata).is_dir():
        real_logs(Path(args.realdata))


if __name__ == "__main__":
    main()
