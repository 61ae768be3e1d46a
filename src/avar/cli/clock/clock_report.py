"""``avar clock-report``: the power-law noise model of a clock from its time error, and its Kalman coefficients.

Reads a table or a clock log (as ``avar deviation`` does: chrony, ntpd, linuxptp, RINEX clock
found from the content), runs :func:`avar.clock_report` and prints the ``h_alpha`` table with
its intervals, the diffusion coefficients q1, q2 and r of the two-state clock model, and the
fit check. ``--output`` writes both tables as one CSV, ``--plot`` the Allan deviation with the
fitted model, ``--export q=FILE`` the Kalman coefficients as YAML (units and formulas in
comments).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from avar.cli.clock.deviation import read_series
from avar.cli.common import Progress, UsageError, add_confidence_arguments, printable, replicates, seed_number
from avar.cli.compute import add_output_arguments, add_reading_arguments
from avar.cli.outputs import check_output_path, csv_text, plan_outputs, report

#: Columns of ``--output``: the power laws and the Kalman coefficients, one row each.
CSV_COLUMNS = ["Quantity", "Noise", "alpha", "Value", "Lower", "Upper", "Unit"]
#: What ``--export NAME[=FILE]`` writes, and FILE when not given.
EXPORTS = {"q": ("the Kalman clock model's diffusion coefficients q1, q2 and r (YAML)", "clock_q.yaml")}
#: Units of the Kalman coefficients.
Q_UNITS = {"q1": "s", "q2": "1/s", "r": "s^2"}
#: What each Kalman coefficient is, for the YAML.
Q_MEANING = {"q1": "white FM: q1 = h_0 / 2", "q2": "random-walk FM: q2 = 2 pi^2 h_-2",
             "r": "white PM (measurement noise): r = sigma_x^2 = h_2 rate / (8 pi^2)"}


def parse_export(text: str) -> tuple[str, str]:
    """``--export NAME[=FILE]`` (as ``avar report``'s): the name of what to write and its file
    (by default the name's own, ``q``: ``clock_q.yaml``)."""
    name, sep, file = text.partition("=")
    if name not in EXPORTS:
        raise UsageError(f"--export {text!r}: expected NAME[=FILE] with NAME one of {', '.join(EXPORTS)}")
    if sep and not file:
        raise UsageError(f"--export {text!r}: give the file after '=' (--export {name}=FILE) or leave '=' out "
                         f"({EXPORTS[name][1]})")
    return name, file or EXPORTS[name][1]


def report_frame(result) -> pd.DataFrame:
    """``--output``: a row per power law (``h``, 1/Hz at f = 1 Hz) and per Kalman coefficient (q1, q2, r)."""
    rows = [("h", row.Noise, int(row.alpha), row.h, row.Lower, row.Upper, "1/Hz")
            for row in result.coefficients.itertuples()]
    noise = {"q1": ("white FM", 0), "q2": ("random-walk FM", -2), "r": ("white PM", 2)}
    rows += [(name, *noise[name], row.Value, row.Lower, row.Upper, Q_UNITS[name])
             for name, row in result.kalman.iterrows()]
    return pd.DataFrame(rows, columns=CSV_COLUMNS)


def q_yaml(result, source: str) -> str:
    """The Kalman coefficients as YAML: ``q1``, ``q2``, ``r`` each with value, interval and unit;
    the model and the formulas in comments."""
    import yaml

    level = f"{result.confidence:g}"
    values = {name: {"value": float(row.Value), "lower": float(row.Lower), "upper": float(row.Upper),
                     "unit": Q_UNITS[name]} for name, row in result.kalman.iterrows()}
    body = {"model": "two-state clock (time error x, fractional frequency y)", "rate_hz": float(result.rate),
            "confidence": float(result.confidence), **values}
    comments = [
        f"# Kalman clock model from avar clock-report of {source} ({result.n_samples} frequency values",
        f"# at {result.rate:g} Hz; lower/upper: the {level} bootstrap interval).",
        "# Two-state model (Zucca and Tavella 2005):  dx = y dt + sqrt(q1) dW1,  dy = sqrt(q2) dW2",
        "# Process noise of a step tau (s):  Q = [[q1 tau + q2 tau^3 / 3, q2 tau^2 / 2], [q2 tau^2 / 2, q2 tau]]",
        "# Its Allan variance:  sigma_y^2(tau) = q1 / tau + q2 tau / 3",
        *(f"#   {name} ({Q_UNITS[name]}): {Q_MEANING[name]}" for name in values),
        "#   with S_y(f) = h_alpha f^alpha (1/Hz); 0: the fitted model has no such term.",
        "# Flicker FM (h_-1) has no finite-state form and is not here; a drift (q3 of the three-state",
        "# model) is not estimated: the record is taken drift-free (--remove-drift).",
    ]
    return "\n".join(comments) + "\n" + yaml.safe_dump(body, sort_keys=False)


def run(args: argparse.Namespace) -> int:
    from avar.fit.clock.report import clock_report
    from avar.stability.conditioning.conversions import DRIFT_MODELS, remove_drift
    from avar.stability.conditioning.resample import fill_gaps

    inputs = [Path(args.file)]
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=[args.file], force=args.force)
    extra = []
    taken = [p.resolve() for p in (plan.csv, plan.figure) if isinstance(p, Path)]
    for name, file in map(parse_export, args.export or []):
        path = check_output_path(f"--export {name}", file, inputs, args.force)
        if path.resolve() in taken:
            raise UsageError(f"--export {name}={file!r} is also given for another output; give them different names")
        taken.append(path.resolve())
        extra.append((path, lambda: q_yaml(result, Path(args.file).name).encode("utf-8")))
    progress = Progress()
    progress(f"reading {args.file}")
    args.nan_policy = "raise"
    series = read_series(args)
    values = series.values
    if np.isnan(values).any():
        filled = fill_gaps(values, "linear")
        print(printable(f"avar clock-report: {filled.note}"), file=sys.stderr)
        values = filled.data
    if args.remove_drift:
        model = DRIFT_MODELS[series.data_type][0]
        drift = remove_drift(values, model=model, data_type=series.data_type, rate=series.rate)
        print(f"avar clock-report: removed the {model} drift, {drift.drift:.4g} /s", file=sys.stderr)
        values = drift.residual
    progress("fitting the clock's noise model")
    result = clock_report(values, rate=series.rate, data_type=series.data_type, confidence=args.confidence,
                          B=args.B, seed=args.seed)
    written = plan.write(csv=lambda: csv_text(report_frame(result)), figure=lambda: result.plot(), extra=extra)
    progress("done")
    for warning in result.warnings:
        print(f"avar clock-report: warning: {printable(warning)}", file=sys.stderr)
    head = f"{printable(Path(args.file).name)} [{printable(series.column)}]: {series.data_type} data"
    report(written, f"{head}\n{result}")
    return 0


def add_parser(commands) -> None:
    from avar.io.clocks.detect import KINDS

    parser = commands.add_parser(
        "clock-report", help="a clock's power-law noise coefficients h_alpha and Kalman q1, q2 with intervals",
        description="The noise model of a clock from its time error or fractional frequency (a table or a clock "
                    "log): white PM, white FM, flicker FM and random-walk FM fitted jointly (GMWM), the power-law "
                    "coefficients h_alpha and the diffusion coefficients q1, q2 (and r) of the two-state Kalman "
                    "clock model with bootstrap intervals, and the check of the fit against the OADEV.")
    parser.add_argument("file", help="CSV/TSV/text, .npy/.npz, Parquet or .mat file of phase or frequency data, or a "
                                     "clock log (chrony, ntpd, ptp4l/phc2sys, RINEX .clk; found from the content)")
    parser.add_argument("--data-type", choices=["phase", "freq"], default=None,
                        help="phase (time error, s) or fractional frequency (freq) (default: none; required for a "
                             "table, a clock log says what its column holds)")
    parser.add_argument("--column", action="append", metavar="NAME",
                        help="the data column, given once (default: the only one; a clock log's offset)")
    parser.add_argument("--log-kind", choices=sorted(KINDS), default=None, metavar="KIND",
                        help="read the file as this kind of clock log (as avar deviation; default: from the content)")
    parser.add_argument("--source", metavar="NAME", help="the source of a clock log holding several (default: the one with the "
                                                          "most records)")
    parser.add_argument("--remove-drift", action="store_true",
                        help="remove a drift first (phase: quadratic, frequency: linear; default: the data as read)")
    add_confidence_arguments(parser, 0.95, "the intervals")
    parser.add_argument("--B", type=replicates, default=100, help="bootstrap replicates of the intervals (default 100)")
    parser.add_argument("--seed", type=seed_number, default=None,
                        help="seed of the bootstrap, a whole number >= 0 (default: fresh randomness)")
    add_reading_arguments(parser)
    add_output_arguments(parser, "write the h_alpha and q tables to this CSV file ('-': stdout; default: none, "
                                 "the tables are printed)")
    parser.add_argument("--export", action="append", metavar="NAME[=FILE]",
                        help="write q: the Kalman clock model's diffusion coefficients q1, q2 and r as YAML with units "
                             "and formulas in comments; FILE defaults to clock_q.yaml (e.g. --export q=clock.yaml)")
    parser.set_defaults(handler=run)
