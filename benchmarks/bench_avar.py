"""Time avar.avar against allantools and a plain NumPy cumsum implementation.

Usage::

    python benchmarks/bench_avar.py            # N = 1e5, 1e6, 1e7 (+ memory of N = 1e8)
    python benchmarks/bench_avar.py --large    # also time N = 1e8 in the table

Every timing is the median of ``--repeat`` runs after a warm-up call, all
measured in this run on this machine; ratios are peer time / avar time.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import textwrap
import time

import numpy as np

import avar
from avar.estimate import averaging_factors

try:
    import allantools
except ImportError:  # pragma: no cover - the "bench" extra
    allantools = None


def median_time(function, repeat: int) -> float:
    function()  # warm-up (numba compilation, page cache)
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def numpy_cumsum_avar(x: np.ndarray, factors: np.ndarray, type: str) -> np.ndarray:
    """The textbook vectorized implementation: one cumsum, slices per level."""
    cumulative = np.concatenate(([0.0], np.cumsum(x - x.mean())))
    out = np.empty(factors.size)
    for i, m in enumerate(factors):
        ends = cumulative if type == "mo" else cumulative[: (x.size // m) * m + 1 : m]
        step = m if type == "mo" else 1
        d = ends[2 * step :] - 2 * ends[step:-step] + ends[: -2 * step]
        out[i] = np.mean(d * d) / (2.0 * m * m)
    return out


def allantools_call(x: np.ndarray, taus: np.ndarray | str, type: str):
    function = allantools.oadev if type == "mo" else allantools.adev
    return lambda: function(x, rate=1.0, data_type="freq", taus=taus)


def row(label: str, ours: float, peers: dict[str, float | None]) -> str:
    cells = [f"{label:<26}", f"{ours * 1e3:>11.2f}"]
    for value in peers.values():
        cells.append(f"{'-':>11}" if value is None else f"{value * 1e3:>11.2f}")
        cells.append(f"{'-':>8}" if value is None else f"{value / ours:>7.1f}x")
    return " ".join(cells)


def memory_of_large_run(n: int) -> tuple[float, float]:
    """Peak RSS (GB) and avar time (s) of a subprocess computing the 'mo' AV of n samples."""
    code = textwrap.dedent(
        f"""
        import time, numpy as np, avar
        avar.avar(np.random.default_rng(0).standard_normal(1000))  # compile outside the timing
        x = np.random.default_rng(1).standard_normal({n})
        start = time.perf_counter()
        avar.avar(x)
        elapsed = time.perf_counter() - start
        # VmHWM: this address space's peak (ru_maxrss would include the parent's
        # resident size at fork time, which survives exec).
        peak_kb = next(int(line.split()[1]) for line in open("/proc/self/status") if line.startswith("VmHWM"))
        print(elapsed, peak_kb)
        """
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    elapsed, max_rss_kb = out.split()
    return int(max_rss_kb) / 1024**2, float(elapsed)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--large", action="store_true", help="also time N = 1e8")
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    sizes = [10**5, 10**6, 10**7] + ([10**8] if args.large else [])
    rng = np.random.default_rng(0)
    header = f"{'case':<26} {'avar ms':>11} {'allantools':>11} {'ratio':>8} {'numpy':>11} {'ratio':>8}"
    print(header)
    print("-" * len(header))
    for n in sizes:
        x = rng.standard_normal(n)
        taus = averaging_factors(n).astype(float)
        for type in ("mo", "to"):
            ours = median_time(lambda: avar.avar(x, type=type), args.repeat)
            peer_repeat = 1 if n >= 10**8 else args.repeat
            peers = {
                "allantools": median_time(allantools_call(x, taus, type), peer_repeat) if allantools else None,
                "numpy": median_time(lambda: numpy_cumsum_avar(x, taus.astype(np.int64), type), peer_repeat),
            }
            print(row(f"N=1e{len(str(n)) - 1} octave {type}", ours, peers), flush=True)
    x = rng.standard_normal(10**5)
    ours = median_time(lambda: avar.avar(x, taus="all"), 3)
    peers = {
        "allantools": median_time(allantools_call(x, "all", "mo"), 1) if allantools else None,
        "numpy": median_time(lambda: numpy_cumsum_avar(x, averaging_factors(x.size, taus="all"), "mo"), 1),
    }
    print(row("N=1e5 taus='all' mo", ours, peers), flush=True)
    peak_gb, elapsed = memory_of_large_run(10**8)
    print(f"\nN=1e8 octave mo in a subprocess: {elapsed:.2f} s, peak resident memory {peak_gb:.2f} GB "
          "(including the 0.8 GB input series)")


if __name__ == "__main__":
    main()
