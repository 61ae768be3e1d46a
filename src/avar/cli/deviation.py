"""``avar deviation``: Stable32-style tables of the deviation statistics of one column of a file.

Every ``--stat NAME`` is looked up by name among the public deviation
functions of ``avar`` (``getattr(avar, NAME)``); the accepted names are the
registry :data:`avar.stability.shared.registry.DEVIATION_STATISTICS`, so a new
statistic needs no change here.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

from avar._escape import figure_text
from avar.cli.common import Progress, UsageError, add_confidence_arguments, printable, variables_note
from avar.cli.compute import add_nan_policy_argument, add_output_arguments, add_reading_arguments
from avar.cli.outputs import plan_outputs, report
from avar.stability.shared.confidence import DEFAULT_CONFIDENCE
from avar.stability.shared.registry import DEVIATION_STATISTICS

#: Columns of the printed table, as Stable32's run table.
TABLE_COLUMNS = ["AF", "Tau", "#", "Alpha", "Min Sigma", "Sigma", "Max Sigma"]


def statistic_function(name: str):
    """The public function of ``avar`` named ``name`` (one of the registry)."""
    import avar

    if name not in DEVIATION_STATISTICS:
        raise UsageError(f"unknown statistic {name!r}; use one of {', '.join(DEVIATION_STATISTICS)}")
    return getattr(avar, name)


def table_of(result) -> pd.DataFrame:
    """One row per level: AF (m), Tau, # (terms), Alpha, Min Sigma, Sigma, Max Sigma."""
    return pd.DataFrame({"AF": result.averaging_factors, "Tau": result.taus, "#": result.n_terms, "Alpha": result.alpha,
                         "Min Sigma": result.lci, "Sigma": result.deviation, "Max Sigma": result.uci},
                        columns=TABLE_COLUMNS)


def format_run(result, source: str) -> str:
    """The header line and the table, numbers as Stable32 prints them (4 significant digits, e-notation)."""
    table = table_of(result)
    text = table.to_string(index=False, na_rep="-",  # no bound (MTIE, TIE rms): a dash
                           formatters={name: "{:.4e}".format for name in ("Tau", "Min Sigma", "Sigma", "Max Sigma")})
    return f"{source}: {result.describe()}\n{text}"



def _values(args: argparse.Namespace):
    from avar.io.read import read

    if args.column and len(args.column) > 1:
        raise UsageError(f"deviation tables are of one column; --column is given {len(args.column)} times")
    data = read(args.file, columns=args.column, rate=args.rate, time_unit=args.time_unit, gaps=args.gaps,
                nan_policy=args.nan_policy)
    names = list(data.columns)
    if len(names) != 1:
        raise UsageError(f"{args.file} has {len(names)} data columns ({', '.join(names[:6])}); "
                         "choose one with --column NAME")
    rate = args.rate if args.rate is not None else data.rate
    note = variables_note(args.file, data)
    if note:
        print(printable(note), file=sys.stderr)
    return names[0], data.columns[names[0]], float(rate)


def run(args: argparse.Namespace) -> int:
    stats = args.stat or ["oadev"]
    functions = [statistic_function(name) for name in stats]
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=[args.file], force=args.force)
    progress = Progress()
    progress(f"reading {args.file}")
    column, values, rate = _values(args)
    results = []
    for name, function in zip(stats, functions):
        progress(f"computing {name}")
        results.append(function(values, rate=rate, data_type=args.data_type, taus=args.taus,
                                confidence=args.confidence, nan_policy=args.nan_policy, alpha=args.noise))
    source = f"{Path(args.file).name} [{column}]"  # names from the user's file: escaped for each sink below

    def csv() -> str:
        frames = [table_of(r).assign(Stat=r.name)[["Stat", *TABLE_COLUMNS]] for r in results]
        return pd.concat(frames, ignore_index=True).to_csv(index=False)

    def figure():
        from avar.plotting.deviation import plot_deviation

        fig = None
        for k, result in enumerate(results):
            fig = plot_deviation(result, colour=f"C{k}", main=f"{figure_text(source)}, {args.data_type} data",
                                 ylab="Deviation", ax=None if fig is None else fig.axes[0])
        return fig

    written = plan.write(csv=csv, figure=figure)
    progress("done")
    report(written, "\n\n".join(format_run(r, printable(source)) for r in results))
    return 0


def add_parser(commands) -> None:
    parser = commands.add_parser(
        "deviation", help="Stable32-style tables of ADEV, OADEV, MDEV, ... of one column of phase or frequency data",
        description="Stable32-style tables (AF, Tau, #, Alpha, Min Sigma, Sigma, Max Sigma) of the NIST SP 1065 "
                    "deviations of one column of phase (time error, s) or fractional frequency data.")
    parser.add_argument("file", help="CSV/TSV/text, .npy/.npz, Parquet or .mat file of phase or frequency data")
    parser.add_argument("--stat", action="append", metavar="NAME", choices=DEVIATION_STATISTICS,
                        help=f"statistic (repeatable; default oadev): {', '.join(DEVIATION_STATISTICS)}")
    parser.add_argument("--data-type", choices=["phase", "freq"], required=True,
                        help="phase (time error, s) or fractional frequency (freq) data; required")
    parser.add_argument("--taus", choices=["octave", "decade", "all"], default="octave",
                        help="grid of averaging times tau (s): octave (m = 1, 2, 4, ... as Stable32; the default), "
                             "decade or all")
    parser.add_argument("--column", action="append", metavar="NAME",
                        help="the data column, given once (default: the file's only data column)")
    add_confidence_arguments(parser, DEFAULT_CONFIDENCE, "Min/Max Sigma",
                             default_text="one sigma, 0.6827, printed 0.683 as Stable32")
    parser.add_argument("--noise", type=int, choices=[2, 1, 0, -1, -2], metavar="ALPHA",
                        help="fix the power-law noise exponent alpha at every level, as Stable32 allows (2 white PM, "
                             "1 flicker PM, 0 white FM, -1 flicker FM, -2 random-walk FM); default: identified")
    add_nan_policy_argument(parser, "terms")
    add_reading_arguments(parser)
    add_output_arguments(parser, "write the tables to this CSV file, with a Stat column ('-': stdout; default: "
                                 "none, the tables are printed)")
    parser.set_defaults(handler=run)

