"""``avar compute``: the Allan variance of the columns of a file."""

from __future__ import annotations

import argparse
import sys
import threading
from contextlib import contextmanager
from pathlib import Path

import pandas as pd

from avar.cli.common import Progress, UsageError, format_table
from avar.cli.outputs import plan_outputs, report
from avar.io.progress import PROGRESS_VALUES


def read_from_args(args: argparse.Namespace):
    """The file named in ``args`` as a Recording or an IMU (``--gyro``/``--accel``, or a bag)."""
    from avar.io.read import read

    if args.column and (args.gyro or args.accel):
        raise UsageError(
            "--column cannot be combined with --gyro/--accel: --gyro and --accel name the IMU's columns "
            "(use them alone, or --column alone for separate series)"
        )
    imu_columns = (args.gyro or []) + (args.accel or [])
    data = read(
        args.file,
        columns=args.column or imu_columns or None,
        freq=args.freq,
        time_unit=args.time_unit,
        gaps=args.gaps,
        topic=args.topic,
    )
    from avar.imu import IMU

    if isinstance(data, IMU):  # a bag
        print(f"{args.file}: {data.describe()}", file=sys.stderr)
        return data
    note = data.describe().replace("(given)", "(--freq)")
    if data.time_column is None and args.freq is None:
        note += "; pass --freq for seconds"
    print(note, file=sys.stderr)
    if data.gaps_ignored:
        print(f"{args.file}: --gaps ignore: the samples are treated as contiguous across the gaps", file=sys.stderr)
    if imu_columns:
        frame = pd.DataFrame(dict(data.columns), copy=False)
        return IMU(frame, data.freq, gyro=args.gyro, accel=args.accel, name=Path(args.file).stem)
    return data


def _warm_up() -> None:
    """Import the kernels and load their compiled code (numba's cache) on a tiny series."""
    import numpy as np

    from avar.stability.allan import avar

    avar(np.arange(8.0))


def compute_from_args(args: argparse.Namespace, progress: Progress):
    """Read the file named in ``args`` and compute its Allan variance(s).

    The kernels load in a background thread while the file is parsed (pandas' C parser
    releases the GIL), so their start-up time overlaps the reading.
    """
    warm_up = threading.Thread(target=_warm_up, name="avar-warm-up", daemon=True)
    warm_up.start()
    progress(f"reading {args.file}")
    try:
        data = read_from_args(args)
    finally:
        warm_up.join()
    from avar.imu import IMU
    from avar.stability.allan import avar

    progress("computing")
    values = data.data.size if isinstance(data, IMU) else len(data.columns) * data.n
    show = values > PROGRESS_VALUES and sys.stderr.isatty()
    if isinstance(data, IMU):  # one pass of the kernels over every channel: a clock, not a count
        with _elapsed(f"computing {len(data.channels)} channels", show):
            return avar(data, type=args.type, taus=args.taus)
    names = list(data.columns)
    if show:
        from tqdm import tqdm

        names = tqdm(names, desc="computing", unit="column", file=sys.stderr, leave=False)
    return {name: avar(data.columns[name], type=args.type, freq=data.freq, taus=args.taus) for name in names}


@contextmanager
def _elapsed(description: str, enabled: bool):
    """A tqdm line on stderr that shows the time spent while the block runs (when enabled)."""
    if not enabled:
        yield
        return
    from tqdm import tqdm

    bar = tqdm(desc=description, bar_format="{desc}: {elapsed}", file=sys.stderr, leave=False)
    stop = threading.Event()

    def tick() -> None:
        while not stop.wait(0.5):
            bar.refresh()

    ticker = threading.Thread(target=tick, daemon=True)
    ticker.start()
    try:
        yield
    finally:
        stop.set()
        ticker.join()
        bar.close()


def summary_of(results) -> pd.DataFrame:
    """One flat summary table: a Scale column (1-based), and Channel when there are several."""
    if isinstance(results, dict):
        if len(results) == 1:
            return next(iter(results.values())).summary().reset_index()
        frames = {name: res.summary() for name, res in results.items()}
        return pd.concat(frames, names=["Channel", "Scale"]).reset_index()
    return results.summary().reset_index()


def figure_of(results):
    from avar.plotting.compare import plot_compare

    if isinstance(results, dict):
        if len(results) == 1:
            return next(iter(results.values())).plot()
        return plot_compare(list(results.values()), labels=list(results))
    return results.plot()


def run(args: argparse.Namespace) -> int:
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=[args.file], force=args.force)
    progress = Progress()
    results = compute_from_args(args, progress)
    summary = summary_of(results)
    written = plan.write(csv=lambda: summary.to_csv(index=False), figure=lambda: figure_of(results))
    progress("done")
    report(written, format_table(summary))
    return 0


def add_input_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "file", help="CSV/TSV/text, .npy, or a ROS bag (.bag, .db3, .mcap; needs avar[ros]); see docs/reading.md"
    )
    parser.add_argument(
        "--column", action="append", metavar="NAME", help="column to use (repeatable; default: all but time columns)"
    )
    parser.add_argument("--freq", type=float, help="sampling rate in Hz (default: from a time column, else 1)")
    parser.add_argument(
        "--time-unit",
        choices=["s", "ms", "us", "ns"],
        default=None,
        help="unit of a numeric time column (default: from its name, e.g. t_ns, 'time [ms]'; else s)",
    )
    parser.add_argument(
        "--gaps",
        choices=["error", "ignore"],
        default="error",
        help="time steps > 1.5 median steps: refuse (default) or treat the samples as contiguous",
    )
    parser.add_argument("--topic", metavar="TOPIC", help="sensor_msgs/Imu topic of a ROS bag (default: its only one)")
    parser.add_argument("--type", choices=["mo", "to"], default="mo", help="maximal overlap (mo) or tau overlap (to)")
    parser.add_argument("--taus", choices=["octave", "decade", "all"], default="octave", help="tau grid")
    parser.add_argument("--gyro", action="append", metavar="NAME", help="gyroscope column (makes an IMU)")
    parser.add_argument("--accel", action="append", metavar="NAME", help="accelerometer column (makes an IMU)")
    parser.add_argument("--output", metavar="CSV", help="write the table to this CSV file ('-': stdout)")
    parser.add_argument("--plot", metavar="PNG", help="write the figure to this file (format from its extension)")
    parser.add_argument("--force", action="store_true", help="replace existing --output / --plot files")



def add_parser(commands) -> None:
    compute = commands.add_parser("compute", help="Allan variance of the columns of a file")
    add_input_arguments(compute)
    compute.set_defaults(handler=run)
