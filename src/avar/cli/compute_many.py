"""``avar compute FILE... [--workers N | --scheduler ADDRESS]``: many files, serially or on a cluster.

This module also holds the one path of reading and computing a file that
``avar compute FILE`` (:mod:`avar.cli.compute`, which imports it) uses: :func:`load`
and :func:`allan_of`, with the tables and figures of a result. Every file is read
and computed by :func:`compute_file`, the same reader and the same estimator.
Without ``--workers``/``--scheduler`` the files run one after the other in this
process; with them, one task per file on a
``dask.distributed`` cluster (:func:`avar.stability.allan.dask.map_on_cluster`): a
``LocalCluster`` of N single-threaded worker processes, or the scheduler at ADDRESS.
A worker sends back only the small result of its file (per channel: taus, cluster
sizes, Allan variances, errors and terms per level, name), from which this process
rebuilds the very result objects the serial run builds, so the tables are equal.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import sys
from collections.abc import Iterable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, NamedTuple

import pandas as pd

from avar._escape import figure_text
from avar.cli.common import (
    InputFileError,
    Progress,
    UsageError,
    format_table,
    printable,
    unit_label,
    variables_note,
    whole_number,
)
from avar.cli.outputs import csv_text, plan_outputs, report

__all__ = ["SHOW_PROGRESS", "ReadOptions", "add_cluster_arguments", "allan_of", "capped_workers", "check_bag_units",
           "compute_file", "compute_files", "figure_of", "load", "run_many", "series_unit", "summary_of"]

#: The progress bar over the files: None shows it when stderr is a terminal; True/False force it.
SHOW_PROGRESS: bool | None = None
#: Seconds to wait for the scheduler named by ``--scheduler``.
CONNECT_TIMEOUT = 15.0
ADDRESS = re.compile(r"^(?:[a-z][a-z0-9+]*://)?(?:\[[0-9A-Fa-f:.]+\]|[^\s:/\[\]]+):\d{1,5}$")
#: Silences the resource tracker's "leaked semaphore" warning after an interrupted cluster run.
QUIET_TRACKER = "ignore:resource_tracker:UserWarning"
DASK_MISSING = '--workers/--scheduler run on dask.distributed, which is not installed: pip install "allanvar[dask]"'


#: ``--workers``: a whole number >= 1.
positive_int = whole_number(1, "worker processes")


def scheduler_address(text: str) -> str:
    """``--scheduler``: a dask.distributed scheduler address such as ``tcp://10.0.0.5:8786``."""
    if not ADDRESS.match(text.strip()):
        raise argparse.ArgumentTypeError(
            f"expected a dask.distributed scheduler address such as tcp://10.0.0.5:8786, got {text!r}")
    return text.strip()


def add_cluster_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--workers", type=positive_int, metavar="N", default=None,
                        help="compute the files in parallel on a local dask cluster of N worker processes "
                             "(needs allanvar[dask]; default: one file after the other, in this process)")
    parser.add_argument("--scheduler", type=scheduler_address, metavar="ADDRESS", default=None,
                        help="compute the files on the dask.distributed scheduler at ADDRESS, "
                             "e.g. tcp://10.0.0.5:8786 (needs allanvar[dask]; default: none)")


# ----------------------------------------------------------------------------- one file, anywhere
@dataclass(frozen=True)
class ReadOptions:
    """How to read a file and which Allan variance to compute: picklable, for the workers of a cluster."""

    column: tuple[str, ...] = ()
    rate: float | None = None
    time_unit: str | None = None
    gaps: str = "error"
    topic: str | None = None
    gyro: tuple[str, ...] = ()
    accel: tuple[str, ...] = ()
    type: str = "mo"
    taus: str = "octave"
    gyro_units: str | None = None
    accel_units: str | None = None
    #: How the rate was given on the command line (``--rate`` or its alias ``--freq``), for the notes.
    rate_option: str = "--rate"
    #: NaN and empty cells: refused ("raise") or kept as gaps the Allan variance skips ("omit").
    nan_policy: str = "raise"

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> ReadOptions:
        if args.column and (args.gyro or args.accel):
            raise UsageError(
                "--column cannot be combined with --gyro/--accel: --gyro and --accel name the IMU's columns "
                "(use them alone, or --column alone for separate series)"
            )
        return cls(tuple(args.column or ()), args.rate, args.time_unit, args.gaps, args.topic,
                   tuple(args.gyro or ()), tuple(args.accel or ()), args.type, args.taus,
                   getattr(args, "gyro_units", None), getattr(args, "accel_units", None),
                   getattr(args, "rate_option", "--rate"), getattr(args, "nan_policy", "raise"))

    @property
    def units(self) -> dict[str, str]:
        """The data units given, keyed as :class:`avar.IMU` takes them (``gyro``, ``accel``)."""
        return {key: unit for key, unit in (("gyro", self.gyro_units), ("accel", self.accel_units)) if unit}


class Loaded(NamedTuple):
    """A file read for ``avar compute`` (:func:`load`)."""

    #: A :class:`avar.Recording`, or an :class:`avar.IMU` (``--gyro``/``--accel``, or a bag).
    data: Any
    #: What the reader found (rate, units, gaps), one line each, for stderr.
    notes: list[str]


def load(path: str, options: ReadOptions, progress: bool | None = None) -> Loaded:
    """The :class:`Loaded` file: a Recording or an IMU (``--gyro``/``--accel``, or a bag), and the notes
    for stderr."""
    from avar.imu import IMU
    from avar.io.read import read

    imu_columns = list(options.gyro + options.accel)
    data = read(
        path,
        columns=list(options.column) or imu_columns or None,
        rate=options.rate,
        time_unit=options.time_unit,
        gaps=options.gaps,
        topic=options.topic,
        progress=progress,
        nan_policy=options.nan_policy,
    )
    if isinstance(data, IMU):  # a bag: SI units by definition (check_bag_units refuses others)
        return Loaded(data, [f"{path}: {data.describe()}"])
    note = data.describe().replace("(given)", f"({options.rate_option})")
    if data.time_column is None and options.rate is None:
        note += "; pass --rate for seconds"
    notes = [note, *filter(None, [variables_note(path, data)])]
    if data.gaps_ignored:
        notes.append(f"{path}: --gaps ignore: the samples are treated as contiguous across the gaps")
    if imu_columns:
        frame = pd.DataFrame(dict(data.columns), copy=False)
        imu = IMU(frame, data.rate, gyro=list(options.gyro) or None, accel=list(options.accel) or None,
                  name=Path(path).stem, units=options.units)
        return Loaded(imu, notes)
    return Loaded(data, notes)


#: The units of a ROS bag's sensor_msgs/Imu, by definition.
BAG_UNITS = (("--gyro-units", "gyro_units", "rad/s"), ("--accel-units", "accel_units", "m/s^2"))


def check_bag_units(paths: Iterable[str], args: argparse.Namespace) -> None:
    """A ROS bag holds SI units by definition: any other ``--gyro-units``/``--accel-units`` is a usage error."""
    from avar.io.read import BAG_SUFFIXES

    if not any(Path(p).suffix.lower() in BAG_SUFFIXES or Path(p).is_dir() for p in paths):
        return
    for option, dest, si in BAG_UNITS:
        value = getattr(args, dest, None)
        if value is not None and value != si:
            raise UsageError(f"{option} {value}: ROS bags hold sensor_msgs/Imu in SI units ({si}) by definition; "
                             f"drop {option}")


def series_unit(args: argparse.Namespace, imu: bool) -> str | None:
    """The unit of separate series (not an IMU): the one of ``--gyro-units``/``--accel-units`` given, which
    labels the figure; both for one kind of series is a usage error."""
    gyro, accel = getattr(args, "gyro_units", None), getattr(args, "accel_units", None)
    if imu:
        return None
    if gyro is not None and accel is not None:
        raise UsageError("separate series are one kind of sensor: give --gyro-units or --accel-units, not both "
                         "(name an IMU's columns with --gyro/--accel to give both)")
    return gyro or accel


def allan_of(data: Any, type: str, taus: str, names: Iterable[str] | None = None, nan_policy: str = "raise"):
    """The Allan variance of an IMU, or of every column of a Recording (a dict by column name; with
    ``nan_policy="omit"`` the differences that touch a NaN are skipped)."""
    from avar.imu import IMU
    from avar.stability.allan.estimator import avar

    if isinstance(data, IMU):
        return avar(data, type=type, taus=taus)
    names = data.columns if names is None else names
    return {name: avar(data.columns[name], type, data.rate, taus=taus, nan_policy=nan_policy) for name in names}


def summary_of(results) -> pd.DataFrame:
    """One flat summary table: a Scale column (1-based), and Channel when there are several."""
    if isinstance(results, dict):
        if len(results) == 1:
            return next(iter(results.values())).summary().reset_index()
        frames = {name: res.summary() for name, res in results.items()}
        return pd.concat(frames, names=["Channel", "Scale"]).reset_index()
    return results.summary().reset_index()


def figure_of(results, ylab: str | None = None):
    """The figure of a result; ``ylab`` labels the y axis of separate series (their unit)."""
    from avar.plotting.compare import plot_compare

    if isinstance(results, dict):
        if len(results) == 1:
            return next(iter(results.values())).plot(ylab=ylab)
        return plot_compare(list(results.values()), labels=[figure_text(name) for name in results], ylab=ylab)
    return results.plot()


# ----------------------------------------------------------------------------- on a worker
def _pack_series(av: Any) -> dict[str, Any]:
    return {field.name: getattr(av, field.name) for field in fields(av)}


def pack(results: Any) -> dict[str, Any]:
    """The numbers of a result (a dict of AllanVariance, or an ImuAllanVariance) as plain, picklable data."""
    if isinstance(results, dict):
        return {"series": {name: _pack_series(av) for name, av in results.items()}}
    imu = {field.name: getattr(results, field.name) for field in fields(results)}
    imu["channels"] = {name: _pack_series(av) for name, av in results.channels.items()}
    imu["units"] = dict(results.units)
    return {"imu": imu}


def unpack(packed: dict[str, Any]) -> Any:
    """The result objects :func:`pack` was given, rebuilt (and validated) by their constructors."""
    from avar.stability.allan.results import AllanVariance, ImuAllanVariance

    if "series" in packed:
        return {name: AllanVariance(**values) for name, values in packed["series"].items()}
    imu = dict(packed["imu"])
    imu["channels"] = {name: AllanVariance(**values) for name, values in imu["channels"].items()}
    return ImuAllanVariance(**imu)


def compute_file(path: str, options: ReadOptions) -> tuple[dict[str, Any], tuple[str, ...]]:
    """Read one file and compute its Allan variance(s): (the packed result, the reader's notes).

    Runs on a worker of the cluster (a module-level function, so it pickles by name),
    or in this process for a serial run.
    """
    data, notes = load(path, options, progress=False)
    return pack(allan_of(data, options.type, options.taus, nan_policy=options.nan_policy)), tuple(notes)


# ----------------------------------------------------------------------------- the driver
def compute_files(
    paths: list[str], options: ReadOptions, workers: int | None = None, scheduler: str | None = None,
    progress: bool | None = None,
) -> list[tuple[Any, tuple[str, ...]]]:
    """(result, notes) of every file, in order: serially (neither ``workers`` nor ``scheduler``),
    else on a dask.distributed cluster. A bar counts the files on stderr when ``progress``."""
    if workers is None and scheduler is None:
        items: Any = paths
        if progress:
            from tqdm import tqdm

            items = tqdm(paths, desc="computing", unit="file", file=sys.stderr)
        packed = [compute_file(path, options) for path in items]
    else:
        from avar.stability.allan.dask import WorkerLost, map_on_cluster

        try:
            packed = map_on_cluster(compute_file, paths, options, scheduler=scheduler, workers=workers or 1,
                                    progress=progress, unit="file", timeout=CONNECT_TIMEOUT)
        except WorkerLost as error:
            raise InputFileError(str(error)) from None
    return [(unpack(result), notes) for result, notes in packed]


def file_labels(paths: list[str]) -> list[str]:
    """The File column: the stems, else the file names, else the paths as given (whichever is unique)."""
    for label in (lambda p: Path(p).stem, lambda p: Path(p).name, str):
        labels = [label(path) for path in paths]
        if len(set(labels)) == len(labels):
            return labels
    return list(paths)


def _channel_table(results: Any) -> pd.DataFrame:
    """A file's summary with a Channel column, whatever its number of channels."""
    if isinstance(results, dict):
        frames = {name: res.summary() for name, res in results.items()}
        return pd.concat(frames, names=["Channel", "Scale"]).reset_index()
    return results.summary().reset_index()


def summary_of_files(labels: list[str], results: list[Any]) -> pd.DataFrame:
    """One table: a File column in front of each file's summary (Channel when any file has several)."""
    single = all(isinstance(res, dict) and len(res) == 1 for res in results)
    frames = []
    for label, res in zip(labels, results):
        frame = summary_of(res) if single else _channel_table(res)
        frame.insert(0, "File", label)
        frames.append(frame)
    return pd.concat(frames, ignore_index=True)


def figure_of_files(labels: list[str], results: list[Any], ylab: str | None = None):
    """Every series of every file on one comparison figure."""
    from avar.plotting.compare import plot_compare

    curves, names = [], []
    for label, res in zip(labels, results):
        channels = res if isinstance(res, dict) else dict(res.channels)
        for name, av in channels.items():
            curves.append(av)
            names.append(label if len(channels) == 1 else f"{label}: {name}")
    return plot_compare(curves, labels=[figure_text(name) for name in names], ylab=ylab)


def _check_files(paths: list[str]) -> None:
    from avar.io.read import check_path

    seen: set[str] = set()
    for path in paths:
        check_path(path)  # InputFileError naming the file
        key = str(Path(path).resolve())
        if key in seen:
            raise UsageError(f"{path} is given twice; give each file once")
        seen.add(key)


def capped_workers(asked: int, files: int, noun: str = "file") -> int:
    """``--workers`` capped by the number of ``files`` (one task each, named ``noun``) and of cores;
    a note on stderr says so."""
    cores = os.cpu_count() or 1
    workers = max(1, min(asked, files, cores))
    if workers < asked:
        print(f"--workers {asked}: {files} {noun}(s) on {cores} core(s); starting {workers} worker process(es)",
              file=sys.stderr)
    return workers


def run_many(args: argparse.Namespace) -> int:
    """``avar compute`` with several files, or with --workers/--scheduler."""
    options = ReadOptions.from_args(args)
    if args.workers is not None and args.scheduler is not None:
        raise UsageError("--workers starts a local cluster and --scheduler names a running one; give one of them")
    on_cluster = args.workers is not None or args.scheduler is not None
    if on_cluster and importlib.util.find_spec("distributed") is None:
        raise UsageError(DASK_MISSING)
    paths = [str(path) for path in args.file]
    check_bag_units(paths, args)
    unit = series_unit(args, bool(args.gyro or args.accel))
    ylab = None if unit is None else unit_label(unit, deviation=False)
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=paths, force=args.force)
    _check_files(paths)
    if args.workers is not None:
        args.workers = capped_workers(args.workers, len(paths))
        # an interrupted run ends at once (os._exit): the cluster's semaphores are the system's to free
        if QUIET_TRACKER not in sys.warnoptions:
            sys.warnoptions.append(QUIET_TRACKER)  # passed on to the resource tracker process
    progress = Progress()
    where = f"on {args.scheduler}" if args.scheduler else f"on {args.workers} local worker(s)"
    progress(f"computing {len(paths)} file(s) {where if on_cluster else 'one after the other'}")
    show = sys.stderr.isatty() if SHOW_PROGRESS is None else SHOW_PROGRESS
    computed = compute_files(paths, options, args.workers, args.scheduler, show)
    for _, notes in computed:
        for note in notes:
            print(printable(note), file=sys.stderr)
    results = [res for res, _ in computed]
    if len(results) == 1:
        summary = summary_of(results[0])

        def figure():
            return figure_of(results[0], ylab)
    else:
        labels = file_labels(paths)
        summary = summary_of_files(labels, results)

        def figure():
            return figure_of_files(labels, results, ylab)
    written = plan.write(csv=lambda: csv_text(summary), figure=figure)
    progress("done")
    report(written, format_table(summary))
    return 0
