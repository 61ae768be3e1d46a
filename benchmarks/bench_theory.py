"""Time avar.moav / avar.noav against the direct sub-block summation of R avar 0.1.3.

The reference is R's MOAV / NOAV loop transcribed to NumPy: for every window, sum the
n x n sub-blocks covmat[A, A], covmat[B, B] and covmat[A, B] (O(T n^2) per scale).
Both run in the same process on the same covariance matrix (a heteroscedastic AR(1),
so that it is not Toeplitz), at every octave scale n = 2, 4, ..., 2^(floor(log2 T) - 1),
one call per function with the whole array of scales. Times are medians over repeats.

Usage::

    PYTHONPATH=src python benchmarks/bench_theory.py [--sizes 1000 4000] [--repeats 7]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

try:
    from avar.models.nonstationary import _check_covmat, moav, noav
except ImportError:  # run from a source checkout without PYTHONPATH
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
    from avar.models.nonstationary import _check_covmat, moav, noav


def direct_av(n: int, covmat: np.ndarray, starts) -> float:
    """R's loop: for each window, sum the n x n sub-blocks."""
    total = 0.0
    for s in starts:
        a, b, c = s, s + n, s + 2 * n
        total += covmat[a:b, a:b].sum() + covmat[b:c, b:c].sum() - 2.0 * covmat[a:b, b:c].sum()
    return total / (n * n * 2 * len(starts))


def direct_moav(ns, covmat):
    t = covmat.shape[0]
    return np.array([direct_av(int(n), covmat, range(t - 2 * n + 1)) for n in ns])


def direct_noav(ns, covmat):
    t = covmat.shape[0]
    return np.array([direct_av(int(n), covmat, range(0, 2 * n * (t // (2 * n)), 2 * n))
                     for n in ns])


def make_covmat(t: int, phi: float, seed: int) -> np.ndarray:
    lag = np.abs(np.subtract.outer(np.arange(t), np.arange(t))).astype(float)
    sd = np.exp(0.5 * np.random.default_rng(seed).standard_normal(t))
    return sd[:, None] * (phi**lag / (1.0 - phi**2)) * sd[None, :]


def median_time(func, repeats: int) -> tuple[float, np.ndarray]:
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = func()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 4000],
                    help="matrix sizes T (default: 1000 4000)")
    ap.add_argument("--repeats", type=int, default=7, help="runs of the library (median)")
    ap.add_argument("--direct-repeats", type=int, default=3,
                    help="runs of the direct summation (median; it is slow)")
    ap.add_argument("--phi", type=float, default=0.9, help="AR(1) coefficient of the covmat")
    ap.add_argument("--seed", type=int, default=1, help="seed of the variance profile")
    args = ap.parse_args(argv)

    print("Theoretical AV from a T x T covariance matrix: avar vs R's sub-block loop (NumPy)")
    print(f"covmat: heteroscedastic AR(1), phi = {args.phi}; all octave scales in one call; "
          f"median of {args.repeats} (library) / {args.direct_repeats} (direct) runs")
    print("'of which check' is the input validation (finite, symmetric) inside the library time")
    header = (f"{'T':>6} {'function':>8} {'scales':>7} {'library [ms]':>13} "
              f"{'of which check':>15} {'direct [ms]':>12} {'speed-up':>9} {'max rel diff':>13}")
    print(header)
    print("-" * len(header))
    for t in args.sizes:
        covmat = make_covmat(t, args.phi, args.seed)
        ns = 2 ** np.arange(1, int(np.log2(t)))
        _check_covmat(covmat)  # warm-up (numba: load or compile the kernel)
        t_check, _ = median_time(lambda: _check_covmat(covmat), args.repeats)
        totals = [0.0, 0.0]
        for name, fast, slow in (("moav", moav, direct_moav), ("noav", noav, direct_noav)):
            fast(ns, covmat)  # warm-up
            t_fast, v_fast = median_time(lambda: fast(ns, covmat), args.repeats)
            t_slow, v_slow = median_time(lambda: slow(ns, covmat), args.direct_repeats)
            totals[0] += t_fast
            totals[1] += t_slow
            diff = float(np.max(np.abs(v_fast / v_slow - 1.0)))
            print(f"{t:>6} {name:>8} {len(ns):>7} {1e3 * t_fast:>13.3f} "
                  f"{1e3 * t_check:>15.3f} {1e3 * t_slow:>12.1f} "
                  f"{t_slow / t_fast:>8.1f}x {diff:>13.1e}")
        print(f"{t:>6} {'both':>8} {len(ns):>7} {1e3 * totals[0]:>13.3f} "
              f"{1e3 * 2 * t_check:>15.3f} {1e3 * totals[1]:>12.1f} {totals[1] / totals[0]:>8.1f}x")
    print("\nnoav's direct loop visits only T/(2n) disjoint blocks (about 1e6 matrix entries at T = 1000"
          " for all scales), so its speed-up is bounded by reading (and checking) the matrix.")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
