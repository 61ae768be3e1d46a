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

from avar.cli.common import (
    InputFileError,
    Progress,
    UsageError,
    add_confidence_arguments,
    add_unit_arguments,
    printable,
    variables_note,
)
from avar.cli.compute import FILE_HELP, add_output_arguments, add_reading_arguments
from avar.cli.compute_many import add_cluster_arguments, check_bag_units
from avar.cli.imu.simulate import add_recheck_arguments, print_recheck
from avar.cli.outputs import check_output_path, csv_text, plan_outputs
from avar.cli.outputs import report as print_outputs


def read_recording(args: argparse.Namespace):
    """The log: a :class:`avar.Recording`, or the :class:`avar.IMU` of a ROS bag; the notes for stderr; its topic.

    A bag's IMU carries its topic as its name, which the Kalibr yaml writes as
    ``rostopic``; for a text log ``--topic`` only labels the yaml.
    """
    from avar.imu import IMU
    from avar.io.read import read

    columns = ((args.gyro or []) + (args.accel or [])) or None
    # For a text log, --topic only labels the Kalibr yaml; for a bag it selects the topic.
    data = read(Path(args.file), columns=columns, rate=args.rate, time_unit=args.time_unit, gaps=args.gaps,
                topic=args.topic if _is_bag(args.file) else None)
    if isinstance(data, IMU):
        return data, [f"{args.file}: {data.describe()}"], data.name
    if data.time_column is None and args.rate is None:
        raise InputFileError(f"{args.file}: no time column to take the rate from; pass --rate (Hz)")
    # The rate, where it comes from and the timestamps' jitter, as `avar compute` says them.
    notes = [data.describe().replace("(given)", f"({args.rate_option})"),
             *filter(None, [variables_note(args.file, data)])]
    if data.gaps_ignored:
        notes.append(f"{args.file}: --gaps ignore: the samples are treated as contiguous across the gaps")
    return data, notes, args.topic


def _is_folder(file: str) -> bool:
    """A folder of logs (not a ROS 2 bag folder, which holds metadata.yaml)."""
    return Path(file).is_dir() and not (Path(file) / "metadata.yaml").is_file()


def _is_bag(file: str) -> bool:
    from avar.io.read import BAG_SUFFIXES

    return Path(file).suffix.lower() in BAG_SUFFIXES or Path(file).is_dir()


def run(args: argparse.Namespace) -> int:
    from avar.fit.report.noise_report import noise_report

    axis_and_inflate(args)
    if len(args.file) > 1 or args.workers is not None or args.scheduler is not None or _is_folder(args.file[0]):
        from avar.cli.imu.report_many import run_many

        if args.export:
            raise UsageError("--export writes one log's report; with several logs, give one log per run")
        if args.recheck is not None:
            raise UsageError("--recheck rechecks the report of one log; with several logs, give one log per run")
        return run_many(args)
    args.file = args.file[0]
    inputs = [Path(args.file)]
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=[args.file], force=args.force)
    for option in ("--kalibr", "--curves", "--html"):
        if getattr(args, option[2:]) == "-":
            raise UsageError(f"{option} writes a file; '-' (stdout) is only for --output (give a file name)")
    outputs = {}
    for option, value in (("--kalibr", args.kalibr), ("--curves", args.curves), ("--html", args.html)):
        if value is not None:
            outputs[option] = check_output_path(option, value, inputs, args.force)
    exports = export_outputs(args, inputs, outputs)
    taken = [p.resolve() for p in (plan.csv, plan.figure) if isinstance(p, Path)]
    for option, path in outputs.items():
        if path.resolve() in taken:
            raise UsageError(f"{option} {str(path)!r} is also given for another output; give them different names")
        taken.append(path.resolve())
    check_bag_units([args.file], args)
    progress = Progress()
    progress(f"reading {args.file}")
    data, notes, topic = read_recording(args)
    for note in notes:
        print(printable(note), file=sys.stderr)
    progress("fitting the noise terms")
    report = noise_report(data, gyro_units=args.gyro_units, accel_units=args.accel_units,
                          gyro=args.gyro, accel=args.accel, confidence=args.confidence, name=Path(args.file).name,
                          source=str(args.file), topic=topic, from_bag=_is_bag(args.file), robust=args.robust)
    renders = {
        "--kalibr": lambda: report.kalibr_text(axis=args.axis, inflate=args.inflate).encode("utf-8"),
        "--curves": lambda: csv_text(report.curves).encode("utf-8"),
        "--html": lambda: _html(report, args),
    }
    renders |= {option: _export_render(report, name, args) for option, name in exports.items()}
    extra = [(path, renders[option]) for option, path in outputs.items()]
    # every output is rendered (the yaml, the curves, the page, the table, the figure) before any is written
    written = plan.write(csv=lambda: csv_text(report.table),
                         figure=lambda: report.plot(customary_axis=args.customary_axis), extra=extra)
    progress("done")
    _export_notes(report, exports, args)
    for warning in report.warnings:
        print(f"warning: {printable(warning)}", file=sys.stderr)
    print_outputs(written, str(report))
    print_recheck(report, args)
    return 0


def axis_and_inflate(args: argparse.Namespace) -> None:
    """``--axis`` (``--kalibr-axis``, deprecated, warns) and ``--inflate`` checked: ``args.axis``, ``args.inflate``."""
    old = getattr(args, "kalibr_axis", None)
    if old is not None:
        print("warning: --kalibr-axis is deprecated (removed in 0.3.0); use --axis, which every --export "
              "follows", file=sys.stderr)
        if args.axis is not None and args.axis != old:
            raise UsageError(f"--axis {args.axis} and --kalibr-axis {old} disagree; give --axis only")
    args.axis = args.axis or old or "max"
    args.kalibr_axis = args.axis
    if not (args.inflate > 0 and args.inflate < float("inf")):
        raise UsageError(f"--inflate must be a finite factor > 0 (on densities and random walks), got {args.inflate:g}")
    args.export = args.export or []


def export_outputs(args: argparse.Namespace, inputs: list[Path], outputs: dict) -> dict[str, str]:
    """Every ``--export NAME[=FILE]`` checked (name, path by the output rules) and added to ``outputs``;
    returns option -> export name. Two exports to one file are refused (by the caller's check of outputs)."""
    from avar.fit.report.exports.registry import DEFAULT_FILES, EXPORTS

    exports = {}
    for text in args.export:
        name, _, file = text.partition("=")
        if name not in EXPORTS:
            raise UsageError(f"--export {printable(text)}: the name must be one of {', '.join(EXPORTS)} "
                             "(NAME or NAME=FILE)")
        option = f"--export {text}"
        if option in outputs:
            raise UsageError(f"{option} is given twice; give it once")
        outputs[option] = check_output_path(option, file or DEFAULT_FILES[name], inputs, args.force)
        exports[option] = name
    return exports


def _export_render(report, name: str, args: argparse.Namespace):
    from avar.fit.report.exports.registry import export_text

    return lambda: export_text(report, name, axis=args.axis, inflate=args.inflate).encode("utf-8")


def _export_notes(report, exports: dict[str, str], args: argparse.Namespace) -> None:
    """The comments a format cannot hold (Basalt's JSON), on stderr."""
    from avar.fit.report.exports.registry import export_notes

    for option, name in exports.items():
        for line in export_notes(report, name, axis=args.axis, inflate=args.inflate):
            print(f"{printable(option)}: {printable(line)}", file=sys.stderr)


def _html(report, args: argparse.Namespace) -> bytes:
    """The self-contained HTML page of the report, naming the command that made it."""
    from avar.plotting.html_report import report_html

    command = " ".join(shlex.quote(word) for word in getattr(args, "command_line", None) or sys.argv)
    return report_html(report, command=command, source=str(args.file)).encode("utf-8")


def add_parser(commands) -> None:
    report = commands.add_parser(
        "report", help="IMU noise report: ARW, bias instability, RRW (IEEE 952), Kalibr imu.yaml, figure",
        description="The IEEE 952 noise terms of every channel of a log, with no scales to choose: quantization, "
                    "angle/velocity random walk, bias instability, rate random walk, ramp, Gauss-Markov and "
                    "sinusoid terms in SI and customary units with intervals; Kalibr imu.yaml, figure, HTML page.")
    report.add_argument("file", nargs="+", help=f"{FILE_HELP}; several logs of one sensor (or a folder of logs) give "
                        "a report per log, the pooled terms and a test of whether the logs agree")
    report.add_argument("--topic", metavar="TOPIC",
                        help="sensor_msgs/Imu topic of a ROS bag (default: the bag's only Imu topic); "
                             "written as Kalibr's rostopic (default /imu0)")
    report.add_argument("--gyro", action="extend", nargs="+", metavar="NAME",
                        help="gyroscope columns, e.g. --gyro gx gy gz (default: by name: gyro*, gx, angular_velocity.*)")
    report.add_argument("--accel", action="extend", nargs="+", metavar="NAME",
                        help="accelerometer columns, e.g. --accel ax ay az (default: by name: acc*, ax, "
                             "linear_acceleration.*)")
    add_unit_arguments(report, "or a ROS bag's SI unit")
    add_reading_arguments(report, "from a time column or a ROS bag's stamps; required without them")
    add_confidence_arguments(report, 0.95, "the intervals and of the band", deprecated_alpha=True)
    report.add_argument("--kalibr", metavar="YAML", help="write a Kalibr imu.yaml, the same as --export kalibr=YAML "
                        "(a value for every key; a term the data do not resolve gives its one-sided 97.5%% upper "
                        "bound, marked in a comment; default: none)")
    report.add_argument("--export", action="append", metavar="NAME[=FILE]",
                        help="write an estimator's IMU file (repeatable): kalibr (imu.yaml), openvins "
                             "(kalibr_imu_chain.yaml), vins (vins_imu.yaml), orbslam3 (orbslam3_imu.yaml), basalt "
                             "(basalt_calib.json), matlab (imu_params.m); FILE defaults to the name in brackets")
    report.add_argument("--axis", choices=["max", "mean"], default=None,
                        help="one value per sensor type in every export: the largest over its axes (max, the "
                             "default) or the mean")
    report.add_argument("--kalibr-axis", choices=["max", "mean"], default=None, help=argparse.SUPPRESS)
    report.add_argument("--inflate", type=float, default=1.0, metavar="K",
                        help="multiply the noise densities and random walks of the exports by K > 0 (a moving "
                             "platform needs more than static values; the table keeps the measured ones; default: 1)")
    report.add_argument("--curves", metavar="CSV", help="write the curves: Channel, Tau (s), ADEV, Lower, Upper, "
                        "Implied ADEV per level, to redraw any figure (default: none)")
    report.add_argument("--robust", action="store_true", help="robust Allan variance: a log with a few per cent "
                        "of spikes gives the terms of the clean process (default: the plain estimator)")
    report.add_argument("--customary-axis", action="store_true",
                        help="the figure's right axis in deg/h (gyroscopes) or ug (accelerometers) (default: none)")
    report.add_argument("--html", metavar="HTML", help="write the report as one self-contained HTML page "
                        "(inline SVG figures, tables, warnings, command, version; default: none)")
    add_cluster_arguments(report)
    add_recheck_arguments(report)
    add_output_arguments(report, "write the table of terms to this CSV file ('-': stdout; default: none, the "
                                 "report is printed)")
    report.set_defaults(handler=run)
