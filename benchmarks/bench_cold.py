"""First-call times: ``import avar`` plus one call, in fresh processes with an empty numba cache.

Usage::

    nice python benchmarks/bench_cold.py [--n 10000] [--only oadev mdev] [--warm]
    nice python benchmarks/bench_cold.py --n 100000

Each public statistic (``avar.avar``, every deviation of the catalogue and the pair ones,
the dynamic deviations, ``robust_avar``, ``psd``, ``phase_noise``, ``avlr``, ``gmwm``,
``noise_report``) and each subcommand (``avar deviation``, ``avar compute``, ``avar
report``) runs once on ``--n`` samples of white noise (1e4 by default; the issue asks for
records up to ~1e5) in a new interpreter whose ``NUMBA_CACHE_DIR`` is a new,
empty folder: what a new user, a CI job or a container waits for the first time. Beside
them, in the same run, allantools' fresh process (import plus ``oadev`` of the same data),
the peer a user compares with. ``--warm`` adds a second column: the same call with the
cache the cold run filled. The code of this checkout runs (``src`` first on ``PYTHONPATH``).

Goals (issue 39, on a quiet machine): each statistic's cold total under 2.5 s, ``avar
deviation`` on a 1e4-point file under 3 s.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"

#: Public statistics timed, by the call their child process makes on ``x`` (and ``y``, a second
#: series for the pair statistics): ``--n`` samples of white noise each.
CALLS = {
    "avar": "avar.avar(x, rate=100.0)",
    "adev": "avar.adev(x)", "oadev": "avar.oadev(x)", "mdev": "avar.mdev(x)", "tdev": "avar.tdev(x)",
    "hdev": "avar.hdev(x)", "ohdev": "avar.ohdev(x)", "totdev": "avar.totdev(x)",
    "mtotdev": "avar.mtotdev(x)", "ttotdev": "avar.ttotdev(x)", "htotdev": "avar.htotdev(x)",
    "mhdev": "avar.mhdev(x)", "htdev": "avar.htdev(x)",
    "theo1": "avar.theo1(x)", "theoh": "avar.theoh(x)", "mhtotdev": "avar.mhtotdev(x)",
    "mtie": "avar.mtie(x)", "tierms": "avar.tierms(x)", "pdev": "avar.pdev(x)",
    "gcodev": "avar.gcodev(x, y)", "three_cornered_hat": "avar.three_cornered_hat(x, y, x - y)",
    "dadev": "avar.dadev(x)", "dhdev": "avar.dhdev(x)", "dynamic": "avar.dynamic('mdev', x)",
    "robust_avar": "avar.robust_avar(x, rate=100.0)",
    "psd": "avar.psd(x)", "phase_noise": "avar.phase_noise(x)",
    "avlr": "avar.avlr(x, wn='auto', rate=100.0)",
    "gmwm": "avar.gmwm(x, avar.WN(sigma2=1.0) + avar.RW(gamma2=1e-6))",
    "noise_report": "avar.noise_report(x, rate=100.0)",
}
CHILD = """
import time
start = time.perf_counter()
import numpy as np
import avar
x = np.random.default_rng(1).standard_normal({n})
y = np.random.default_rng(2).standard_normal({n})
imported = time.perf_counter()
{call}
print(imported - start, time.perf_counter() - imported)
"""
PEER = """
import time
start = time.perf_counter()
import numpy as np
import allantools
x = np.random.default_rng(1).standard_normal({n})
imported = time.perf_counter()
allantools.oadev(x, rate=1.0, data_type="freq", taus="octave")
print(imported - start, time.perf_counter() - imported)
"""


def _environment(cache: str) -> dict[str, str]:
    env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": f"{SRC}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}
    env.pop("AVAR_DATA_DIR", None)
    return env


def run_code(code: str, cache: str) -> tuple[float, float]:
    """(import s, first call s) of ``code`` in a fresh interpreter with ``cache`` as numba's cache."""
    out = subprocess.run([sys.executable, "-c", code], env=_environment(cache), capture_output=True, text=True,
                         check=True).stdout.split()
    return float(out[-2]), float(out[-1])


def run_command(arguments: list[str], cache: str) -> float:
    """Wall time (s) of ``python -m avar ARGUMENTS`` in a fresh interpreter."""
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "avar", *arguments], env=_environment(cache), capture_output=True,
                   check=True)
    return time.perf_counter() - start


def write_files(folder: Path, n: int) -> dict[str, Path]:
    """A one-column frequency record and a 2 h, 200 Hz six-axis log (``time gx .. az``)."""
    import numpy as np

    rng = np.random.default_rng(3)
    series = folder / "clock.txt"
    np.savetxt(series, rng.standard_normal(n) * 1e-12)
    rows = 2 * 3600 * 200
    log = folder / "imu.csv"
    t = np.arange(rows) / 200.0
    gyro = rng.standard_normal((rows, 3)) * 1e-3  # rad/s
    accel = rng.standard_normal((rows, 3)) * 1e-2 + [0.0, 0.0, 9.81]  # m/s^2
    data = np.column_stack([gyro, accel])
    # the stamps with every digit they need (%.6g would round 1000.005 s to 1000 s: duplicate times)
    np.savetxt(log, np.column_stack([t, data]), delimiter=",", header="time,gx,gy,gz,ax,ay,az", comments="",
               fmt=["%.3f"] + ["%.6g"] * 6)
    return {"series": series, "log": log}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=10_000, help="samples of each statistic's record (default 1e4)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="time only these statistics or commands")
    parser.add_argument("--warm", action="store_true", help="also time the call again with the filled cache")
    args = parser.parse_args()
    wanted = set(args.only) if args.only else None
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        files = write_files(folder, args.n)
        try:
            importing, call = run_code(PEER.format(n=args.n), str(folder / "peer"))
            rows.append(("allantools oadev (peer)", importing, call, float("nan")))
        except (subprocess.CalledProcessError, FileNotFoundError):
            print("allantools is not installed: pip install allantools (the peer's row is left out)")
        for name, call_code in CALLS.items():
            if wanted and name not in wanted:
                continue
            cache = str(folder / f"cache-{name}")
            importing, call = run_code(CHILD.format(n=args.n, call=call_code), cache)
            warm = sum(run_code(CHILD.format(n=args.n, call=call_code), cache)) if args.warm else float("nan")
            rows.append((name, importing, call, warm))
            print(f"  {name}: {importing + call:.2f} s", file=sys.stderr)
        commands = {
            "avar deviation (1e4-point file)": ["deviation", str(files["series"]), "--stat", "oadev", "--data-type", "freq"],
            "avar compute (2 h 6-axis log)": ["compute", str(files["log"])],
            "avar report (2 h 6-axis log)": ["report", str(files["log"])],
        }
        for label, arguments in commands.items():
            if wanted and arguments[0] not in wanted:
                continue
            cache = str(folder / f"cache-{arguments[0]}")
            cold = run_command(arguments, cache)
            warm = run_command(arguments, cache) if args.warm else float("nan")
            rows.append((label, float("nan"), cold, warm))
            print(f"  {label}: {cold:.2f} s", file=sys.stderr)
    print(f"\nFirst call in a fresh process, empty numba cache, N = {args.n:g} (s):\n")
    print("| statistic or command | import | first call | total | warm total |")
    print("|---|---|---|---|---|")
    for name, importing, call, warm in rows:
        total = call if importing != importing else importing + call
        cells = ["" if v != v else f"{v:.2f}" for v in (importing, call, total, warm)]
        print(f"| {name} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
