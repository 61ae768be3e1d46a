"""The ``avar`` command line.

Subcommands: ``demo``, ``compute``, ``fit``, ``datasets``. Problems with the
user's files end with a one-line message on stderr and exit code 1; usage
errors with exit code 2. Nothing here computes: it reads, calls the library
and writes.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from avar.estimate import avar
from avar.files import TIME_UNITS, InputFileError, read_series

DEMO_FREQ = 100.0
DEMO_N = 100_000
DEMO_SCALES = {"wn": range(1, 8), "rw": range(12, 16)}
FLOAT_FORMAT = "{:.6g}".format


class Progress:
    """Stage messages on stderr, only when it is a terminal."""

    def __init__(self, enabled: bool | None = None) -> None:
        self.enabled = sys.stderr.isatty() if enabled is None else enabled
        self.started = time.perf_counter()

    def __call__(self, message: str) -> None:
        if self.enabled:
            print(f"[{time.perf_counter() - self.started:6.1f} s] {message}", file=sys.stderr, flush=True)


def parse_scales(text: str) -> list[int]:
    """``"1:7"`` -> 1..7 (inclusive, as in R), ``"1,3,5"``, ``"4"``.

    >>> parse_scales("2:4"), parse_scales("1,3"), parse_scales("6")
    ([2, 3, 4], [1, 3], [6])
    """
    scales: list[int] = []
    for part in text.split(","):
        part = part.strip()
        try:
            if ":" in part:
                low, high = (int(v) for v in part.split(":"))
                if low > high:
                    raise argparse.ArgumentTypeError(f"invalid scale range {part!r}: {low} > {high}")
                scales.extend(range(low, high + 1))
            else:
                scales.append(int(part))
        except ValueError:
            raise argparse.ArgumentTypeError(f"invalid scale selection {text!r}; use e.g. 1:7, 3 or 1,2,5") from None
    return scales


def simulate_demo_series(n: int = DEMO_N, seed: int = 2024) -> np.ndarray:
    """White noise (sigma2 = 1) plus a random walk (gamma2 = 1e-6), per sample."""
    from avar.models import RW, WN

    return (WN(sigma2=1.0) + RW(gamma2=1e-6)).simulate(n, seed=seed)


def format_table(frame: pd.DataFrame, index: bool = False) -> str:
    return frame.to_string(index=index, float_format=FLOAT_FORMAT)


def run_demo(args: argparse.Namespace) -> int:
    from avar.avlr import avlr

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    x = simulate_demo_series()
    result = avar(x, freq=DEMO_FREQ)
    fit = avlr(result, **DEMO_SCALES)
    print(f"Simulated {DEMO_N} samples of white noise + random walk at {DEMO_FREQ:g} Hz")
    print(result.describe())
    print(format_table(result.summary().reset_index()))  # with the Scale numbers the fit uses
    print()
    print(fit)
    figure_path = out / "avar_demo.png"
    fit.plot(decomp=True).savefig(figure_path, dpi=110)
    print(f"\nWrote {figure_path}")
    return 0


def compute_from_args(args: argparse.Namespace, progress: Progress):
    """Read the file named in ``args`` and compute its Allan variance(s)."""
    from avar.imu import IMU

    progress(f"reading {args.file}")
    columns = args.column or ((args.gyro or []) + (args.accel or [])) or None
    table = read_series(args.file, columns, rate_from_time=args.freq is None, time_unit=args.time_unit)
    if args.freq is not None:
        freq, source = args.freq, "--freq"
    elif table.freq is not None:
        freq, source = table.freq, f"time column {table.time_column!r}"
    else:
        freq, source = 1.0, "no time column: pass --freq for seconds"
    print(
        f"{args.file}: {len(table.columns.columns)} column(s) x {len(table.columns)} samples at {freq:g} Hz ({source})",
        file=sys.stderr,
    )
    progress("computing")
    if args.gyro or args.accel:
        imu = IMU(table.columns, freq=freq, gyro=args.gyro, accel=args.accel, name=Path(args.file).stem)
        return avar(imu, type=args.type, taus=args.taus)
    results = {
        name: avar(table.columns[name].to_numpy(), type=args.type, freq=freq, taus=args.taus)
        for name in table.columns
    }
    return results


def summary_of(results) -> pd.DataFrame:
    """One flat summary table: a Scale column (1-based), and Channel when there are several."""
    if isinstance(results, dict):
        if len(results) == 1:
            return next(iter(results.values())).summary().reset_index()
        frames = {name: res.summary() for name, res in results.items()}
        return pd.concat(frames, names=["Channel", "Scale"]).reset_index()
    return results.summary().reset_index()


def figure_of(results):
    from avar.plotting import plot_compare

    if isinstance(results, dict):
        if len(results) == 1:
            return next(iter(results.values())).plot()
        return plot_compare(list(results.values()), labels=list(results))
    return results.plot()


def run_compute(args: argparse.Namespace) -> int:
    progress = Progress()
    results = compute_from_args(args, progress)
    summary = summary_of(results)
    print(format_table(summary))
    if args.output:
        summary.to_csv(args.output, index=False)
        print(f"Wrote {args.output}")
    if args.plot:
        figure_of(results).savefig(args.plot, dpi=110)
        print(f"Wrote {args.plot}")
    progress("done")
    return 0


PROCESSES = (("qn", "quantization noise"), ("wn", "white noise"), ("rw", "random walk"), ("dr", "drift"))
SENSOR_SUFFIXES = {"Gyroscope": "gyro", "Accelerometer": "acc"}


def imu_selections(args: argparse.Namespace, present_types) -> dict[str, list[int]]:
    """``--wn`` applies to every sensor type present; ``--wn-gyro``/``--wn-acc`` override it."""
    selections = {}
    for process, _ in PROCESSES:
        for sensor_type in present_types:
            suffix = SENSOR_SUFFIXES[sensor_type]
            value = getattr(args, f"{process}_{suffix}") or getattr(args, process)
            if value:
                selections[f"{process}_{suffix}"] = value
    return selections


def run_fit(args: argparse.Namespace) -> int:
    from avar.avlr import avlr

    imu = bool(args.gyro or args.accel)
    per_sensor = [f"--{name}-{suffix}" for name, _ in PROCESSES for suffix in ("gyro", "acc")
                  if getattr(args, f"{name}_{suffix}")]
    if imu and args.ci:
        raise UsageError("--ci (bootstrap intervals) is available for one series, not for IMU fits")
    if per_sensor and not imu:
        raise UsageError(f"{', '.join(per_sensor)} apply to IMU fits only (name the columns with --gyro/--accel)")
    progress = Progress()
    results = compute_from_args(args, progress)
    progress("fitting")
    if isinstance(results, dict):
        if len(results) != 1:
            raise InputFileError(
                f"fit takes one column (--column NAME) or an IMU (--gyro/--accel); the file has {list(results)}"
            )
        selections = {name: getattr(args, name) for name, _ in PROCESSES if getattr(args, name)}
        fit = avlr(next(iter(results.values())), ci=args.ci, B=args.B, alpha=args.alpha, seed=args.seed, **selections)
        figure = (lambda: fit.plot(decomp=True)) if args.plot else None
    else:
        fit = avlr(results, **imu_selections(args, results.present_types))
        figure = fit.plot if args.plot else None
    print(fit)
    if args.output:
        fit.summary().to_csv(args.output)
        print(f"Wrote {args.output}")
    if figure is not None:
        figure().savefig(args.plot, dpi=110)
        print(f"Wrote {args.plot}")
    progress("done")
    return 0


def run_datasets(args: argparse.Namespace) -> int:
    from avar import datasets

    if args.name is None:
        print(format_table(datasets.list()))
        return 0
    try:
        data = datasets.load(args.name)
    except KeyError as error:
        raise InputFileError(str(error.args[0]) if error.args else str(error)) from error
    print(data)
    print()
    print(format_table(data.summary(), index=True))
    if args.plot:
        data.plot().savefig(args.plot, dpi=110)
        print(f"Wrote {args.plot}")
    return 0


class UsageError(Exception):
    """Options that do not go together (exit code 2, like argparse's own errors)."""


class Parser(argparse.ArgumentParser):
    """argparse with one-line usage errors (exit code 2)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def add_input_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="CSV, whitespace-separated text or .npy file")
    parser.add_argument("--column", action="append", metavar="NAME", help="column to use (repeatable; default: all)")
    parser.add_argument("--freq", type=float, help="sampling rate in Hz (default: from a time column, else 1)")
    parser.add_argument(
        "--time-unit", choices=sorted(TIME_UNITS), default="s", help="unit of a numeric time column (default s)"
    )
    parser.add_argument("--type", choices=["mo", "to"], default="mo", help="maximal overlap (mo) or tau overlap (to)")
    parser.add_argument("--taus", choices=["octave", "decade", "all"], default="octave", help="tau grid")
    parser.add_argument("--gyro", action="append", metavar="NAME", help="gyroscope column (makes an IMU)")
    parser.add_argument("--accel", action="append", metavar="NAME", help="accelerometer column (makes an IMU)")
    parser.add_argument("--output", metavar="CSV", help="write the table to this CSV file")
    parser.add_argument("--plot", metavar="PNG", help="write the figure to this file")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="avar", description="Allan variance and AVLR noise model estimation")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    demo = commands.add_parser("demo", help="simulate a sensor, compute and fit its Allan variance, plot it")
    demo.add_argument("--out", default=".", metavar="DIR", help="directory for avar_demo.png (default: .)")
    demo.set_defaults(handler=run_demo)
    compute = commands.add_parser("compute", help="Allan variance of the columns of a file")
    add_input_arguments(compute)
    compute.set_defaults(handler=run_compute)
    fit = commands.add_parser("fit", help="Allan variance linear regression (AVLR) of a file")
    add_input_arguments(fit)
    for name, label in PROCESSES:
        fit.add_argument(f"--{name}", type=parse_scales, metavar="SCALES", help=f"scales of the {label}, e.g. 1:7")
        for suffix, sensor in (("gyro", "gyroscopes"), ("acc", "accelerometers")):
            fit.add_argument(
                f"--{name}-{suffix}", type=parse_scales, metavar="SCALES", help=f"scales of the {label} of the {sensor}"
            )
    fit.add_argument("--ci", action="store_true", help="parametric bootstrap confidence intervals")
    fit.add_argument("--B", type=int, default=100, help="bootstrap replicates (default 100)")
    fit.add_argument("--alpha", type=float, default=0.05, help="1 - confidence level (default 0.05)")
    fit.add_argument("--seed", type=int, default=None, help="seed of the bootstrap")
    fit.set_defaults(handler=run_fit)
    data = commands.add_parser("datasets", help="list the IMU data sets, or summarize / plot one")
    data.add_argument("name", nargs="?", help="data set name, e.g. navchip_av")
    data.add_argument("--plot", metavar="PNG", help="write the figure to this file")
    data.set_defaults(handler=run_datasets)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    if args.command in ("compute", "fit") and args.freq is not None and not args.freq > 0:
        print(f"avar: error: --freq must be > 0, got {args.freq}", file=sys.stderr)
        return 2
    try:
        return args.handler(args)
    except BrokenPipeError:  # output piped into e.g. head, which closed it (an OSError: first)
        sys.stderr.close()
        return 0
    except UsageError as error:
        print(f"avar {args.command}: error: {error}", file=sys.stderr)
        return 2
    except (InputFileError, ValueError, TypeError, OSError) as error:
        print(f"avar: error: {error}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
