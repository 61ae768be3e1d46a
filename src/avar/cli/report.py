"""``avar report``: the IMU noise report of a log in one command.

Reads the file, runs :func:`avar.noise_report` (no scales to choose), writes
the requested files (Kalibr ``imu.yaml``, figure, CSV table, HTML page) and then prints
the table, by the output rules of :mod:`avar.cli.outputs`.
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path
from types import SimpleNamespace

from avar.cli.common import InputFileError, Progress, UsageError, confidence_alpha, printable
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
        return SimpleNamespace(columns=values, freq=data.freq, source=str(args.file), topic=data.name,
                               notes=[f"{args.file}: {data.describe()}"], bag=True)
    if data.time_column is None and args.freq is None:
        raise InputFileError(f"{args.file}: no time column to take the rate from; pass --freq (Hz)")
    # The rate, where it comes from and the timestamps' jitter, as `avar compute` says them.
    notes = [data.describe().replace("(given)", "(--freq)")]
    if data.gaps_ignored:
        notes.append(f"{args.file}: --gaps ignore: the samples are treated as contiguous across the gaps")
    return SimpleNamespace(columns=dict(data.columns), freq=data.freq, source=str(args.file), topic=args.topic,
                           notes=notes, bag=is_bag)


def run(args: argparse.Namespace) -> int:
    from avar.fit.report.noise_report import noise_report

    inputs = [Path(args.file)]
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=[args.file], force=args.force)
    for option in ("--kalibr", "--curves", "--html"):
        if getattr(args, option[2:]) == "-":
            raise UsageError(f"{option} writes a file; '-' (stdout) is only for --output (give a file name)")
    outputs = {}
    for option, value in (("--kalibr", args.kalibr), ("--curves", args.curves), ("--html", args.html)):
        if value is not None:
            outputs[option] = check_output_path(option, value, inputs, args.force)
    taken = [p.resolve() for p in (plan.csv, plan.figure) if isinstance(p, Path)]
    for option, path in outputs.items():
        if path.resolve() in taken:
            raise UsageError(f"{option} {str(path)!r} is also given for another output; give them different names")
        taken.append(path.resolve())
    if Path(args.file).suffix.lower() in (".bag", ".db3", ".mcap") or Path(args.file).is_dir():
        for option, value, si in (("--gyro-units", args.gyro_units, "rad/s"), ("--accel-units", args.accel_units, "m/s^2")):
            if value is not None and value != si:
                raise UsageError(f"{option} {value}: ROS bags hold sensor_msgs/Imu in SI units ({si}) by definition; "
                                 f"drop {option}")
    progress = Progress()
    progress(f"reading {args.file}")
    recording = read_recording(args)
    for note in recording.notes:
        print(note, file=sys.stderr)
    progress("fitting the noise terms")
    report = noise_report(recording, gyro_units=args.gyro_units, accel_units=args.accel_units,
                          gyro=args.gyro, accel=args.accel, alpha=args.alpha, name=Path(args.file).name,
                          from_bag=recording.bag, robust=args.robust)
    renders = {
        "--kalibr": lambda: report.kalibr_text(axis=args.kalibr_axis).encode("utf-8"),
        "--curves": lambda: csv_text(report.curves).encode("utf-8"),
        "--html": lambda: _html(report, args),
    }
    extra = [(path, renders[option]) for option, path in outputs.items()]
    # every output is rendered (the yaml, the curves, the page, the table, the figure) before any is written
    written = plan.write(csv=lambda: csv_text(report.table),
                         figure=lambda: report.plot(customary_axis=args.customary_axis), extra=extra)
    progress("done")
    for warning in report.warnings:
        print(f"warning: {printable(warning)}", file=sys.stderr)
    print_outputs(written, str(report))
    return 0


def _html(report, args: argparse.Namespace) -> bytes:
    """The self-contained HTML page of the report, naming the command that made it."""
    from avar.plotting.html_report import report_html

    command = " ".join(shlex.quote(word) for word in getattr(args, "command_line", None) or sys.argv)
    return report_html(report, command=command, source=str(args.file)).encode("utf-8")


def add_parser(commands) -> None:
    report = commands.add_parser(
        "report", help="IMU noise report: ARW, bias instability, RRW (IEEE 952), Kalibr imu.yaml, figure"
    )
    report.add_argument("file", help="CSV/TSV/text, .npy/.npz, Parquet, .mat, or a ROS bag (.bag, .db3, .mcap; needs allanvar[ros])")
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
    report.add_argument("--alpha", type=confidence_alpha, default=0.05, help="1 - confidence level of the intervals")
    report.add_argument("--kalibr", metavar="YAML", help="write a Kalibr imu.yaml (a value for every key; "
                        "a term the data do not resolve gives its 95%% upper bound, marked in a comment)")
    report.add_argument("--kalibr-axis", choices=["max", "mean"], default="max",
                        help="aggregate the axes of a sensor type for Kalibr: the largest (default) or the mean")
    report.add_argument("--curves", metavar="CSV", help="write the curves: Channel, Tau (s), ADEV, Lower, Upper, "
                        "Implied ADEV per level, to redraw any figure")
    report.add_argument("--robust", action="store_true", help="robust Allan variance: a log with a few per cent "
                        "of spikes gives the terms of the clean process")
    report.add_argument("--customary-axis", action="store_true",
                        help="the figure's right axis in deg/h (gyroscopes) or ug (accelerometers)")
    report.add_argument("--plot", metavar="PNG", help="write the report figure")
    report.add_argument("--html", metavar="HTML", help="write the report as one self-contained HTML page "
                        "(inline SVG figures, tables, warnings, command, version)")
    report.add_argument("--output", metavar="CSV", help="write the table of terms")
    report.add_argument("--force", action="store_true", help="overwrite existing output files")
    report.set_defaults(handler=run)
