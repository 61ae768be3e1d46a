"""The ``avar`` command line."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from avar.estimate import avar

DEMO_FREQ = 100.0
DEMO_N = 100_000


def simulate_demo_series(n: int = DEMO_N, seed: int = 2024) -> np.ndarray:
    """White noise (sigma2 = 1) plus a random walk (gamma2 = 1e-6), per sample."""
    rng = np.random.default_rng(seed)
    return rng.standard_normal(n) + np.cumsum(rng.normal(0.0, 1e-3, n))


def run_demo(args: argparse.Namespace) -> int:
    x = simulate_demo_series()
    result = avar(x, freq=DEMO_FREQ)
    print(f"Simulated {DEMO_N} samples of white noise + random walk at {DEMO_FREQ:g} Hz")
    print(result.describe())
    print(result.summary().to_string(index=False, float_format=lambda v: f"{v:.6g}"))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="avar", description="Allan variance and AVLR noise model estimation")
    commands = parser.add_subparsers(dest="command", required=True)
    demo = commands.add_parser("demo", help="simulate a sensor, compute its Allan variance and print it")
    demo.set_defaults(handler=run_demo)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.handler(args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
