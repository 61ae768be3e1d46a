"""``avar report``: the IMU noise report of a log in one command.

Reads the file, runs :func:`avar.noise_report` (no scales to choose), writes
the requested files (Kalibr ``imu.yaml``, figure, CSV table) and then prints
the table, by the output rules of :mod:`avar.cli.outputs`.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from types import SimpleNamespace

from avar.cli.common import InputFileError, Progress, UsageError, confidence_alpha
from avar.cli.outputs import check_output_path, csv_text, plan_outputs
from avar.cli.outputs import report as print_outputs


def read_recording(args: argparse.Namespace):
    """The log as a Recording, or as an IMU-like table when it is a ROS bag.

    A bag's IMU carries its topic as its name; it is handed on as named
    columns with that topic, which the Kalibr yaml writes as ``rostopic``.
    """
    from avar.imu import IMU
    from avar.io.read import BAG_SUFFIXES, read

    columns = ((args.gyro or []) + (args.accel or [])) or None
    path = Path(args.file)
    is_bag = path.suffix.lower() in BAG_SUFFIXES or path.is_dir()
    # For a text log, --topic only labels the Kalibr yaml; for a bag it selects the topic.
    data = read(path, columns=columns, freq=args.freq, time_unit=args.time_unit, gaps=args.gaps,
                topic=args.topic if is_bag else None)
    if isinstance(data, IMU):
        values = {name: data[name] for name in data.channels}
        return SimpleNamespace(columns=values, freq=data.freq, source=str(args.file), topic=data.name)
    if data.time_column is None and args.freq is None:
        raise InputFileError(f"{args.file}: no time column to take the rate from; pass --freq (Hz)")
    return SimpleNamespace(columns=dict(data.columns), freq=data.freq, source=str(args.file), topic=args.topic)


def run(args: argparse.Namespace) -> int:
    from avar.fit.noise_report import noise_report

    inputs = [Path(args.file)]
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=[args.file], force=args.force)
    if args.kalibr == "-":
        raise UsageError("--kalibr writes a file; '-' (stdout) is only for --output (give e.g. imu.yaml)")
    kalibr = check_output_path("--kalibr", args.kalibr, inputs, args.force) if args.kalibr else None
    if kalibr is not None and any(isinstance(p, Path) and p.resolve() == kalibr.resolve()
                                  for p in (plan.csv, plan.figure)):
        raise UsageError(f"--kalibr {args.kalibr!r} is also given for another output; give them different names")
    progress = Progress()
    progress(f"reading {args.file}")
    recording = read_recording(args)
    n = len(next(iter(recording.columns.values())))
    print(f"{args.file}: {len(recording.columns)} column(s) x {n} samples at {recording.freq:g} Hz", file=sys.stderr)
    progress("fitting the noise terms")
    report = noise_report(recording, gyro_units=args.gyro_units, accel_units=args.accel_units,
                          gyro=args.gyro, accel=args.accel, alpha=args.alpha, name=Path(args.file).name)
    extra = []
    if kalibr is not None:
        extra.append((kalibr, lambda: kalibr_yaml(report.kalibr())))
    # every output is rendered (the yaml, the table, the figure) before any is written
    written = plan.write(csv=lambda: csv_text(report.table), figure=report.plot, extra=extra)
    progress("done")
    print_outputs(written, str(report))
    return 0


def kalibr_yaml(fields: dict) -> bytes:
    """The Kalibr fields as YAML; a non-finite density is refused (Kalibr cannot read ``.nan``)."""
    import math

    import yaml

    bad = [key for key, value in fields.items() if isinstance(value, float) and not math.isfinite(value)]
    if bad:
        raise InputFileError(f"the Kalibr field(s) {bad} are not finite numbers; nothing was written")
    return yaml.safe_dump(fields, sort_keys=False, default_flow_style=False).encode("utf-8")


def add_parser(commands) -> None:
    report = commands.add_parser(
        "report", help="IMU noise report: ARW, bias instability, RRW (IEEE 952), Kalibr imu.yaml, figure"
    )
    report.add_argument("file", help="CSV/TSV/text, .npy, or a ROS bag (.bag, .db3, .mcap; needs avar[ros])")
    report.add_argument("--topic", help="sensor_msgs/Imu topic of a ROS bag (default: its only one); "
                        "written as Kalibr's rostopic")
    report.add_argument("--gyro", nargs="+", metavar="NAME", help="gyroscope columns (default: by name)")
    report.add_argument("--accel", nargs="+", metavar="NAME", help="accelerometer columns (default: by name)")
    report.add_argument("--gyro-units", choices=["rad/s", "deg/s", "deg/h"], help="gyroscope data unit (default rad/s)")
    report.add_argument("--accel-units", choices=["m/s^2", "g", "mg"], help="accelerometer data unit (default m/s^2)")
    report.add_argument("--freq", type=float, help="sampling rate in Hz (default: from a time column)")
    report.add_argument("--time-unit", choices=["s", "ms", "us", "ns"], default=None,
                        help="unit of a numeric time column (default: from its name, else s)")
    report.add_argument("--gaps", choices=["error", "ignore"], default="error",
                        help="time steps > 1.5 median steps: refuse (default) or treat the samples as contiguous")
    report.add_argument("--alpha", type=confidence_alpha, default=0.05, help="1 - confidence level of the intervals")
    report.add_argument("--kalibr", metavar="YAML", help="write a Kalibr imu.yaml")
    report.add_argument("--plot", metavar="PNG", help="write the report figure")
    report.add_argument("--output", metavar="CSV", help="write the table of terms")
    report.add_argument("--force", action="store_true", help="overwrite existing output files")
    report.set_defaults(handler=run)
