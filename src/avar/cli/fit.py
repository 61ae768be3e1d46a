"""``avar fit``: Allan variance linear regression (AVLR) of a file."""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace

from avar._vocabulary import REMOVED_IN
from avar.cli.common import (
    InputFileError,
    Progress,
    UsageError,
    add_confidence_arguments,
    parse_scales,
    replicates,
    seed_number,
    unit_label,
)
from avar.cli.compute import add_input_arguments, compute_from_args
from avar.cli.compute_many import check_bag_units, series_unit
from avar.cli.outputs import csv_text, plan_outputs, report

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


def parse_units(values: list[str] | None, imu: bool) -> dict[str, str]:
    """The deprecated ``--units deg/s`` (one series), ``--units gyro=deg/s --units accel=g`` (IMU)."""
    if not values:
        return {}
    if not imu:
        if len(values) != 1 or "=" in values[0]:
            raise UsageError("--units takes one unit for one series, e.g. --units deg/s")
        return {"series": values[0]}
    units = {}
    for value in values:
        key, _, unit = value.partition("=")
        kind = {"gyro": "Gyroscope", "accel": "Accelerometer", "acc": "Accelerometer"}.get(key.strip().lower())
        if kind is None or not unit:
            raise UsageError(f"--units {value!r}: for an IMU give gyro=UNIT and/or accel=UNIT")
        units[kind] = unit.strip()
    return units


def _units(args: argparse.Namespace, imu: bool) -> dict[str, str]:
    """The data units: ``--gyro-units``/``--accel-units`` (an IMU's are on its result already; a series' one
    labels the figure), or the deprecated ``--units``, with a note on stderr."""
    if args.units:
        if args.gyro_units or args.accel_units:
            raise UsageError("give --gyro-units/--accel-units or the deprecated --units, not both")
        print(f"avar fit: --units is deprecated and will be removed in avar {REMOVED_IN}; "
              "use --gyro-units UNIT / --accel-units UNIT", file=sys.stderr)
        return parse_units(args.units, imu)
    unit = series_unit(args, imu)
    return {"series": unit} if unit else {}


def run(args: argparse.Namespace) -> int:
    from avar.fit.avlr import avlr

    imu = bool(args.gyro or args.accel)
    per_sensor = [f"--{name}-{suffix}" for name, _ in PROCESSES for suffix in ("gyro", "acc")
                  if getattr(args, f"{name}_{suffix}")]
    if args.per_axis and not imu:
        raise UsageError("--per-axis applies to IMU fits only (name the columns with --gyro/--accel)")
    check_bag_units([args.file], args)
    units = _units(args, imu)
    if per_sensor and not imu:
        raise UsageError(f"{', '.join(per_sensor)} apply to IMU fits only (name the columns with --gyro/--accel)")
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=[args.file], force=args.force)
    progress = Progress()
    results = compute_from_args(args, progress)
    progress("fitting")
    if isinstance(results, dict):
        if len(results) != 1:
            raise InputFileError(
                f"fit takes one column (--column NAME) or an IMU (--gyro/--accel); the file has {list(results)}"
            )
        selections = {name: getattr(args, name) for name, _ in PROCESSES if getattr(args, name)}
        fit = avlr(next(iter(results.values())), ci=args.ci, B=args.B, confidence=args.confidence, seed=args.seed,
                   **selections)
        ylab = unit_label(units["series"], args.deviation) if units else None

        def figure():
            return fit.plot(decomp=True, deviation=args.deviation, ylab=ylab)
    else:
        if units:
            results = replace(results, units=units)
        fit = avlr(results, ci=args.ci, B=args.B, confidence=args.confidence, seed=args.seed, per_axis=args.per_axis,
                   **imu_selections(args, results.present_types))

        def figure():
            return fit.plot(deviation=args.deviation)
    written = plan.write(csv=lambda: csv_text(fit.summary(), index=True), figure=figure)
    progress("done")
    report(written, str(fit))
    return 0



def add_parser(commands) -> None:
    fit = commands.add_parser(
        "fit", help="Allan variance linear regression (AVLR) of a file",
        description="Allan variance linear regression (AVLR, R's avlr) of one column or of an IMU: each process "
                    "(quantization, white noise, random walk, drift) fitted on the 1-based scales you choose, "
                    "the Scale column of 'avar compute'; optional bootstrap intervals.")
    add_input_arguments(fit)
    for name, label in PROCESSES:
        fit.add_argument(f"--{name}", type=parse_scales, metavar="SCALES",
                         help=f"1-based scales of the {label}, e.g. 1:7, 3 or 1,2,5 (default: not fitted)")
        for suffix, sensor in (("gyro", "gyroscopes"), ("acc", "accelerometers")):
            fit.add_argument(
                f"--{name}-{suffix}", type=parse_scales, metavar="SCALES",
                help=f"scales of the {label} of the {sensor} (default: those of --{name})"
            )
    fit.add_argument("--ci", action="store_true",
                     help="parametric bootstrap confidence intervals, series or IMU (default: none)")
    fit.add_argument("--per-axis", action="store_true",
                     help="IMU: one model per axis (default: one per sensor type, pooled over its axes)")
    fit.add_argument("--deviation", action="store_true",
                     help="plot the Allan deviation (default: the Allan variance)")
    fit.add_argument("--units", action="append", metavar="UNIT", help=argparse.SUPPRESS)  # deprecated
    fit.add_argument("--B", type=replicates, default=100, help="bootstrap replicates (default 100)")
    add_confidence_arguments(fit, 0.95, "the bootstrap intervals", deprecated_alpha=True)
    fit.add_argument("--seed", type=seed_number, default=None,
                     help="seed of the bootstrap, a whole number >= 0 (default: fresh randomness)")
    fit.set_defaults(handler=run)
