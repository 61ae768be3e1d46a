"""Pieces shared by the subcommands: progress messages, scale ranges, tables, errors."""

from __future__ import annotations

import argparse
import sys
import time

import pandas as pd

from avar._escape import terminal as printable
from avar._validation import check_freq, short_repr
from avar._vocabulary import REMOVED_IN, complement
from avar.fit.report.noise_terms import ACCEL, GYRO, UNIT_SPELLINGS, check_unit
from avar.io.read import InputFileError

__all__ = ["FLOAT_FORMAT", "InputFileError", "Progress", "UsageError", "accel_unit", "add_confidence_arguments",
           "add_rate_arguments", "add_unit_arguments", "confidence_alpha", "confidence_level", "display",
           "format_table", "gyro_unit", "parse_scales", "printable", "replicates", "resolve_aliases", "seed_number",
           "unit_label", "variables_note", "whole_number"]

FLOAT_FORMAT = "{:.6g}".format


class Progress:
    """Stage messages on stderr, only when it is a terminal."""

    def __init__(self, enabled: bool | None = None) -> None:
        self.enabled = sys.stderr.isatty() if enabled is None else enabled
        self.started = time.perf_counter()

    def __call__(self, message: str) -> None:
        if self.enabled:
            print(f"[{time.perf_counter() - self.started:6.1f} s] {printable(message)}", file=sys.stderr, flush=True)


#: Most scale numbers a comma-separated ``--wn`` list may expand to (a single range stays lazy).
MAX_LISTED_SCALES = 1_000_000


def parse_scales(text: str) -> range | list[int]:
    """``"1:7"`` -> 1..7 (inclusive, as in R), ``"1,3,5"``, ``"4"``.

    The ends of a range are checked before it is expanded: one range is returned
    as a ``range`` (checked against the number of levels without expansion).

    >>> parse_scales("2:4"), parse_scales("1,3"), parse_scales("6")
    (range(2, 5), [1, 3], [6])
    """
    parts = [part.strip() for part in text.split(",")]
    pieces: list[range] = []
    for part in parts:
        try:
            low, high = (int(v) for v in part.split(":")) if ":" in part else (int(part), int(part))
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"invalid scale selection {short_repr(text)}; use e.g. 1:7, 3 or 1,2,5 (1-based scale numbers)"
            ) from None
        if low > high:
            raise argparse.ArgumentTypeError(f"invalid scale range {short_repr(part)}: {low} > {high}")
        if low < 1:
            raise argparse.ArgumentTypeError(
                f"invalid scale {low} in {short_repr(text)}: scale numbers start at 1 (e.g. 1:7)"
            )
        pieces.append(range(low, high + 1))
    if len(pieces) == 1 and ":" in parts[0]:
        return pieces[0]
    total = sum(len(piece) for piece in pieces)
    if total > MAX_LISTED_SCALES:
        raise argparse.ArgumentTypeError(
            f"scale selection {short_repr(text)} lists {total} scales, more than {MAX_LISTED_SCALES:,}; "
            "an Allan variance has far fewer levels"
        )
    return [scale for piece in pieces for scale in piece]


#: Files whose variables (keys) become the columns: the note says which became time and which data.
ARCHIVE_SUFFIXES = (".mat", ".npz")


def variables_note(path: str, data) -> str | None:
    """``log.mat: time from variable 'time'; data from 'gx', 'gy'`` for a ``.mat``/``.npz`` file of several
    variables (None for other files), so that the choice the reader made is never silent."""
    if not str(path).lower().endswith(ARCHIVE_SUFFIXES) or not hasattr(data, "columns"):
        return None
    names = list(data.columns)
    if len(names) + (data.time_column is not None) < 2:
        return None
    time = f"time from variable {data.time_column!r}" if data.time_column else "no time variable"
    shown = ", ".join(repr(name) for name in names[:8]) + (f" and {len(names) - 8} more" if len(names) > 8 else "")
    return f"{path}: {time}; data from {shown}"


#: Longest name or text cell shown in a printed table (the CSV output keeps it whole).
CELL_LIMIT = 60


def _cell(value: object) -> object:
    if not isinstance(value, str):
        return value
    text = printable(value)
    return text if len(text) <= CELL_LIMIT else f"{text[:CELL_LIMIT - 3]}..."


def display(text: object, limit: int = 200) -> str:
    """``repr(text)`` for a message, cut to about ``limit`` characters with the full length said."""
    shown = repr(str(text))
    if len(shown) <= limit:
        return shown
    return f"{shown[:limit]}... ({len(str(text))} characters)"


def format_table(frame: pd.DataFrame, index: bool = False) -> str:
    """The table as text for a terminal (names and text cells with control characters escaped)."""
    frame = frame.rename(columns=_cell)
    for name in frame.columns:
        if frame[name].dtype.kind in "OSU" or str(frame[name].dtype) == "str":
            frame[name] = frame[name].map(_cell)
    return frame.to_string(index=index, float_format=FLOAT_FORMAT)


def _probability(text: str, expected: str) -> float:
    """``text`` as a number strictly between 0 and 1, else a usage error saying what was ``expected``."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError(f"expected {expected}, got {short_repr(text)}")
    return value


def confidence_level(text: str) -> float:
    """``--confidence``: a probability strictly between 0 and 1 (0.95 for 95 % intervals)."""
    return _probability(text, "a confidence level, a number in (0, 1) such as 0.95")


def _unit_type(kind: str, option: str):
    def unit(text: str) -> str:
        try:
            return check_unit(text, kind, option)
        except (TypeError, ValueError):
            raise argparse.ArgumentTypeError(f"expected a {kind.lower()} unit: {', '.join(UNIT_SPELLINGS[kind])} "
                                             f"(any case), got {short_repr(text)}") from None

    unit.__name__ = option.strip("-").replace("-", "_")
    unit.__doc__ = f"``{option}``: a {kind.lower()} data unit, in its canonical spelling."
    return unit


#: ``--gyro-units`` / ``--accel-units``: the unit spellings Python's ``gyro_units=`` / ``accel_units=`` take.
gyro_unit = _unit_type(GYRO, "--gyro-units")
accel_unit = _unit_type(ACCEL, "--accel-units")


def unit_label(unit: str, deviation: bool) -> str:
    """The y label of a figure of data in ``unit``: ``Allan deviation [deg/s]``, ``Allan variance [(g)^2]``."""
    return f"Allan deviation [{unit}]" if deviation else f"Allan variance [({unit})^2]"


def add_rate_arguments(parser: argparse.ArgumentParser, default: str) -> None:
    """``--rate HZ`` and its hidden alias ``--freq`` (R's name)."""
    parser.add_argument("--rate", type=float, metavar="HZ", default=None,
                        help=f"sampling rate in Hz (default: {default})")
    parser.add_argument("--freq", type=float, metavar="HZ", default=None, help=argparse.SUPPRESS)


def add_confidence_arguments(parser: argparse.ArgumentParser, default: float, what: str,
                             deprecated_alpha: bool = False, default_text: str | None = None) -> None:
    """``--confidence P`` (a probability; ``default`` when not given) and, for the subcommands that had it,
    the hidden deprecated ``--alpha`` (1 - P)."""
    parser.add_argument("--confidence", type=confidence_level, metavar="P", default=None,
                        help=f"confidence level of {what}, a probability in (0, 1) "
                             f"(default {default_text or format(default, 'g')})")
    parser.set_defaults(confidence_default=default)
    if deprecated_alpha:
        parser.add_argument("--alpha", type=confidence_alpha, default=None, help=argparse.SUPPRESS)


def add_unit_arguments(parser: argparse.ArgumentParser, series: str) -> None:
    """``--gyro-units`` and ``--accel-units``, the spellings of Python's ``gyro_units=`` and ``accel_units=``."""
    parser.add_argument("--gyro-units", type=gyro_unit, metavar="UNIT",
                        help=f"unit of the gyroscope data: {', '.join(UNIT_SPELLINGS[GYRO])} (default: rad/s, "
                             f"{series})")
    parser.add_argument("--accel-units", type=accel_unit, metavar="UNIT",
                        help=f"unit of the accelerometer data: {', '.join(UNIT_SPELLINGS[ACCEL])} (default: m/s^2, "
                             f"{series})")


def resolve_aliases(args: argparse.Namespace) -> list[str]:
    """Fold the aliases of the parsed options into their names; the notes to print on stderr.

    ``--freq`` becomes ``--rate`` (``args.rate_option`` says which was typed; the value is
    checked under that name), ``--alpha A`` (deprecated) becomes ``--confidence 1 - A``, and
    ``--confidence`` takes its subcommand's default when neither is given. Both spellings
    of one option: a UsageError naming both.
    """
    notes = []
    if hasattr(args, "rate"):
        freq = getattr(args, "freq", None)
        args.rate_option = "--rate"
        if freq is not None:
            if args.rate is not None:
                raise UsageError("give --rate or its alias --freq, not both")
            args.rate, args.rate_option = freq, "--freq"
        if args.rate is not None:
            try:
                args.rate = check_freq(args.rate, args.rate_option)
            except ValueError as error:
                raise UsageError(str(error)) from None
    if hasattr(args, "freq"):
        del args.freq
    if hasattr(args, "confidence"):
        alpha = getattr(args, "alpha", None)
        if alpha is not None:
            if args.confidence is not None:
                raise UsageError("give --confidence or the deprecated --alpha (1 - confidence), not both")
            args.confidence = complement(alpha)
            if not args.confidence < 1.0:
                raise UsageError(f"--alpha {alpha!r} is too small: 1 - alpha rounds to 1; give --confidence")
            notes.append(f"--alpha is deprecated and will be removed in avar {REMOVED_IN}; "
                         f"use --confidence {args.confidence:g} (confidence = 1 - alpha)")
        if args.confidence is None:
            args.confidence = args.confidence_default
    if hasattr(args, "alpha"):
        del args.alpha
    return notes


def confidence_alpha(text: str) -> float:
    """``--alpha`` (deprecated): 1 - the confidence level, a number strictly between 0 and 1."""
    return _probability(text, "1 - the confidence level, a number in (0, 1) such as 0.05")


def whole_number(minimum: int, what: str = ""):
    """An argparse ``type``: a whole number >= ``minimum``, refused with one line naming ``what`` it counts.

    >>> whole_number(1, "workers")("3")
    3
    """
    label = f"a whole number of {what} >= {minimum}" if what else f"a whole number >= {minimum}"

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = minimum - 1
        if value < minimum:
            raise argparse.ArgumentTypeError(f"expected {label}, got {short_repr(text)}")
        return value

    return parse


#: ``--seed``: a whole number >= 0.
seed_number = whole_number(0)


def replicates(text: str) -> int:
    """``--B``: a whole number (its range is checked by the fit, which names the limit)."""
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number of replicates, got {short_repr(text)}") from None


class UsageError(Exception):
    """Options that do not go together (exit code 2, like argparse's own errors)."""


class Parser(argparse.ArgumentParser):
    """argparse with one-line usage errors (exit code 2)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")
