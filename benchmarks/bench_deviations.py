"""Time the deviation family against allantools on the same data and taus, same run.

Usage::

    python benchmarks/bench_deviations.py            # N = 1e5, 1e6, 1e7 (totdev up to 1e6)
    python benchmarks/bench_deviations.py --quick    # N = 1e5, 1e6, one repeat
    python benchmarks/bench_deviations.py --acceptance  # N = 1e6 alone, 5 repeats, no catalogue
    python benchmarks/bench_deviations.py --total    # MTOTDEV, TTOTDEV, HTOTDEV, Theo1, ThêoH, MHTOTDEV
    python benchmarks/bench_deviations.py --total --sizes 1000 3000 100000

``--total``: the total and Theo statistics (white FM, octave taus, no bias
correction so that both compute the same numbers) against allantools, timed
once per call (allantools is O(N^2) Python: 10 s for MTOTDEV at N = 3e3) up
to ``--peer-max`` points, and ours alone beyond (ThêoH and MHTOTDEV have no peer); wall
and CPU time (the CPU time counts every thread). MTOTDEV, TTOTDEV, HTOTDEV and MHTOTDEV
are also timed in the same run by the direct O(N m) loop they used before the blocked
O(N) expansion (:mod:`avar._kernels.total.blocks`, :mod:`avar._kernels.total.mhtot_blocks`), with the largest
relative difference of the two results; above ``--loop-max`` points the loop is
not run and its time is extrapolated from the largest N timed by the octave sum
of (N - 3m + 1) m (marked ``~``).

Every estimator of the registry is timed; the peer columns only where allantools has the
statistic (not MHDEV and HTDEV, whose rows show ours alone).

Frequency data (white FM), ``taus="octave"`` on both sides (allantools is given
our averaging times, so both compute the same levels). Columns:

* ``allantools``: the plain call (deviations only);
* ``allantools full``: the allantools recipe for everything our public
  function returns: the deviation, then per tau ``autocorr_noise_id`` (Barnes's
  B1 and R(n), ``allantools.ci.b1``/``rn`` and their boundaries, where fewer
  than 30 points remain and ``autocorr_noise_id`` raises), ``edf_greenhall``
  (``edf_totdev`` for totdev) and ``confidence_interval`` (at our 0.683);
* ``core``: :func:`avar.stability.classic.core.deviation_levels` alone
  (variances and term counts: what the plain allantools call computes);
* ``avar``: the public function (validation, variances, noise
  identification, EDF and chi-squared bounds).

Times are the median of a few runs after a warm-up (numba compilation);
ratios are peer time / our time: ``core`` and ``avar`` against the plain
call, ``full`` = allantools full / avar. The acceptance point checked at the
end: the public function at least 3x faster than the plain allantools call at
N = 1e6, for every estimator.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import time
import warnings

import bench_catalogue  # benchmarks/bench_catalogue.py
import numpy as np
from timing import median_time  # benchmarks/timing.py

import avar
from avar._kernels.runtime.paths import forced
from avar.stability.classic.core import deviation_levels
from avar.stability.shared.grids import deviation_factors
from avar.stability.shared.registry import CLASSIC as ESTIMATORS

try:
    import allantools
    from allantools import ci as atci
except ImportError:  # pragma: no cover - the "bench" extra
    allantools = atci = None

#: Greenhall's (d, overlapping, modified) of each estimator, as allantools.ci.confidence_interval_noiseID.
GREENHALL = {"adev": (2, False, False), "oadev": (2, True, False), "mdev": (2, True, True),
             "tdev": (2, True, True), "hdev": (3, False, False), "ohdev": (3, True, False)}
TARGET = 3.0
ACCEPTANCE_N = 10**6


def allantools_alpha(x: np.ndarray, m: int, rate: float, dmax: int) -> int:
    """allantools' noise ID at one tau: lag-1 autocorrelation, B1 and R(n) below 30 points."""
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # it prints before raising
            return int(atci.autocorr_noise_id(x, m, data_type="phase", dmin=0, dmax=dmax)[0])
    except NotImplementedError:
        k = (len(x) - 1) // m
        if k < 3:
            return 0
        b1 = atci.b1(x, m, rate)
        for b_hi, alpha in ((-3, -2), (-2, -1), (-1, 0)):
            if b1 > atci.b1_boundary(b_hi, k):
                return alpha
        return 1 if atci.rn(x, m, rate) > atci.rn_boundary(m, 0) else 2


def allantools_full(estimator: str, y: np.ndarray, taus: np.ndarray, rate: float = 1.0):
    """The deviation and its chi-squared bounds per tau, the allantools way."""
    out_taus, devs, _, _ = getattr(allantools, estimator)(y, rate=rate, data_type="freq", taus=taus)
    x = allantools.frequency2phase(y, rate)
    dmax = 3 if estimator in ("hdev", "ohdev") else 2
    bounds = []
    for tau, dev in zip(out_taus, devs):
        m = int(round(tau * rate))
        alpha = allantools_alpha(x, m, rate, dmax)
        if estimator == "totdev":
            edf = atci.edf_totdev(len(x), m, alpha)
        else:
            d, overlapping, modified = GREENHALL[estimator]
            edf = atci.edf_greenhall(alpha=alpha, d=d, m=m, N=len(x), overlapping=overlapping, modified=modified)
        bounds.append(atci.confidence_interval(dev, edf, ci=0.683) if edf else (np.nan, np.nan))
    return devs, bounds


TOTAL = ("mtotdev", "ttotdev", "htotdev", "theo1", "theoh", "mhtotdev")
#: Those without a bias correction to turn off, and without an allantools peer.
UNPAIRED = ("theoh", "mhtotdev")


def once(function) -> float:
    """Wall time (s) of one call."""
    start = time.perf_counter()
    function()
    return time.perf_counter() - start


def window_points(n: int) -> float:
    """sum over the octave factors m <= N / 3 of (N - 3m + 1) m: the O(N m) statistics' work."""
    m = 2 ** np.arange(int(np.log2(n // 3)) + 1, dtype=np.float64)
    return float(np.sum((n - 3 * m + 1) * m))


#: The statistics whose levels cost O(N m) by the direct loop (O(N) by the blocked expansion).
LOOPS = ("mtotdev", "ttotdev", "htotdev", "mhtotdev")


@contextlib.contextmanager
def direct_loop():
    """MTOTDEV, TTOTDEV, HTOTDEV and MHTOTDEV by the direct O(N m) loop (the path before the expansion)."""
    from avar._kernels.total import mhtot
    from avar._kernels.total import windows as total

    saved = total.FAST_WORK, mhtot.FAST_WORK
    total.FAST_WORK = mhtot.FAST_WORK = 1 << 62
    try:
        yield
    finally:
        total.FAST_WORK, mhtot.FAST_WORK = saved


def timed(function, y, options) -> tuple[float, float, object]:
    """Wall and CPU time (s) of one call, and its result."""
    results = []
    cpu = time.process_time()
    wall = once(lambda: results.append(function(y, **options)))
    return wall, time.process_time() - cpu, results[0]


def bench_total(sizes: list[int], peer_max: int, loop_max: int) -> None:
    """Time the total and Theo statistics against allantools (up to ``peer_max`` points); MTOTDEV,
    TTOTDEV and HTOTDEV also by the direct loop (up to ``loop_max`` points, extrapolated beyond)."""
    print("| statistic | N | levels | allantools (ms) | avar wall (ms) | avar CPU (ms) | avar vs allantools "
          "| direct loop wall (ms) | direct loop CPU (ms) | direct / avar (wall) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    measured = {}  # statistic -> (N, wall, cpu) of the direct loop's largest run
    for n in sizes:
        y = np.random.default_rng(0).standard_normal(n) * 1e-11
        for name in TOTAL:
            options = {} if name in UNPAIRED else {"bias_correction": False}
            function = getattr(avar, name)
            function(y[:1000], **options)  # numba compilation
            ours, cpu, result = timed(function, y, options)
            peer = "-"
            ratio = "-"
            if allantools is not None and name not in UNPAIRED and n <= peer_max:
                factors = result.averaging_factors.astype(float)
                at = getattr(allantools, name)
                seconds = once(lambda: at(y, rate=1.0, data_type="freq", taus=factors))  # noqa: B023
                peer, ratio = f"{seconds * 1e3:.0f}", f"{seconds / ours:.0f}x"
            loop = "| - | - | - |"
            if name in LOOPS:
                if n <= loop_max:
                    with direct_loop():
                        function(y[:1000], **options)
                        wall, loop_cpu, direct = timed(function, y, options)
                    measured[name] = (n, wall, loop_cpu)
                    worst = np.max(np.abs(direct.variance / result.variance - 1))
                    loop = f"| {wall * 1e3:.1f} | {loop_cpu * 1e3:.1f} | {wall / ours:.0f}x (rel. diff {worst:.0e}) |"
                elif name in measured:
                    base, wall, loop_cpu = measured[name]
                    scale = window_points(n) / window_points(base)
                    loop = (f"| ~{wall * scale * 1e3:.3g} | ~{loop_cpu * scale * 1e3:.3g} | ~{wall * scale / ours:.0f}x "
                            f"(extrapolated from N = {base:.0e}) |")
            print(f"| {name} | {n:.0e} | {len(result)} | {peer} | {ours * 1e3:.1f} | {cpu * 1e3:.1f} | {ratio} {loop}",
                  flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="N = 1e5 and 1e6, one repeat")
    parser.add_argument("--acceptance", action="store_true",
                        help="N = 1e6 alone (the acceptance point), 5 repeats, without the catalogue")
    parser.add_argument("--total", action="store_true", help="the total and Theo statistics instead")
    parser.add_argument("--sizes", type=int, nargs="+", default=[3000, 100000, 1000000],
                        help="N of --total (default 3e3 1e5 1e6)")
    parser.add_argument("--peer-max", type=int, default=3000, help="largest N timed for allantools in --total")
    parser.add_argument("--loop-max", type=int, default=100000,
                        help="largest N run by the direct O(N m) loop in --total (beyond: extrapolated)")
    args = parser.parse_args()
    warnings.simplefilter("ignore")  # allantools' polyfit RankWarning on long series
    if args.total:
        bench_total(args.sizes, args.peer_max, args.loop_max)
        return
    sizes = [ACCEPTANCE_N] if args.acceptance else [10**5, 10**6] if args.quick else [10**5, 10**6, 10**7]
    repeat = 5 if args.acceptance else 1 if args.quick else 3
    print("| estimator | N | levels | allantools (ms) | allantools full (ms) | avar core (ms) | avar (ms) "
          "| core vs allantools | avar vs allantools | avar vs allantools full |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    public_ratio = {}
    for n in sizes:
        y = np.random.default_rng(0).standard_normal(n) * 1e-11
        with forced("compiled"):  # every route's kernels compiled first, as `avar warmup` leaves them
            for estimator in ESTIMATORS:
                getattr(avar, estimator)(y)
        for estimator in ESTIMATORS:
            if estimator == "totdev" and n > 10**6:
                continue
            factors = deviation_factors(estimator, n + 1, 1.0, "octave")
            ours = median_time(lambda: getattr(avar, estimator)(y), repeat)
            core = median_time(lambda: deviation_levels(estimator, y, factors, "freq"), repeat)
            if allantools is None:
                print(f"| {estimator} | {n:.0e} | {factors.size} | - | - | {core * 1e3:.1f} | {ours * 1e3:.1f} "
                      "| - | - | - |", flush=True)
                continue
            if not hasattr(allantools, estimator):  # mhdev, htdev: no allantools function to compare
                print(f"| {estimator} | {n:.0e} | {factors.size} | - | - | {core * 1e3:.1f} | {ours * 1e3:.1f} "
                      "| - | - | - |", flush=True)
                continue
            taus = factors.astype(float)
            peer_repeat = 1 if n >= 10**7 else repeat
            peer = median_time(lambda: getattr(allantools, estimator)(y, rate=1.0, data_type="freq", taus=taus),
                               peer_repeat)
            full = median_time(lambda: allantools_full(estimator, y, taus), peer_repeat)
            if n == ACCEPTANCE_N:
                public_ratio[estimator] = peer / ours
            print(f"| {estimator} | {n:.0e} | {factors.size} | {peer * 1e3:.1f} | {full * 1e3:.1f} "
                  f"| {core * 1e3:.1f} | {ours * 1e3:.1f} | {peer / core:.1f}x | {peer / ours:.1f}x "
                  f"| {full / ours:.1f}x |", flush=True)
    if public_ratio:
        print(f"\nAcceptance (public function >= {TARGET:g}x the plain allantools call at N = {ACCEPTANCE_N:.0e}):")
        for estimator, ratio in public_ratio.items():
            print(f"  {estimator:7s} {ratio:5.2f}x  {'holds' if ratio >= TARGET else 'NOT MET'}")
    if not args.acceptance:
        print("\nThe rest of the catalogue (benchmarks/bench_catalogue.py):")
        bench_catalogue.main(quick=args.quick)


if __name__ == "__main__":
    main()
