"""Pieces shared by the subcommands: progress messages, scale ranges, tables, errors."""

from __future__ import annotations

import argparse
import sys
import time

import pandas as pd

from avar._validation import short_repr
from avar.io.read import InputFileError

__all__ = ["FLOAT_FORMAT", "InputFileError", "Progress", "UsageError", "format_table", "parse_scales"]

FLOAT_FORMAT = "{:.6g}".format


class Progress:
    """Stage messages on stderr, only when it is a terminal."""

    def __init__(self, enabled: bool | None = None) -> None:
        self.enabled = sys.stderr.isatty() if enabled is None else enabled
        self.started = time.perf_counter()

    def __call__(self, message: str) -> None:
        if self.enabled:
            print(f"[{time.perf_counter() - self.started:6.1f} s] {message}", file=sys.stderr, flush=True)


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


def format_table(frame: pd.DataFrame, index: bool = False) -> str:
    return frame.to_string(index=index, float_format=FLOAT_FORMAT)


class UsageError(Exception):
    """Options that do not go together (exit code 2, like argparse's own errors)."""


class Parser(argparse.ArgumentParser):
    """argparse with one-line usage errors (exit code 2)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")
