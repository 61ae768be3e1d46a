"""Empirical coverage of the AVLR parametric-bootstrap intervals.

Repeats, ``REPETITIONS`` times: simulate white noise WN(sigma2 = 1) of length
N = 10**4 (freq 1 Hz, so the true parameter is sigma = 1), fit ``wn`` on every
octave scale with ``avlr(..., ci=True, B=100)`` and check whether the 95%
interval contains 1. Prints the coverage of this library's intervals
(estimate -/+ z_{0.975} SD, z the normal quantile) and, from the same
bootstrap SDs, the coverage that R ``avar`` 0.1.3's intervals would have had
(half-width dnorm(0.975) SD: its defect 3).

Usage::

    PYTHONPATH=src python benchmarks/avlr_coverage.py [REPETITIONS [SEED]]
"""

from __future__ import annotations

import sys
import time

import numpy as np
from scipy.stats import norm

from avar.fit.avlr import avlr

N = 10_000
REPLICATES = 100
ALPHA = 0.05
TRUE_SIGMA = 1.0


def coverage(repetitions: int, seed: int) -> dict[str, float]:
    """Coverage of the library's and of R's intervals, and the mean half-width."""
    rng = np.random.default_rng(seed)
    hits = hits_r = 0
    widths = []
    for _ in range(repetitions):
        x = TRUE_SIGMA * rng.standard_normal(N)
        fit = avlr(x, wn=range(1, 13), ci=True, B=REPLICATES, alpha=ALPHA, seed=rng)
        row = fit.ci.loc["WN"]
        hits += row["Lower"] <= TRUE_SIGMA <= row["Upper"]
        half_r = norm.pdf(1 - ALPHA / 2) * row["SD"]  # R 0.1.3: dnorm(1 - alpha/2)
        hits_r += row["Estimate"] - half_r <= TRUE_SIGMA <= row["Estimate"] + half_r
        widths.append(row["Upper"] - row["Lower"])
    return {"coverage": hits / repetitions, "coverage_r": hits_r / repetitions, "width": float(np.mean(widths))}


def main(argv: list[str]) -> None:
    repetitions = int(argv[1]) if len(argv) > 1 else 200
    seed = int(argv[2]) if len(argv) > 2 else 2024
    start = time.perf_counter()
    result = coverage(repetitions, seed)
    elapsed = time.perf_counter() - start
    standard_error = np.sqrt(0.95 * 0.05 / repetitions)
    print(f"AVLR bootstrap coverage: WN(sigma2=1), N = {N}, wn on all 12 scales, B = {REPLICATES}, "
          f"{repetitions} repetitions (seed {seed})")
    print(f"  95% normal-quantile intervals (this library): coverage {result['coverage']:.3f} "
          f"(nominal 0.95 +/- {2 * standard_error:.3f}), mean width {result['width']:.4f}")
    print(f"  R avar 0.1.3 (dnorm instead of qnorm):      coverage {result['coverage_r']:.3f}")
    print(f"  {elapsed:.1f} s ({1e3 * elapsed / repetitions:.0f} ms per fit with B = {REPLICATES})")


if __name__ == "__main__":
    main(sys.argv)
