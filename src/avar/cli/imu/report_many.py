"""``avar report LOG LOG... [--workers N | --scheduler ADDRESS]``: several logs of one sensor.

Every log (a file, a ROS bag, or every log of a folder) gets its own noise report
and bias-versus-temperature slopes (:func:`report_file`, on a worker of a dask
cluster with ``--workers``/``--scheduler``, the machinery of ``avar compute``:
:func:`avar.stability.allan.dask.map_on_cluster`; one after the other in this
process otherwise, with a progress notice), then this process pools them
(:func:`avar.fit.report.sessions.several_logs.combine_sessions`) and prints the
pooled table, one line per log and the warnings (a log that disagrees, a
temperature that drifts).
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from avar.cli.common import InputFileError, Progress, UsageError, printable
from avar.cli.compute_many import (
    CONNECT_TIMEOUT,
    DASK_MISSING,
    QUIET_TRACKER,
    capped_workers,
    check_bag_units,
    file_labels,
)
from avar.cli.outputs import csv_text, plan_outputs
from avar.cli.outputs import report as print_outputs

__all__ = ["LOG_SUFFIXES", "ReportOptions", "expand_logs", "report_file", "run_many"]

#: Files of a folder taken as logs (a subfolder is a log when it is a ROS 2 bag: it holds metadata.yaml).
LOG_SUFFIXES = (".csv", ".tsv", ".txt", ".dat", ".log", ".npy", ".npz", ".parquet", ".mat", ".bag", ".db3",
                ".mcap")
#: The progress bar over the logs: None shows it when stderr is a terminal; True/False force it.
SHOW_PROGRESS: bool | None = None


@dataclass(frozen=True)
class ReportOptions:
    """How to read a log and report it: picklable, for the workers of a cluster."""

    rate: float | None = None
    time_unit: str | None = None
    gaps: str = "error"
    topic: str | None = None
    gyro: tuple[str, ...] = ()
    accel: tuple[str, ...] = ()
    gyro_units: str | None = None
    accel_units: str | None = None
    confidence: float = 0.95
    robust: bool = False
    rate_option: str = "--rate"

    @classmethod
    def from_args(cls, args: argparse.Namespace) -> ReportOptions:
        return cls(args.rate, args.time_unit, args.gaps, args.topic, tuple(args.gyro or ()), tuple(args.accel or ()),
                   args.gyro_units, args.accel_units, args.confidence, bool(args.robust),
                   getattr(args, "rate_option", "--rate"))


def _is_bag(path: Path) -> bool:
    from avar.io.read import BAG_SUFFIXES

    return path.suffix.lower() in BAG_SUFFIXES or path.is_dir()


def expand_logs(files: list[str]) -> list[str]:
    """The logs named: files and ROS 2 bag folders as given, and every log of any other folder (sorted)."""
    logs: list[str] = []
    for name in files:
        path = Path(name)
        if path.is_dir() and not (path / "metadata.yaml").is_file():
            found = sorted(str(p) for p in path.iterdir()
                           if (p.is_file() and p.suffix.lower() in LOG_SUFFIXES)
                           or (p.is_dir() and (p / "metadata.yaml").is_file()))
            if not found:
                raise InputFileError(f"{name}: a folder with no log ({', '.join(LOG_SUFFIXES)} or ROS 2 bag folder)")
            logs += found
        else:
            logs.append(name)
    seen: set[str] = set()
    for log in logs:
        key = str(Path(log).resolve())
        if key in seen:
            raise UsageError(f"{log} is given twice; give each log once")
        seen.add(key)
    return logs


def report_file(path: str, options: ReportOptions, name: str) -> tuple[dict[str, Any], tuple[str, ...]]:
    """Read one log and report it: (its packed session, the reader's notes). Runs on a worker or here.

    Every column is read (a temperature column gives the bias-versus-temperature slopes);
    ``--gyro``/``--accel`` then select the sensor channels.
    """
    from avar.fit.report.sessions.several_logs import log_session, pack_session
    from avar.imu import IMU
    from avar.io.read import check_path, read

    check_path(path)
    bag = _is_bag(Path(path))
    data = read(Path(path), rate=options.rate, time_unit=options.time_unit, gaps=options.gaps,
                topic=options.topic if bag else None, progress=False)
    if isinstance(data, IMU):
        notes = [f"{path}: {data.describe()}"]
    else:
        if data.time_column is None and options.rate is None:
            raise InputFileError(f"{path}: no time column to take the rate from; pass --rate (Hz)")
        notes = [data.describe().replace("(given)", f"({options.rate_option})")]
        if data.gaps_ignored:
            notes.append(f"{path}: --gaps ignore: the samples are treated as contiguous across the gaps")
    selection = {"gyro": list(options.gyro) or None, "accel": list(options.accel) or None}
    if isinstance(data, IMU):
        selection = {}
    session = log_session(data, name, options.gyro_units, options.accel_units, confidence=options.confidence,
                          source=str(path), topic=data.name if isinstance(data, IMU) else options.topic,
                          from_bag=bag, robust=options.robust, **selection)
    return pack_session(session), tuple(notes)


def _sessions(paths: list[str], names: list[str], options: ReportOptions, workers: int | None,
              scheduler: str | None, progress: Progress) -> list[tuple[dict[str, Any], tuple[str, ...]]]:
    if workers is None and scheduler is None:
        done = []
        for at, (path, name) in enumerate(zip(paths, names)):
            progress(f"log {at + 1}/{len(paths)}: {path}")
            done.append(report_file(path, options, name))
        return done
    from avar.stability.allan.dask import WorkerLost, map_on_cluster

    show = sys.stderr.isatty() if SHOW_PROGRESS is None else SHOW_PROGRESS
    try:
        return map_on_cluster(_report_named, list(zip(paths, names)), options, scheduler=scheduler,
                              workers=workers or 1, progress=show, unit="log", timeout=CONNECT_TIMEOUT)
    except WorkerLost as error:
        raise InputFileError(str(error)) from None


def _report_named(item: tuple[str, str], options: ReportOptions) -> tuple[dict[str, Any], tuple[str, ...]]:
    """:func:`report_file` of one (path, name) task (a module-level function: it pickles by name)."""
    return report_file(item[0], options, item[1])


def run_many(args: argparse.Namespace) -> int:
    """``avar report`` with several logs (or a folder of logs), or with --workers/--scheduler."""
    from avar.fit.report.sessions.several_logs import combine_sessions, unpack_session

    for option in ("kalibr", "curves", "html"):
        if getattr(args, option, None) is not None:
            raise UsageError(f"--{option} writes one log's report; with several logs, give one log per run "
                             "(the pooled table goes to --output, the figure to --plot)")
    if args.workers is not None and args.scheduler is not None:
        raise UsageError("--workers starts a local cluster and --scheduler names a running one; give one of them")
    on_cluster = args.workers is not None or args.scheduler is not None
    if on_cluster and importlib.util.find_spec("distributed") is None:
        raise UsageError(DASK_MISSING)
    paths = expand_logs([str(f) for f in args.file])
    if len(paths) < 2:
        raise UsageError(f"several logs (a folder, --workers, --scheduler) pool at least 2 logs; got {len(paths)}: "
                         f"{', '.join(paths)} (one log: avar report LOG, without --workers/--scheduler)")
    check_bag_units(paths, args)
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=paths, force=args.force)
    options = ReportOptions.from_args(args)
    if args.workers is not None:
        args.workers = capped_workers(args.workers, len(paths), "log")
        if QUIET_TRACKER not in sys.warnoptions:
            sys.warnoptions.append(QUIET_TRACKER)
    progress = Progress()
    where = f"on {args.scheduler}" if args.scheduler else f"on {args.workers} local worker(s)"
    print(f"reporting {len(paths)} logs {where if on_cluster else 'one after the other'}", file=sys.stderr)
    done = _sessions(paths, file_labels(paths), options, args.workers, args.scheduler, progress)
    for _, notes in done:
        for note in notes:
            print(printable(note), file=sys.stderr)
    progress("pooling the logs and testing their agreement")
    result = combine_sessions([unpack_session(packed) for packed, _ in done], args.confidence)
    written = plan.write(csv=lambda: csv_text(result.summary()), figure=lambda: result.plot())
    progress("done")
    for warning in result.warnings:
        print(f"warning: {printable(warning)}", file=sys.stderr)
    print_outputs(written, result.text(warnings=False))
    return 0
