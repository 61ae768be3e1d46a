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

from avar.cli.common import InputFileError, Progress, UsageError
from avar.cli.outputs import Written, check_output_path, plan_outputs, write_atomically
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
        return SimpleNamespace(columns=values, freq=data.freq, source=str(args.file), topic=data.name,
                               notes=[f"{args.file}: {data.describe()}"])
    if data.time_column is None and args.freq is None:
        raise InputFileError(f"{args.file}: no time column to take the rate from; pass --freq (Hz)")
    # The rate, where it comes from and the timestamps' jitter, as `avar compute` says them.
    notes = [data.describe().replace("(given)", "(--freq)")]
    if data.gaps_ignored:
        notes.append(f"{args.file}: --gaps ignore: the samples are treated as contiguous across the gaps")
    return SimpleNamespace(columns=dict(data.columns), freq=data.freq, source=str(args.file), topic=args.topic,
                           notes=notes)


def run(args: argparse.Namespace) -> int:
    from avar.fit.noise_report import noise_report

    inputs = [Path(args.file)]
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=[args.file], force=args.force)
    kalibr = check_output_path("--kalibr", args.kalibr, inputs, args.force) if args.kalibr else None
    if kalibr is not None and any(isinstance(p, Path) and p.resolve() == kalibr.resolve()
                                  for p in (plan.csv, plan.figure)):
        raise UsageError(f"--kalibr {args.kalibr!r} is also given for another output; give them different names")
    progress = Progress()
    progress(f"reading {args.file}")
    recording = read_recording(args)
    for note in recording.notes:
        print(note, file=sys.stderr)
    progress("fitting the noise terms")
    report = noise_report(recording, gyro_units=args.gyro_units, accel_units=args.accel_units,
                          gyro=args.gyro, accel=args.accel, alpha=args.alpha, name=Path(args.file).name)
    files = []
    if kalibr is not None:
        import yaml

        text = yaml.safe_dump(report.kalibr(), sort_keys=False, default_flow_style=False)
        write_atomically(kalibr, text.encode("utf-8"))
        files.append(str(kalibr))
    written = plan.write(csv=lambda: report.table.to_csv(index=False), figure=report.plot)
    progress("done")
    print_outputs(Written(tuple(files) + written.files, written.stdout_csv), str(report))
    return 0


def add_parser(commands) -> None:
    report = commands.add_parser(
        "report", help="IMU noise report: ARW, bias instability, RRW (IEEE 952), Kalibr imu.yaml, figure"
    )
    report.add_argument("file", help="CSV/TSV/text, .npy, or a ROS bag (.bag, .db3, .mcap; needs allanvar[ros])")
    report.add_argument("--topic", help="sensor_msgs/Imu topic of a ROS bag (default: its only one); "
                        "written as Kalibr's rostopic")
    report.add_argument("--gyro", action="extend", nargs="+", metavar="NAME",
                        help="gyroscope columns, e.g. --gyro gx gy gz (default: by name)")
    report.add_argument("--accel", action="extend", nargs="+", metavar="NAME",
                        help="accelerometer columns, e.g. --accel ax ay az (default: by name)")
    report.add_argument("--gyro-units", choices=["rad/s", "deg/s", "deg/h"], help="gyroscope data unit (default rad/s)")
    report.add_argument("--accel-units", choices=["m/s^2", "g", "mg"], help="accelerometer data unit (default m/s^2)")
    report.add_argument("--freq", type=float, help="sampling rate in Hz (default: from a time column)")
    report.add_argument("--time-unit", choices=["s", "ms", "us", "ns"], default=None,
                        help="unit of a numeric time column (default: from its name, else s)")
    report.add_argument("--gaps", choices=["error", "ignore"], default="error",
                        help="time steps > 1.5 median steps: refuse (default) or treat the samples as contiguous")
    report.add_argument("--alpha", type=float, default=0.05, help="1 - confidence level of the intervals")
    report.add_argument("--kalibr", metavar="YAML", help="write a Kalibr imu.yaml")
    report.add_argument("--plot", metavar="PNG", help="write the report figure")
    report.add_argument("--output", metavar="CSV", help="write the table of terms")
    report.add_argument("--force", action="store_true", help="overwrite existing output files")
    report.set_defaults(handler=run)
