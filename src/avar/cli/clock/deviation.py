"""``avar deviation``: Stable32-style tables of the deviation statistics of one column of a file.

Every ``--stat NAME`` is looked up by name among the public deviation
functions of ``avar`` (``getattr(avar, NAME)``); the accepted names are the
registry :data:`avar.stability.shared.registry.DEVIATION_STATISTICS`, so a new
statistic needs no change here.

A clock log (chrony, ntpd, linuxptp, RINEX clock; found from its content by
:func:`avar.io.clocks.detect.detect`, or named by ``--log-kind``) is read by
:func:`avar.read_clock_log`: its default column (the offset) unless ``--column``
names another field, its time-stamp gaps as NaN gaps the statistics skip. ``--check``
runs :func:`avar.check` first and prints what it finds; ``--dynamic WINDOW[:STEP]``
gives the dynamic deviation (:func:`avar.dynamic`) instead of the tables.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from avar._escape import figure_text
from avar.cli.common import Progress, UsageError, add_confidence_arguments, printable, variables_note
from avar.cli.compute import add_nan_policy_argument, add_output_arguments, add_reading_arguments
from avar.cli.outputs import plan_outputs, report
from avar.stability.shared.confidence import DEFAULT_CONFIDENCE
from avar.stability.shared.registry import CLASSIC, DEVIATION_STATISTICS

#: Columns of the printed table, as Stable32's run table.
TABLE_COLUMNS = ["AF", "Tau", "#", "Alpha", "Min Sigma", "Sigma", "Max Sigma"]
#: Columns of ``--dynamic --output``: the surface in long form.
SURFACE_COLUMNS = ["time", "tau", "deviation", "lower", "upper"]
#: Bytes of a file read to tell a clock log from a table.
HEAD_BYTES = 1 << 16
#: Clock log kinds found from the content; a Stable32 data file is only read as one when named
#: (``--log-kind stable32``): one or two columns of numbers are also a plain table.
DETECTED_KINDS = frozenset({"chrony-tracking", "chrony-statistics", "chrony-measurements", "ntpd-loopstats",
                            "ntpd-peerstats", "linuxptp", "rinex-clock"})


class Series(NamedTuple):
    """The data of a run: its name, the values (NaN in gaps), rate (Hz), data type, NaN policy,
    and each value's file line (0 where unknown: a table)."""

    column: str
    values: np.ndarray
    rate: float
    data_type: str
    nan_policy: str
    lines: np.ndarray


def statistic_function(name: str):
    """The public function of ``avar`` named ``name`` (one of the registry)."""
    import avar

    if name not in DEVIATION_STATISTICS:
        raise UsageError(f"unknown statistic {name!r}; use one of {', '.join(DEVIATION_STATISTICS)}")
    return getattr(avar, name)


def table_of(result) -> pd.DataFrame:
    """One row per level: AF (m), Tau, # (terms), Alpha, Min Sigma, Sigma, Max Sigma.

    ThêoH joins two tables: its OADEV levels (tau = m tau0) and its Theo1 levels (tau = 0.75 m
    tau0). Its rows are sorted by tau, one per tau (where both parts reach one tau the Theo1
    level, bias removed, is kept), with AF = tau / tau0 and a ``Part`` column naming the part.
    """
    table = pd.DataFrame({"AF": result.averaging_factors, "Tau": result.taus, "#": result.n_terms,
                          "Alpha": result.alpha, "Min Sigma": result.lci, "Sigma": result.deviation,
                          "Max Sigma": result.uci}, columns=TABLE_COLUMNS)
    if result.estimator != "theoh":
        return table
    taus = np.asarray(result.taus)
    runs = np.split(np.arange(taus.size), np.flatnonzero(np.diff(taus) < 0) + 1)  # OADEV's levels, then Theo1's
    part = np.full(taus.size, "OADEV", dtype=object)
    for run in runs[1:]:
        part[run] = "Theo1"
    table["AF"] = [f"{value:g}" for value in np.round(taus * result.rate, 6)]
    table.insert(0, "Part", part)
    table = table.sort_values(["Tau", "Part"], kind="stable").drop_duplicates("Tau", keep="last")
    return table.reset_index(drop=True)


def format_run(result, source: str) -> str:
    """The header line and the table, numbers as Stable32 prints them (4 significant digits, e-notation)."""
    table = table_of(result)
    text = table.to_string(index=False, na_rep="-",  # no bound (MTIE, TIE rms): a dash
                           formatters={name: "{:.4e}".format for name in ("Tau", "Min Sigma", "Sigma", "Max Sigma")})
    return f"{source}: {result.describe()}\n{text}"


def clock_log_kind(path: str, forced: str | None) -> str | None:
    """The kind of clock log ``path`` is (``forced`` when given), from its first 64 kB; None: a table."""
    from avar.io.clocks.detect import detect
    from avar.io.clocks.result import ClockLogError
    from avar.io.clocks.table import Text
    from avar.io.streams import open_bytes

    if forced is not None:
        return forced
    try:
        with open_bytes(Path(path)) as handle:
            data = handle.read(HEAD_BYTES)
    except (OSError, EOFError, ValueError):
        return None  # the table reader says what is wrong
    if b"\0" in data:
        return None
    lines = data.decode("utf-8-sig", errors="replace").splitlines()
    if len(data) == HEAD_BYTES and len(lines) > 1:
        lines = lines[:-1]  # cut inside a line
    try:
        kind = detect(Text(Path(path), lines, False))
    except ClockLogError:
        return None
    return kind if kind in DETECTED_KINDS else None


def _clock_series(args: argparse.Namespace, kind: str) -> Series:
    from avar.io.clocks.detect import KINDS, read_clock_log

    if args.column and len(args.column) > 1:
        raise UsageError(f"deviation tables are of one column; --column is given {len(args.column)} times")
    takes = KINDS[kind][2]
    selection: dict[str, Any] = {}
    if args.source is not None:
        if "source" not in takes:
            raise UsageError(f"--source: a {KINDS[kind][0]} holds one source")
        selection["source"] = args.source
    if "rate" in takes:  # a Stable32 data file without time tags
        selection.update(rate=args.rate, time_unit=args.time_unit, data_type=args.data_type)
    elif args.rate is not None or args.time_unit is not None:
        option = args.rate_option if args.rate is not None else "--time-unit"
        raise UsageError(f"{option}: the time stamps of a {KINDS[kind][0]} give its rate; leave it out")
    log = read_clock_log(args.file, kind=kind, column=args.column[0] if args.column else None, **selection)
    if args.data_type is not None and args.data_type != log.data_type:
        raise UsageError(f"--data-type {args.data_type}: the log's column is {log.data_type} data ({log.column}); "
                         "leave --data-type out or choose the column with --column")
    for line in f"read as a clock log: {log.describe()}".splitlines():
        print(printable(f"avar deviation: {line}"), file=sys.stderr)
    series = log.to_series()
    values = series.to_numpy(dtype=np.float64)
    lines = np.zeros(values.size, dtype=np.int64)
    lines[np.flatnonzero(np.isfinite(values))] = log.lines if log.lines.size == log.n else 0
    nan_policy = args.nan_policy
    missing = int(series.attrs.get("missing", 0))
    if missing:
        nan_policy = "omit"
        print(f"avar deviation: the {log.gaps.count} time-stamp gap(s) leave {missing} missing sample(s): "
              "NaN gaps the statistics skip (--nan-policy omit)", file=sys.stderr)
    return Series(str(series.name), values, float(log.rate), log.data_type, nan_policy, lines)


def _table_series(args: argparse.Namespace) -> Series:
    from avar.io.read import read

    if args.data_type is None:
        raise UsageError("--data-type phase|freq is required (only a clock log says what it holds)")
    if args.source is not None:
        raise UsageError("--source selects a source of a clock log; this file is read as a table")
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
    values = np.asarray(data.columns[names[0]], dtype=np.float64)
    return Series(names[0], values, float(rate), args.data_type, args.nan_policy, np.zeros(values.size, np.int64))


def read_series(args: argparse.Namespace) -> Series:
    """The column of a clock log or of a table, as ``args`` ask."""
    kind = clock_log_kind(args.file, args.log_kind)
    return _table_series(args) if kind is None else _clock_series(args, kind)


def check_lines(series: Series) -> list[str]:
    """``--check``: one line per outlier or jump :func:`avar.check` finds (sample, time, file line, size),
    or one line saying there is none."""
    from avar.stability.conditioning.check import check

    finite = np.flatnonzero(np.isfinite(series.values))
    try:
        found = check(series.values[finite], data_type=series.data_type, rate=series.rate)
    except ValueError as error:  # too few values for the MAD and the jump windows
        return [f"avar deviation: warning: check not run: {error}"]
    unit = {"phase spike": " s", "phase jump": " s", "frequency spike": "", "frequency jump": ""}
    lines = []
    for event in found.events:
        sample = int(finite[event.index])
        line = int(series.lines[sample])
        where = f"sample {sample + 1} (t = {sample / series.rate:g} s{f', line {line}' if line else ''})"
        lines.append(f"avar deviation: warning: {event.kind} at {where}, size {event.size:.4g}{unit[event.kind]}")
    if not lines:
        return [f"avar deviation: check: no outliers or jumps in {finite.size} {series.data_type} values "
                f"(threshold {found.threshold:.3g}, 5 MADs of the fractional frequency)"]
    skipped = " (NaN gaps left out; sample numbers count them)" if finite.size < series.values.size else ""
    return [f"avar deviation: check: {len(found.events)} outlier(s) or jump(s) in {finite.size} "
            f"{series.data_type} values{skipped}; the tables below include them", *lines]


def parse_window(text: str) -> tuple[int, int | None]:
    """``--dynamic WINDOW[:STEP]``: whole numbers of samples."""
    parts = text.split(":")
    try:
        numbers = [int(part) for part in parts]
    except ValueError:
        numbers = []
    if len(parts) not in (1, 2) or len(numbers) != len(parts) or min(numbers) < 1:
        raise argparse.ArgumentTypeError(f"expected WINDOW or WINDOW:STEP, whole numbers of samples >= 1, "
                                         f"got {text!r}")
    return numbers[0], numbers[1] if len(numbers) == 2 else None


def dynamic_text(result, source: str) -> str:
    """The dynamic deviation's line and its non-stationarity summary, one line per run of windows."""
    runs = result.unstable()
    lines = [f"{source}: {result.describe()}"]
    if runs.empty:
        lines.append("stationary: no window leaves the 99 % band of the whole record's deviation at any tau")
        return "\n".join(lines)
    lines.append(f"non-stationary: {len(runs)} run(s) of windows leave the 99 % band of the whole record's "
                 "deviation:")
    for run in runs.itertuples(index=False):
        change = "" if np.isnan(run[7]) else f", change near t = {run[7]:.6g} s"
        lines.append(f"  windows {run[0]}..{run[1]} (t = {run[3]:.6g} .. {run[4]:.6g} s){change}: "
                     f"deviation x {run[9]:.3g} of the record's at tau = {run[8]:.6g} s")
    return "\n".join(lines)


def surface_frame(result) -> pd.DataFrame:
    """``--dynamic --output``: one row per window and tau (time: the window's centre, s)."""
    n_windows, n_taus = result.deviation.shape
    return pd.DataFrame({"time": np.repeat(result.times, n_taus), "tau": np.tile(result.taus, n_windows),
                         "deviation": result.deviation.ravel(), "lower": result.lci.ravel(),
                         "upper": result.uci.ravel()}, columns=SURFACE_COLUMNS)


def _run_dynamic(args: argparse.Namespace, series: Series, source: str, plan, progress: Progress) -> int:
    import avar

    stat = (args.stat or ["oadev"])[0]
    if (args.stat and len(args.stat) > 1) or stat not in CLASSIC:
        raise UsageError(f"--dynamic takes one --stat of {', '.join(CLASSIC)}; got {', '.join(args.stat or [])}")
    window, step = args.dynamic
    progress(f"computing the dynamic {stat} (windows of {window} samples)")
    result = avar.dynamic(stat, series.values, rate=series.rate, data_type=series.data_type, window=window,
                          step=step, taus=args.taus, confidence=args.confidence, nan_policy=series.nan_policy)
    written = plan.write(csv=lambda: surface_frame(result).to_csv(index=False),
                         figure=lambda: result.plot(main=f"{figure_text(source)}: {result.name}"))
    progress("done")
    report(written, dynamic_text(result, printable(source)))
    return 0


def run(args: argparse.Namespace) -> int:
    stats = args.stat or ["oadev"]
    functions = [statistic_function(name) for name in stats]
    plan = plan_outputs(csv=args.output, figure=args.plot, inputs=[args.file], force=args.force)
    progress = Progress()
    progress(f"reading {args.file}")
    series = read_series(args)
    source = f"{Path(args.file).name} [{series.column}]"  # names from the user's file: escaped for each sink below
    if args.check:
        for line in check_lines(series):
            print(printable(line), file=sys.stderr, flush=True)
    if args.dynamic is not None:
        return _run_dynamic(args, series, source, plan, progress)
    results = []
    for name, function in zip(stats, functions):
        progress(f"computing {name}")
        results.append(function(series.values, rate=series.rate, data_type=series.data_type, taus=args.taus,
                                confidence=args.confidence, nan_policy=series.nan_policy, alpha=args.noise))

    def csv() -> str:
        frames = [table_of(r).assign(Stat=r.name) for r in results]
        frames = [frame[["Stat", *(c for c in frame.columns if c != "Stat")]] for frame in frames]
        return pd.concat(frames, ignore_index=True).to_csv(index=False)

    def figure():
        from avar.plotting.deviation import plot_deviation

        fig = None
        for k, result in enumerate(results):
            fig = plot_deviation(result, colour=f"C{k}", main=f"{figure_text(source)}, {series.data_type} data",
                                 ylab="Deviation", ax=None if fig is None else fig.axes[0])
        return fig

    written = plan.write(csv=csv, figure=figure)
    progress("done")
    report(written, "\n\n".join(format_run(r, printable(source)) for r in results))
    return 0


def add_parser(commands) -> None:
    from avar.io.clocks.detect import KINDS

    parser = commands.add_parser(
        "deviation", help="Stable32-style tables of ADEV, OADEV, MDEV, ... of one column of phase or frequency data",
        description="Stable32-style tables (AF, Tau, #, Alpha, Min Sigma, Sigma, Max Sigma) of the NIST SP 1065 "
                    "deviations of one column of phase (time error, s) or fractional frequency data, from a table "
                    "or a clock log (chrony, ntpd, ptp4l/phc2sys, RINEX clock: found from the content).")
    parser.add_argument("file", help="CSV/TSV/text, .npy/.npz, Parquet or .mat file of phase or frequency data, or a "
                                     "clock log (chrony tracking/statistics/measurements, ntpd loopstats/peerstats, "
                                     "ptp4l/phc2sys/ts2phc output, RINEX .clk)")
    parser.add_argument("--stat", action="append", metavar="NAME", choices=DEVIATION_STATISTICS,
                        help=f"statistic (repeatable; default oadev): {', '.join(DEVIATION_STATISTICS)}")
    parser.add_argument("--data-type", choices=["phase", "freq"], default=None,
                        help="phase (time error, s) or fractional frequency (freq) data (default: none; required "
                             "for a table, a clock log says what its column holds)")
    parser.add_argument("--taus", choices=["octave", "decade", "all"], default="octave",
                        help="grid of averaging times tau (s): octave (m = 1, 2, 4, ... as Stable32; the default), "
                             "decade or all")
    parser.add_argument("--column", action="append", metavar="NAME",
                        help="the data column, given once (default: the file's only data column; a clock log's "
                             "offset, e.g. --column 'Freq ppm' for chrony's frequency)")
    parser.add_argument("--log-kind", choices=sorted(KINDS), default=None, metavar="KIND",
                        help="read the file as this kind of clock log (default: found from the content; a "
                             f"Stable32 data file only when named): {', '.join(sorted(KINDS))}")
    parser.add_argument("--source", metavar="NAME",
                        help="the source of a clock log holding several (an address of chrony statistics/"
                             "measurements or ntpd peerstats; 'ptp4l master', 'phc2sys' ...; default: the one with "
                             "the most records)")
    parser.add_argument("--check", action="store_true",
                        help="look for outliers and jumps first (avar.check, Stable32's Check: 5 MADs) and print "
                             "one line for each, with its position and size, on stderr (default: no check)")
    parser.add_argument("--dynamic", type=parse_window, metavar="WINDOW[:STEP]",
                        help="the dynamic deviation of the first --stat (default oadev) in windows of WINDOW samples "
                             "every STEP (default WINDOW / 10): its non-stationarity summary; --output writes the "
                             "surface (time, tau, deviation, lower, upper), --plot the heat map")
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
