"""How many degrees of freedom do MTOTVAR and HTOTVAR really have? Simulation against the formulas.

The EDF of a variance estimate v is 2 E[v]^2 / var(v). Over R records of power-law
phase noise (Kasdin and Walter, exact spectrum, ``avar.models.noise.power_law``)
of N = 1001 points, the size of Stable32's PHASE.DAT, this script estimates it per
level and prints it next to:

* ``avar``: what avar uses (:func:`avar.stability.uncertainty.total_edf.total_edf`), which is
  Stable32 1.60's: its printed one-sigma bounds of PHASE.DAT and of a 1253-point
  clock record are reproduced to 1e-4 (``tests/stability/test_total_theo.py``). For
  MTOTVAR from m = 10 that is b (N - 1) / m - c, (b, c) = (1.3313, 1.8927) at white
  FM, (1.7319, 2.9896) at flicker PM, (0.9204, 0.7596) at flicker FM, a law of no
  published table; NIST SP 1065 Table 8 at the other noises, the modified Allan
  variance's Greenhall EDF below m = 10. HTOTVAR: (N / m) / (b0 + b1 m / N) from
  m = 16, NIST SP 1065 Table 5's simple EDF plus 2 below and at PM;
* ``nist``: NIST SP 1065 Table 8 for MTOTVAR from m = 10 (b N / m - c).

The standard error of a simulated EDF comes from 200 bootstrap resamples of the R
estimates. A formula is right where it lies within a few standard errors.

Run: ``python benchmarks/total_edf_simulation.py [--records 2000]`` (about 1 min per
1,000 records on 2 cores). Measured (2,000 records, seed 0 .. 1999), white FM:

====  ===========  ======  ==================
m     simulation   nist    avar (= Stable32)
====  ===========  ======  ==================
16    64.2         67.6    81.3
32    32.9         33.2    39.7
64    14.7         16.0    18.9
128   6.2          7.4     8.5
====  ===========  ======  ==================

so Stable32's MTOTDEV intervals at m >= 10 are those of 20 to 40 % more degrees of
freedom than the estimates have (flicker PM: 50 % at m = 128). avar prints Stable32's
(its tables are the reference a clock engineer checks against) and says so; Table 8's
are closer to the simulation.
"""

from __future__ import annotations

import argparse

import numpy as np

import avar
from avar.models.noise import power_law
from avar.stability.uncertainty.total_edf import MTOT_EDF, MTOT_EDF_FROM, total_edf

N_PHASE = 1001
LEVELS = {"mtotdev": [1, 4, 10, 16, 32, 64, 128, 256], "htotdev": [2, 4, 8, 16, 32, 64, 128, 256]}


def simulated_edf(estimator: str, alpha: int, records: int, factors: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """EDF per level and its bootstrap standard error, from ``records`` simulated records."""
    variances = np.empty((records, len(factors)))
    for seed in range(records):
        x = power_law(alpha, N_PHASE, data_type="phase", seed=seed)
        result = getattr(avar, estimator)(x, data_type="phase", taus=np.array(factors, dtype=float), alpha=alpha)
        variances[seed] = result.variance

    def edf(v: np.ndarray) -> np.ndarray:
        return 2.0 * v.mean(axis=0) ** 2 / v.var(axis=0, ddof=1)

    rng = np.random.default_rng(1)
    boot = np.array([edf(variances[rng.integers(0, records, records)]) for _ in range(200)])
    return edf(variances), boot.std(axis=0)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--records", type=int, default=1000)
    parser.add_argument("--cases", nargs="*", default=["mtotdev:0", "mtotdev:1", "mtotdev:-1", "htotdev:0",
                                                       "htotdev:1", "htotdev:-1"])
    args = parser.parse_args()
    for case in args.cases:
        estimator, alpha = case.split(":")[0], int(case.split(":")[1])
        factors = LEVELS[estimator]
        edf, error = simulated_edf(estimator, alpha, args.records, factors)
        ours = total_edf(estimator, np.full(len(factors), alpha), np.array(factors), N_PHASE)
        print(f"\n{estimator}, alpha = {alpha}, N = {N_PHASE}, {args.records} records")
        print(f"{'m':>5} {'simulated':>10} {'+/-':>6} {'avar':>8} {'nist':>8}")
        for m, e, s, o in zip(factors, edf, error, ours):
            b, c = MTOT_EDF[alpha]
            nist = f"{b * N_PHASE / m - c:8.2f}" if estimator == "mtotdev" and m >= MTOT_EDF_FROM else f"{'':>8}"
            print(f"{m:5d} {e:10.2f} {s:6.2f} {o:8.2f} {nist}")


if __name__ == "__main__":
    main()
