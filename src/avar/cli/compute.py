"""``avar compute``: the Allan variance of the columns of a file (or of several: :mod:`avar.cli.compute_many`).

``summary_of``, ``figure_of``, ``ReadOptions``, ``load`` and ``allan_of`` live in
:mod:`avar.cli.compute_many` (the one path of reading and computing, for one file or
many, on a worker of a cluster or here) and are re-exported here.
"""

from __future__ import annotations

import argparse
import sys
import threading
from contextlib import contextmanager

from avar.cli.common import (
    Progress,
    add_rate_arguments,
    add_unit_arguments,
    format_table,
    printable,
    unit_label,
)
from avar.cli.compute_many import (
    ReadOptions,
    add_cluster_arguments,
    allan_of,
    check_bag_units,
    figure_of,
    load,
    run_many,
    series_unit,
    summary_of,
)
from avar.cli.outputs import csv_text, plan_outputs, report
from avar.io.streams import PROGRESS_VALUES

__all__ = ["ReadOptions", "add_input_arguments", "add_parser", "allan_of", "compute_from_args", "figure_of", "load",
           "read_from_args", "run", "summary_of"]


def read_from_args(args: argparse.Namespace):
    """The file named in ``args`` as a Recording or an IMU (``--gyro``/``--accel``, or a bag)."""
    loaded = load(args.file, ReadOptions.from_args(args))
    for note in loaded.notes:
        print(printable(note), file=sys.stderr)
    return loaded.data


#: The warm-up's thread: its compilations are speculative, the first-run notice ignores them.
WARM_UP_THREAD = "avar-warm-up"


def _warm_up() -> None:
    """Import the kernels and load their compiled code (numba's cache) on a tiny series.

    On a cold cache the tiny series would compile the short-series kernels, which a long
    file does not use, and hold numba's compiler lock meanwhile: then only the import
    is done here, and the file's own call compiles what it needs.
    """
    import numpy as np

    from avar._kernels.allan.small import small_allan_variance
    from avar._kernels.runtime.cache import cached_for_this_machine
    from avar.stability.allan.estimator import avar

    if cached_for_this_machine(small_allan_variance):
        x = np.arange(8.0)
        x.setflags(write=False)  # read-only, as a file's columns are: the same compiled signature
        avar(x)


def compute_from_args(args: argparse.Namespace, progress: Progress):
    """Read the file named in ``args`` and compute its Allan variance(s).

    The kernels load in a background thread while the file is parsed (pandas' C parser
    releases the GIL), so their start-up time overlaps the reading.
    """
    warm_up = threading.Thread(target=_warm_up, name=WARM_UP_THREAD, daemon=True)
    warm_up.start()
    progress(f"reading {args.file}")
    try:
        data = read_from_args(args)
    finally:
        warm_up.join()
    from avar.imu import IMU

    progress("computing")
    values = data.data.size if isinstance(data, IMU) else len(data.columns) * data.n
    show = values > PROGRESS_VALUES and sys.stderr.isatty()
    if isinstance(data, IMU):  # one pass of the kernels over every channel: a clock, not a count
        with _elapsed(f"computing {len(data.channels)} channels", show):
            return allan_of(data, args.type, args.taus)
    names = list(data.columns)
    if show:
        from tqdm import tqdm

        names = tqdm(names, desc="computing", unit="column", file=sys.stderr, leave=False)
    return allan_of(data, args.type, args.taus, names, nan_policy=getattr(args, "nan_policy", "raise"))


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


def run(args: argparse.Namespace) -> int:
    if len(args.file) > 1 or args.workers is not None or args.scheduler is not None:
        return run_many(args)
    args = argparse.Namespace(**{**vars(args), "file": args.file[0]})
    check_bag_units([args.file], args)
    unit = series_unit(args, bool(args.gyro or args.accel))
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=[args.file], force=args.force)
    progress = Progress()
    results = compute_from_args(args, progress)
    summary = summary_of(results)
    ylab = None if unit is None else unit_label(unit, deviation=False)
    written = plan.write(csv=lambda: csv_text(summary), figure=lambda: figure_of(results, ylab))
    progress("done")
    report(written, format_table(summary))
    return 0


#: What every subcommand reads.
FILE_HELP = "CSV/TSV/text, .npy/.npz, Parquet, .mat, or a ROS bag (.bag, .db3, .mcap; needs allanvar[ros]); see docs/reading.md"
#: One help text per shared option, so that an option says the same in every subcommand.
TIME_UNIT_HELP = "unit of a numeric time column: s, ms, us or ns (default: from its name, e.g. t_ns, 'time [ms]'; else s)"
GAPS_HELP = "time steps > 1.5 median steps: refuse (error, the default) or treat the samples as contiguous (ignore)"
TAUS_HELP = "grid of averaging times tau (s): octave (m = 2, 4, 8, ...; the default), decade or all"
OUTPUT_HELP = "write the table to this CSV file ('-': stdout; default: none, the table is printed)"
PLOT_HELP = "write the figure to this file, format from its extension: png, pdf, svg, ... (default: none)"
FORCE_HELP = "replace existing output files (default: refuse)"


def add_reading_arguments(parser: argparse.ArgumentParser, rate_default: str = "from a time column, else 1 Hz") -> None:
    """How a file is read: its rate, its time column and its gaps (every subcommand that reads a file)."""
    add_rate_arguments(parser, rate_default)
    parser.add_argument("--time-unit", choices=["s", "ms", "us", "ns"], default=None, help=TIME_UNIT_HELP)
    parser.add_argument("--gaps", choices=["error", "ignore"], default="error", help=GAPS_HELP)


def add_nan_policy_argument(parser: argparse.ArgumentParser, what: str) -> None:
    """``--nan-policy raise|omit``: NaN and empty cells refused, or read as gaps the statistics skip."""
    parser.add_argument("--nan-policy", choices=["raise", "omit"], default="raise",
                        help=f"NaN values and empty cells (gaps) in the data: refuse (raise, the default), or read "
                             f"them as gaps and skip the {what} that touch them (omit)")


def add_output_arguments(parser: argparse.ArgumentParser, table: str = OUTPUT_HELP) -> None:
    parser.add_argument("--output", metavar="CSV", help=table)
    parser.add_argument("--plot", metavar="PNG", help=PLOT_HELP)
    parser.add_argument("--force", action="store_true", help=FORCE_HELP)


def add_input_arguments(parser: argparse.ArgumentParser, many: bool = False) -> None:
    """The reading and output options; ``many``: one or more files (``avar compute``)."""
    if many:
        parser.add_argument("file", nargs="+",
                            help=f"{FILE_HELP}; several files give one table with a File column")
    else:
        parser.add_argument("file", help=FILE_HELP)
    parser.add_argument(
        "--column", action="append", metavar="NAME", help="column to use (repeatable; default: all but time columns)"
    )
    add_reading_arguments(parser)
    parser.add_argument("--topic", metavar="TOPIC",
                        help="sensor_msgs/Imu topic of a ROS bag (default: the bag's only Imu topic)")
    parser.add_argument("--type", choices=["mo", "to"], default="mo",
                        help="estimator: maximal overlap (mo, the default) or tau overlap (to)")
    parser.add_argument("--taus", choices=["octave", "decade", "all"], default="octave", help=TAUS_HELP)
    parser.add_argument("--gyro", action="extend", nargs="+", metavar="NAME",
                        help="gyroscope columns, e.g. --gyro gx gy gz (makes an IMU; default: none)")
    parser.add_argument("--accel", action="extend", nargs="+", metavar="NAME",
                        help="accelerometer columns, e.g. --accel ax ay az (makes an IMU; default: none)")
    add_unit_arguments(parser, "or a ROS bag's SI unit; for separate series give one, which labels the figure")
    add_output_arguments(parser)


def add_parser(commands) -> None:
    compute = commands.add_parser(
        "compute", help="Allan variance of the columns of one or more files",
        description="The Allan variance of every column of one or more files (or of an IMU's channels): the table "
                    "Scale, Time (s), AVar, ADev, Lower CI, Upper CI; a figure; many files at once, optionally on "
                    "a dask cluster.")
    add_input_arguments(compute, many=True)
    add_nan_policy_argument(compute, "differences of cluster means")
    add_cluster_arguments(compute)
    compute.set_defaults(handler=run)
