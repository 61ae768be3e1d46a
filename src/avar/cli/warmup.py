"""``avar warmup``: compile every kernel once, so that no later command waits for numba.

numba compiles each kernel on first use and keeps the machine code in its cache (see
:mod:`avar._kernels.runtime.cache`). A new environment (a venv, a CI job, a container
image) pays that once per kernel, seconds each, spread over the first calls. This command
pays it up front: it runs every public statistic on a small record of each data type (with
a gap too, which takes the gap-aware kernels), the Allan variance of float64 and float32
logs short and long (the long one takes the streaming sweep), the joint estimator, the noise
report and the stream, and prints how long each family took. Run it at install time or in
a container's build step; a second run loads everything from the cache in about a second.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable

#: Samples of the records the statistics are warmed on (short: the compile, not the data, costs).
SHORT = 4096
#: Statistics that refuse gaps (no gap-aware kernels to warm).
GAP_FREE = frozenset({"theoh"})
#: Samples of the long Allan-variance record: beyond 2**22 a log takes the streaming sweep's kernels.
LONG = 2**22 + 4096


def _steps(full: bool) -> list[tuple[str, Callable[[], object]]]:
    """(label, call) of every warm-up step; ``full`` adds the long-record kernels."""
    import numpy as np

    import avar
    from avar.stability.shared.registry import DEVIATION_STATISTICS

    rng = np.random.default_rng(0)
    y = rng.standard_normal(SHORT)
    x = np.cumsum(y) * 1e-9
    gappy = y.copy()
    gappy[SHORT // 3] = np.nan

    def deviations() -> None:
        for name in DEVIATION_STATISTICS:
            statistic = getattr(avar, name)
            statistic(y)
            statistic(x, data_type="phase")
            if name not in GAP_FREE:
                statistic(gappy, nan_policy="omit")

    def allan() -> None:
        for data in (y, y.astype(np.float32)):
            for kind in ("mo", "to"):
                avar.avar(data, type=kind, rate=100.0)
                avar.avar(data, type=kind, rate=100.0, taus="all")
        avar.avar(gappy, nan_policy="omit")
        avar.avar(y, ci="chi2")

    def long_logs() -> None:
        long = rng.standard_normal(LONG)
        for data in (long, long.astype(np.float32)):
            for kind in ("mo", "to"):
                avar.avar(data, type=kind)

    def fits() -> None:
        imu = avar.IMU(np.column_stack([y, y[::-1], y[::2].repeat(2), y, y, y]), 100.0, gyro=[0, 1, 2], accel=[3, 4, 5])
        avar.avlr(avar.avar(y, rate=100.0), wn=range(1, 5), rw=range(6, 10))
        avar.gmwm(y, avar.WN(sigma2=1.0) + avar.RW(gamma2=1e-6))
        avar.noise_report(imu)
        avar.robust_avar(y)

    def stream() -> None:
        for name in ("oadev", "adev", "mdev", "tdev", "hdev", "ohdev"):
            avar.Stream(name, taus=[1, 10, 100]).update(y[: SHORT // 2]).update(y[SHORT // 2:]).result()

    steps = [("the deviation catalogue", deviations), ("avar() and its intervals", allan),
             ("AVLR, GMWM, the noise report, robust AV", fits), ("Stream", stream)]
    if full:
        steps.append((f"avar() of logs over {LONG - 4096:,} samples", long_logs))
    return steps


def run(args: argparse.Namespace) -> int:
    from avar._kernels.runtime.cache import user_cache_dir
    from avar._kernels.runtime.paths import forced

    start = time.perf_counter()
    for label, step in _steps(not args.quick):
        began = time.perf_counter()
        with forced("compiled"):  # short records would take the NumPy twins of cold kernels
            step()
        print(f"avar warmup: {label}: {time.perf_counter() - began:.1f} s", file=sys.stderr, flush=True)
    import os

    where = os.environ.get("NUMBA_CACHE_DIR") or f"numba's cache beside the package (or {user_cache_dir()})"
    print(f"avar warmup: every kernel compiled and cached in {time.perf_counter() - start:.1f} s; "
          f"kept in {where}")
    return 0


def add_parser(commands) -> None:
    warm = commands.add_parser(
        "warmup", help="compile and cache every numerical kernel now (first-run wait paid up front)",
        description="Compile every numerical kernel once and store it in numba's cache, so that no later "
                    "command or call waits for the compiler: run it after installing, or in a container's "
                    "build step. Prints the time of each family; a second run takes about a second.")
    warm.add_argument("--quick", action="store_true",
                      help="leave out the kernels of logs over 2**22 samples (default: warm them too)")
    warm.set_defaults(handler=run)
