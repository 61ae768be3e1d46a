"""The rest of the catalogue against allantools, same run: MTIE, TIE rms, PDEV, GCODEV; the Stream's cost
per sample; the power-law generator against theory.

Usage::

    python benchmarks/bench_catalogue.py            # everything (allantools is not run on MTIE at 1e6: tens of minutes)
    python benchmarks/bench_catalogue.py --quick    # smaller sizes, one repeat

Also run at the end of ``benchmarks/bench_deviations.py``. Phase data (random
walk), octave taus on both sides (allantools is given our taus). Ratios are
allantools time / avar time (the public function: validation, the statistic,
noise identification, EDF and bounds where it has them).
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from timing import median_time  # benchmarks/timing.py

import avar

try:
    import allantools
except ImportError:  # pragma: no cover - the "bench" extra
    allantools = None

#: statistic -> sizes timed against allantools (its pdev and gcodev are O(N m) Python loops).
PEER_SIZES = {"mtie": (10**5,), "tierms": (10**5, 10**6), "pdev": (10**4,), "gcodev": (10**5,)}


def bench_peers(quick: bool) -> None:
    print("| statistic | N | levels | allantools (ms) | avar (ms) | avar vs allantools | max rel. difference |")
    print("|---|---|---|---|---|---|---|")
    for name, sizes in PEER_SIZES.items():
        for n in sizes[:1] if quick else sizes:
            rng = np.random.default_rng(0)
            x = np.cumsum(rng.standard_normal(n)) * 1e-9
            x2 = np.cumsum(rng.standard_normal(n)) * 1e-9
            if name == "gcodev":
                ours = median_time(lambda: avar.gcodev(x, x2, data_type="phase"), 1 if quick else 3)
                result = avar.gcodev(x, x2, data_type="phase")
            else:
                function = getattr(avar, name)
                ours = median_time(lambda: function(x, data_type="phase"), 1 if quick else 3)
                result = function(x, data_type="phase")
            taus = result.taus
            if allantools is None:
                print(f"| {name} | {n:.0e} | {taus.size} | - | {ours * 1e3:.1f} | - | - |", flush=True)
                continue
            start = time.perf_counter()
            if name == "gcodev":
                at_taus, at_dev, _, _ = allantools.gcodev(x, x2, rate=1.0, data_type="phase", taus=taus)
            else:
                at_taus, at_dev, _, _ = getattr(allantools, name)(x, rate=1.0, data_type="phase", taus=taus)
            peer = time.perf_counter() - start
            ours_dev = np.abs(result.deviation[np.searchsorted(taus, at_taus)])
            diff = float(np.max(np.abs(ours_dev / at_dev - 1)))
            print(f"| {name} | {n:.0e} | {taus.size} | {peer * 1e3:.1f} | {ours * 1e3:.1f} | {peer / ours:.1f}x "
                  f"| {diff:.1e} |", flush=True)
    n = 10**6
    x = np.cumsum(np.random.default_rng(1).standard_normal(n))
    for name in ("mtie", "tierms", "pdev"):
        seconds = median_time(lambda: getattr(avar, name)(x, data_type="phase"), 1)
        print(f"\n{name} at N = 1e6, octave taus: {seconds:.3f} s", end="")
    print()


def bench_stream(quick: bool) -> None:
    print("\n| stream | N | levels | mean chunk | ns per sample | equals batch (max rel. difference) |")
    print("|---|---|---|---|---|---|")
    sizes = (10**5, 10**6) if quick else (10**5, 10**6, 10**7)
    taus = 2.0 ** np.arange(0, 14)
    for statistic in ("oadev", "mdev", "ohdev"):
        for n in sizes:
            y = np.random.default_rng(2).standard_normal(n)
            stream = avar.Stream(statistic, taus=taus)
            stream.update(y[:10])  # compile
            stream = avar.Stream(statistic, taus=taus)
            cuts = np.sort(np.random.default_rng(3).integers(0, n, max(1, n // 65536)))  # chunks of random sizes
            start = time.perf_counter()
            for chunk in np.split(y, cuts):
                stream.update(chunk)
            seconds = time.perf_counter() - start
            if n <= 10**6:
                batch = getattr(avar, statistic)(y, taus=taus)
                diff = f"{float(np.max(np.abs(stream.result().deviation / batch.deviation - 1))):.1e}"
            else:
                diff = "-"
            print(f"| {statistic} | {n:.0e} | {taus.size} | {n // (cuts.size + 1)} | {seconds / n * 1e9:.1f} | {diff} |",
                  flush=True)


def bench_power_law(quick: bool) -> None:
    """Coverage of theory by the 95 % bands of OADEV of generated noise (alpha fixed to the truth)."""
    from avar.models.noise import discrete_psd
    from avar.stability.uncertainty.edf import chi2_bounds, estimator_edf

    n, seeds = (2**14, 20) if quick else (2**17, 50)
    f = np.geomspace(1e-9, 0.5, 400001)
    factors = 2 ** np.arange(0, int(np.log2(n)) - 3)
    print(f"\nPower-law generator, N = {n}, {seeds} seeds, OADEV at m = 1 .. {factors[-1]}, 95 % bands:")
    for alpha in (-2, -1, 0, 1, 2):
        theory = avar.psd_to_deviation(f, discrete_psd(f, alpha), factors.astype(float), rate=1.0)
        edf = estimator_edf("oadev", np.full(factors.size, alpha), factors, n + 1)
        inside, ratio = [], []
        for seed in range(seeds):
            res = avar.oadev(avar.noise.power_law(alpha, n, seed=seed), taus=factors.astype(float))
            lci, uci = chi2_bounds(res.deviation, edf, 0.95)
            inside.append((lci <= theory) & (theory <= uci))
            ratio.append(res.variance / theory**2)
        print(f"  alpha = {alpha:+d}: {np.mean(inside):.1%} of levels inside; mean AVAR / theory "
              f"{np.mean(ratio):.3f} (levels {np.round(np.mean(ratio, axis=0), 2).tolist()})")


def bench_pdev_edf(quick: bool) -> None:
    """Empirical EDF of PDEV (2 mean**2 / variance over simulated series) against the one used for its bounds."""
    from avar.stability.time_error.deviations import pdev_edf

    n, seeds = 1024, (100 if quick else 300)
    factors = 2 ** np.arange(0, 8)
    print(f"\nPDEV EDF, N = {n}, {seeds} series per noise, m = {factors.tolist()}:")
    for alpha in (2, 1, 0, -1, -2):
        v = np.array([avar.pdev(avar.noise.power_law(alpha, n, seed=s), taus=factors.astype(float),
                                alpha=alpha).variance for s in range(seeds)])
        empirical = 2 * v.mean(0) ** 2 / v.var(0)
        used = pdev_edf(np.full(factors.size, alpha), factors, n + 1)
        print(f"  alpha = {alpha:+d}: empirical / used {np.round(empirical / used, 2).tolist()}")


def main(quick: bool | None = None) -> None:
    if quick is None:
        parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
        parser.add_argument("--quick", action="store_true", help="smaller sizes, one repeat")
        quick = parser.parse_args().quick
    warnings.simplefilter("ignore")
    bench_peers(quick)
    bench_stream(quick)
    bench_power_law(quick)
    bench_pdev_edf(quick)


if __name__ == "__main__":
    main()
