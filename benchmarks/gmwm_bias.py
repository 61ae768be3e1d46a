"""Bias of the GMWM point estimates on many series, and where DR's omega bias comes from.

The scenarios of ``gmwm_vs_avlr.py`` (N = 10**5), fitted with the default
weights and no bootstrap (a fit takes milliseconds, so thousands of series
measure a bias to a few tenths of a per cent). Prints, per parameter, the
mean relative error, its standard error, their ratio z and the relative SD.

For a drift the Allan variance is linear in omega**2 (omega**2 tau**2 / 2),
so the fit estimates omega**2 and omega_hat is its square root. If
omega_hat**2 is unbiased, omega_hat is biased low by Jensen's inequality,
about -var(omega_hat) / (2 omega) (delta method). The script prints the
bias of omega_hat**2 and that prediction next to the measured bias of
omega_hat. (No unbiased estimator of sqrt(mu) exists from X ~ N(mu, s**2):
the mean of any statistic is analytic in mu, sqrt is not at 0.)

Usage::

    python benchmarks/gmwm_bias.py [SERIES [FIRST_SEED [SCENARIOS]]]

(default 2000 series per scenario, seeds 10000 ..., scenarios ``abc``).
"""

from __future__ import annotations

import multiprocessing
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pandas as pd
from gmwm_vs_avlr import SCENARIOS, N

import avar


def fit_one(task: tuple[str, int]) -> np.ndarray:
    name, seed = task
    truth, spec, _ = SCENARIOS[name]
    return avar.gmwm(truth.simulate(N, seed=seed), spec).estimates.to_numpy()


def bias_table(name: str, series: int, first_seed: int, workers: int) -> tuple[pd.DataFrame, float]:
    truth, spec, _ = SCENARIOS[name]
    start = time.perf_counter()
    # spawn: the parent has run OpenMP-threaded kernels, after which fork() is unsafe
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        tasks = [(name, seed) for seed in range(first_seed, first_seed + series)]
        estimates = np.array(list(pool.map(fit_one, tasks, chunksize=20)))
    elapsed = time.perf_counter() - start
    labels = list(avar.gmwm(truth.simulate(N, seed=0), spec).estimates.index)
    relative = estimates / np.asarray(truth.parameter_vector) - 1.0
    mean, se = relative.mean(axis=0), relative.std(axis=0, ddof=1) / np.sqrt(series)
    table = pd.DataFrame({"rel. bias": mean, "SE": se, "z": mean / se, "rel. SD": relative.std(axis=0, ddof=1)},
                         index=labels)
    if "DR.omega" in labels:
        k = labels.index("DR.omega")
        squared = (estimates[:, k] / truth.parameter_vector[k]) ** 2 - 1.0
        table.loc["DR.omega**2"] = [squared.mean(), squared.std(ddof=1) / np.sqrt(series),
                                    squared.mean() / (squared.std(ddof=1) / np.sqrt(series)), squared.std(ddof=1)]
        table.loc["Jensen prediction for omega", "rel. bias"] = -relative[:, k].var(ddof=1) / 2.0
    return table, elapsed


def main() -> None:
    series = int(sys.argv[1]) if len(sys.argv) > 1 else 2000
    first_seed = int(sys.argv[2]) if len(sys.argv) > 2 else 10_000
    for name in sys.argv[3] if len(sys.argv) > 3 else SCENARIOS:
        table, elapsed = bias_table(name, series, first_seed, workers=2)
        print(f"\n({name}) {SCENARIOS[name][0]!r}: {series} series, N = {N}, default weights ({elapsed:.0f} s)")
        print(table.to_string(float_format=lambda v: f"{v:+.4f}"), flush=True)


if __name__ == "__main__":
    main()
