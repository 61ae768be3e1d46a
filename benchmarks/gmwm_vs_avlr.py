"""GMWM against AVLR on simulated series with known truth, in the same run.

Scenarios (per-sample parameters, freq 1 Hz, N = 10**5):

(a) WN(sigma2=1) + RW(gamma2=1e-6)
(b) WN(sigma2=1) + AR1(phi=0.99, sigma2=1e-2) + RW(gamma2=3e-5)   (AR1 correlation time 100 samples)
(c) QN(q2=1) + WN(sigma2=1) + RW(gamma2=1e-4) + DR(omega=1.3e-4)

Each process dominates a range of scales (the crossings of the AV lines are
about m = 3, 170 and 4000 in (c)).

For each of ``SERIES`` simulated series: ``avar.gmwm`` with ``ci=True`` (B
bootstrap replicates) and ``avar.avlr`` on hand-chosen scales (each process on
the octave levels where it dominates most; AVLR has no AR1) with ``ci=True``.
AVLR estimates (continuous-time sigma, Q, gamma, omega) are converted to the
same per-sample parameters (sigma2 = sigma^2, q2 = Q^2, gamma2 = gamma^2,
omega) as are its interval bounds (monotone maps). Prints, per parameter:
bias (and its standard error), RMSE, the RMSE ratio GMWM / AVLR, the coverage
of the nominal 95% intervals, and the median relative error; then the time per
fit (without and with intervals).

Usage::

    PYTHONPATH=src python benchmarks/gmwm_vs_avlr.py [SERIES [B [SEED [SCENARIOS]]]]

(SCENARIOS: a subset of the letters, e.g. ``bc``; default all three.)
"""

from __future__ import annotations

import sys
import time

import numpy as np
import pandas as pd

import avar
from avar.models import AR1, DR, QN, RW, WN

N = 100_000
#: Print the running table every this many series.
REPORT_EVERY = 20
SCENARIOS = {
    "a": (WN(sigma2=1.0) + RW(gamma2=1e-6), "WN + RW",
          {"wn": range(1, 7), "rw": range(13, 16)}),
    "b": (WN(sigma2=1.0) + AR1(phi=0.99, sigma2=1e-2) + RW(gamma2=3e-5), "WN + AR1 + RW",
          {"wn": range(1, 4), "rw": range(13, 16)}),
    "c": (QN(q2=1.0) + WN(sigma2=1.0) + RW(gamma2=1e-4) + DR(omega=1.3e-4), "QN + WN + RW + DR",
          {"qn": [1], "wn": range(4, 6), "rw": range(9, 11), "dr": range(14, 16)}),
}
#: AVLR process -> (GMWM label, map from the continuous parameter to the per-sample one at 1 Hz).
AVLR_PARAMETERS = {"WN": ("WN.sigma2", np.square), "QN": ("QN.q2", np.square),
                   "RW": ("RW.gamma2", np.square), "DR": ("DR.omega", np.abs)}


def run(name: str, series: int, replicates: int, rng: np.random.Generator) -> tuple[pd.DataFrame, dict]:
    truth, spec, scales = SCENARIOS[name]
    labels = list(avar.gmwm(truth.simulate(N, seed=0), spec).estimates.index)
    true = pd.Series(truth.parameter_vector, index=labels)
    rows = {"gmwm": [], "avlr": []}
    cover = {"gmwm": [], "avlr": []}
    times = {"gmwm": 0.0, "gmwm ci": 0.0, "avlr": 0.0, "avlr ci": 0.0}
    for _ in range(series):
        x = truth.simulate(N, seed=rng)
        start = time.perf_counter()
        avar.gmwm(x, spec)
        times["gmwm"] += time.perf_counter() - start
        start = time.perf_counter()
        fit = avar.gmwm(x, spec, ci=True, B=replicates, seed=rng)
        times["gmwm ci"] += time.perf_counter() - start
        rows["gmwm"].append(fit.estimates)
        cover["gmwm"].append((fit.ci["Lower"] <= true) & (true <= fit.ci["Upper"]))
        start = time.perf_counter()
        avar.avlr(x, **scales)
        times["avlr"] += time.perf_counter() - start
        start = time.perf_counter()
        slope = avar.avlr(x, **scales, ci=True, B=replicates, seed=rng)
        times["avlr ci"] += time.perf_counter() - start
        estimate, hit = {}, {}
        for process, (label, to_sample) in AVLR_PARAMETERS.items():
            if process in slope.estimates.index:
                estimate[label] = to_sample(slope.estimates[process])
                low, high = sorted(to_sample(slope.ci.loc[process, ["Lower", "Upper"]].to_numpy()))
                low = 0.0 if slope.ci.loc[process, "Lower"] < 0 <= slope.ci.loc[process, "Upper"] else low
                hit[label] = low <= true[label] <= high
        rows["avlr"].append(pd.Series(estimate))
        cover["avlr"].append(pd.Series(hit))
        done = len(rows["gmwm"])
        if done % REPORT_EVERY == 0 and done < series:
            print(f"({name}) after {done} series:\n{summarize(true, rows, cover, done).to_string()}", flush=True)
    return summarize(true, rows, cover, series), {key: value / series for key, value in times.items()}


def summarize(true: pd.Series, rows: dict, cover: dict, series: int) -> pd.DataFrame:
    """Bias, its standard error, RMSE, median relative error and coverage per method and parameter."""
    table = {}
    for method in ("gmwm", "avlr"):
        draws = pd.DataFrame(rows[method])
        error = draws - true[draws.columns]
        table[method] = pd.DataFrame({
            "true": true[draws.columns],
            "bias": error.mean(),
            "bias SE": error.std(ddof=1) / np.sqrt(series),
            "RMSE": np.sqrt((error**2).mean()),
            "median rel err": (draws / true[draws.columns] - 1).abs().median(),
            "coverage": pd.DataFrame(cover[method]).astype(float).mean(),
        })
    merged = pd.concat(table, axis=1)
    merged[("ratio", "RMSE gmwm/avlr")] = merged[("gmwm", "RMSE")] / merged[("avlr", "RMSE")]
    return merged


def main() -> None:
    series = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    replicates = int(sys.argv[2]) if len(sys.argv) > 2 else 100
    seed = int(sys.argv[3]) if len(sys.argv) > 3 else 2026
    rng = np.random.default_rng(seed)
    avar.gmwm(WN(sigma2=1.0).simulate(1000, seed=0), "WN")  # compile and import before timing
    avar.avlr(WN(sigma2=1.0).simulate(1000, seed=0), wn=[1, 2], ci=True, B=2)
    pd.set_option("display.width", 250)
    pd.set_option("display.max_columns", 30)
    for name in sys.argv[4] if len(sys.argv) > 4 else SCENARIOS:
        table, times = run(name, series, replicates, rng)
        print(f"\n({name}) {SCENARIOS[name][0]!r}: {series} series, N = {N}, B = {replicates}")
        print(table.to_string(float_format=lambda v: f"{v:.4g}"))
        print("time per fit (s): " + ", ".join(f"{k} {v:.3f}" for k, v in times.items()), flush=True)


if __name__ == "__main__":
    main()
