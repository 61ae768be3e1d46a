"""Time the streaming Allan variance kernel against allantools and a NumPy cumsum, same run.

Usage::

    python benchmarks/bench_avar.py              # N = 1e3 .. 1e8, memory of 1e8 float64/float32
    python benchmarks/bench_avar.py --huge       # also a 1e9-sample float32 memmap (RssAnon sampled)

Columns: ``kernel`` is ``avar._kernels.streaming_allan_variance`` (the streaming
entry point, called directly); ``avar.avar`` is the public function (until the
integrator wires the kernel in, it copies to float64 and runs the old
cumulative-sum kernels). Ratios are peer time / kernel time, all measured in
this run. ``limit`` is the fraction of one ``numpy.sum`` pass over the same
array (time of the sum / time of the kernel): 1.0 would be reading the input
once at full memory bandwidth.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import textwrap
import threading
import time

import numpy as np

import avar
from avar._kernels import streaming_allan_variance as allan_variance_columns
from avar.stability.grids import averaging_factors

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


def allantools_call(x: np.ndarray, taus: np.ndarray, type: str):
    function = allantools.oadev if type == "mo" else allantools.adev
    return lambda: function(x, rate=1.0, data_type="freq", taus=taus)


def fmt(seconds: float | None) -> str:
    return "-" if seconds is None else f"{seconds * 1e3:.3f}"


def ratio(peer: float | None, ours: float) -> str:
    return "-" if peer is None else f"{peer / ours:.1f}x"


SUBPROCESS = """
import time, numpy as np
from avar._kernels import streaming_allan_variance as allan_variance_columns
from avar.stability.grids import averaging_factors
allan_variance_columns(np.random.default_rng(0).standard_normal(300_000).astype({dtype!r}), np.array([2, 4]), "mo")
{load}
f = averaging_factors(x.shape[0])
start = time.perf_counter()
allan_variance_columns(x, f, {type!r})
elapsed = time.perf_counter() - start
status = dict(line.split(":", 1) for line in open("/proc/self/status"))
print(elapsed, int(status["VmHWM"].split()[0]), x.nbytes)
"""


def peak_memory(n: int, dtype: str, type: str = "mo") -> tuple[float, float, float]:
    """(seconds, peak resident GB, input GB) of a fresh process computing the octave AV of n samples."""
    load = f"x = np.random.default_rng(1).standard_normal({n}).astype({dtype!r})"
    code = textwrap.dedent(SUBPROCESS.format(dtype=dtype, load=load, type=type))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    return float(out[0]), int(out[1]) / 1024**2, int(out[2]) / 1024**3


def huge_memmap_run(n: int) -> None:
    """1e9-sample float32 memmap: time and RssAnon sampled every 0.2 s in the child."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "huge.npy")
        x = np.lib.format.open_memmap(path, mode="w+", dtype=np.float32, shape=(n,))
        rng = np.random.default_rng(2)
        for start in range(0, n, 1 << 24):
            stop = min(n, start + (1 << 24))
            x[start:stop] = rng.standard_normal(stop - start, dtype=np.float32)
        x.flush()
        del x
        code = textwrap.dedent(
            f"""
            import threading, time, numpy as np
            from avar._kernels import streaming_allan_variance as allan_variance_columns
            from avar.stability.grids import averaging_factors
            peak = [0]
            def sample():
                while True:
                    for line in open("/proc/self/status"):
                        if line.startswith("RssAnon"):
                            peak[0] = max(peak[0], int(line.split()[1]))
                    time.sleep(0.2)
            threading.Thread(target=sample, daemon=True).start()
            x = np.load({path!r}, mmap_mode="r")
            start = time.perf_counter()
            allan_variance_columns(x, averaging_factors(x.shape[0]), "mo")
            print(time.perf_counter() - start, peak[0])
            """
        )
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
        print(f"\nN=1e9 float32 memmap octave mo: {float(out[0]):.1f} s, max sampled RssAnon {int(out[1]) / 1024:.0f} MB")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--huge", action="store_true", help="also a 1e9-sample float32 memmap run")
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--allantools-max", type=float, default=1e7, help="largest N timed with allantools")
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    print("| case | kernel ms | avar.avar ms | allantools ms | ratio | numpy cumsum ms | ratio | numpy.sum ms | limit |")
    print("|---|---|---|---|---|---|---|---|---|")
    for exponent in range(3, 9):
        n = 10**exponent
        x = rng.standard_normal(n)
        factors = averaging_factors(n)
        repeat = args.repeat if n < 10**8 else 1
        small_repeat = max(repeat, 200 if n <= 10**4 else repeat)
        sum_time = median_time(lambda: x.sum(), small_repeat)
        for type in ("mo", "to"):
            ours = median_time(lambda: allan_variance_columns(x, factors, type), small_repeat)
            public = median_time(lambda: avar.avar(x, type=type), small_repeat)
            peer_repeat = 1 if n >= 10**7 else repeat
            at = None
            if allantools is not None and n <= args.allantools_max:
                at = median_time(allantools_call(x, factors.astype(float), type), peer_repeat)
            npy = median_time(lambda: numpy_cumsum_avar(x, factors, type), peer_repeat)
            print(
                f"| N=1e{exponent} octave {type} | {fmt(ours)} | {fmt(public)} | {fmt(at)} | {ratio(at, ours)} "
                f"| {fmt(npy)} | {ratio(npy, ours)} | {fmt(sum_time)} | {sum_time / ours:.3f} |",
                flush=True,
            )
    print()
    for dtype in ("float64", "float32"):
        elapsed, peak, size = peak_memory(10**8, dtype)
        print(f"N=1e8 {dtype} octave mo (kernel, fresh process): {elapsed:.2f} s, VmHWM {peak:.2f} GB, "
              f"input {size:.2f} GB, extra {1024 * (peak - size):.0f} MB", flush=True)
    if args.huge:
        huge_memmap_run(10**9)


if __name__ == "__main__":
    threading.current_thread().name = "bench"
    main()
