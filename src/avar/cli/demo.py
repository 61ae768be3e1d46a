"""``avar demo``: simulate a sensor, compute and fit its Allan variance, plot it."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from avar.cli.common import UsageError, format_table
from avar.cli.outputs import plan_outputs, report

DEMO_FREQ = 100.0
DEMO_N = 100_000
DEMO_SCALES = {"wn": range(1, 8), "rw": range(12, 16)}


def simulate_demo_series(n: int = DEMO_N, seed: int = 2024) -> np.ndarray:
    """White noise (sigma2 = 1) plus a random walk (gamma2 = 1e-6), per sample."""
    from avar.models import RW, WN

    return (WN(sigma2=1.0) + RW(gamma2=1e-6)).simulate(n, seed=seed)


def run(args: argparse.Namespace) -> int:
    from avar.fit.avlr import avlr
    from avar.stability.allan import avar

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {args.out!r} is a file; give a directory for avar_demo.png")
    out.mkdir(parents=True, exist_ok=True)
    plan = plan_outputs(figure=str(out / "avar_demo.png"), force=args.force, figure_option="--out")
    x = simulate_demo_series()
    result = avar(x, freq=DEMO_FREQ)
    fit = avlr(result, **DEMO_SCALES)
    written = plan.write(figure=lambda: fit.plot(decomp=True))
    report(written, "\n".join([
        f"Simulated {DEMO_N} samples of white noise + random walk at {DEMO_FREQ:g} Hz",
        result.describe(),
        format_table(result.summary().reset_index()),  # with the Scale numbers the fit uses
        "",
        str(fit),
        "",
    ]))
    return 0



def add_parser(commands) -> None:
    demo = commands.add_parser("demo", help="simulate a sensor, compute and fit its Allan variance, plot it")
    demo.add_argument("--out", default=".", metavar="DIR", help="directory for avar_demo.png (default: .)")
    demo.add_argument("--force", action="store_true", help="replace an existing avar_demo.png")
    demo.set_defaults(handler=run)
