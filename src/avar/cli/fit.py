"""``avar fit``: Allan variance linear regression (AVLR) of a file."""

from __future__ import annotations

import argparse
from dataclasses import replace

from avar.cli.common import (
    InputFileError,
    Progress,
    UsageError,
    confidence_alpha,
    parse_scales,
    replicates,
    seed_number,
)
from avar.cli.compute import add_input_arguments, compute_from_args
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
    """``--units deg/s`` (one series), ``--units gyro=deg/s --units accel=g`` (IMU)."""
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


def run(args: argparse.Namespace) -> int:
    from avar.fit.avlr import avlr

    imu = bool(args.gyro or args.accel)
    per_sensor = [f"--{name}-{suffix}" for name, _ in PROCESSES for suffix in ("gyro", "acc")
                  if getattr(args, f"{name}_{suffix}")]
    if args.per_axis and not imu:
        raise UsageError("--per-axis applies to IMU fits only (name the columns with --gyro/--accel)")
    units = parse_units(args.units, imu)
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
        fit = avlr(next(iter(results.values())), ci=args.ci, B=args.B, alpha=args.alpha, seed=args.seed, **selections)
        ylab = None
        if units:
            ylab = f"Allan deviation [{units['series']}]" if args.deviation else f"Allan variance [({units['series']})^2]"

        def figure():
            return fit.plot(decomp=True, deviation=args.deviation, ylab=ylab)
    else:
        if units:
            results = replace(results, units=units)
        fit = avlr(results, ci=args.ci, B=args.B, alpha=args.alpha, seed=args.seed, per_axis=args.per_axis,
                   **imu_selections(args, results.present_types))

        def figure():
            return fit.plot(deviation=args.deviation)
    written = plan.write(csv=lambda: csv_text(fit.summary(), index=True), figure=figure)
    progress("done")
    report(written, str(fit))
    return 0



def add_parser(commands) -> None:
    fit = commands.add_parser("fit", help="Allan variance linear regression (AVLR) of a file")
    add_input_arguments(fit)
    for name, label in PROCESSES:
        fit.add_argument(f"--{name}", type=parse_scales, metavar="SCALES", help=f"scales of the {label}, e.g. 1:7")
        for suffix, sensor in (("gyro", "gyroscopes"), ("acc", "accelerometers")):
            fit.add_argument(
                f"--{name}-{suffix}", type=parse_scales, metavar="SCALES", help=f"scales of the {label} of the {sensor}"
            )
    fit.add_argument("--ci", action="store_true", help="parametric bootstrap confidence intervals (series or IMU)")
    fit.add_argument("--per-axis", action="store_true", help="IMU: one model per axis instead of per sensor type")
    fit.add_argument("--deviation", action="store_true", help="plot the Allan deviation instead of the variance")
    fit.add_argument("--units", action="append", metavar="UNIT",
                     help="data unit: one for a series (deg/s), or gyro=UNIT / accel=UNIT for an IMU (repeatable)")
    fit.add_argument("--B", type=replicates, default=100, help="bootstrap replicates (default 100)")
    fit.add_argument("--alpha", type=confidence_alpha, default=0.05, help="1 - confidence level (default 0.05)")
    fit.add_argument("--seed", type=seed_number, default=None, help="seed of the bootstrap")
    fit.set_defaults(handler=run)
