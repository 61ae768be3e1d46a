"""The text of a clock log, and its whitespace-separated records as cells, with their file lines.

* :func:`load_text`: a file's lines (gzip, bzip2 and xz decompressed, found by their first bytes);
* :func:`split_fields`: the chosen lines split on whitespace by pandas' C parser into named cells of
  text, each row with its file line; a line with too few fields is an error naming it;
* :func:`numbers`: a field as float64, a cell that is not a number an error naming its line;
* :func:`pick_source`: the one source of a file that interleaves several.

Errors are :class:`~avar.io.clocks.result.ClockLogError` with one line: the file, the line number,
the field and what is wrong.
"""

from __future__ import annotations

import csv
import io
import re
from collections.abc import Collection, Sequence
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from avar.io.clocks.result import ClockLogError
from avar.io.streams import open_bytes

#: Fields a line may hold beyond the ones a format documents (newer versions add columns at the end).
EXTRA_FIELDS = 4
_EXPECTED = re.compile(r"Expected (\d+) fields in line (\d+), saw (\d+)")


class Text(NamedTuple):
    """A log's lines (without line ends) and whether the last one is unfinished (no line end)."""

    path: Path
    lines: list[str]
    unfinished: bool


class Table(NamedTuple):
    """Cells of text named by field (missing trailing fields are NaN), each row's file line (1-based),
    and whether an unfinished last line (too short, without a line end: a log being written) was left out."""

    cells: pd.DataFrame
    lines: np.ndarray
    unfinished: bool = False


def clip(value: Any, limit: int = 40) -> str:
    """``repr`` of a cell, cut to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else f"{text[:limit]}..."


def is_number(token: str) -> bool:
    """Whether ``token`` reads as a float (``"1e-9"``, ``"-3"``; not ``"N"`` nor ``"127.0.0.1"``)."""
    try:
        float(token)
    except ValueError:
        return False
    return True


def fail(path: Path, line: int | None, message: str) -> ClockLogError:
    """The one-line error: ``"tracking.log, line 7: field 'Offset' is not a number: '1.2x'"``."""
    return ClockLogError(f"{path}{'' if line is None else f', line {line}'}: {message}")


def load_text(path: Any) -> Text:
    """The lines of the file ``path`` (decompressed; UTF-8, undecodable bytes replaced).

    Raises
    ------
    ClockLogError
        The file is missing, a directory, empty or not text (a NUL byte).
    """
    path = Path(path)
    if not path.is_file():
        raise fail(path, None, "no such file" if not path.exists() else "not a regular file")
    try:
        with open_bytes(path) as handle:
            data = handle.read()
    except (OSError, EOFError) as error:
        raise fail(path, None, f"cannot be read: {error}") from None
    if b"\0" in data[:65536]:
        raise fail(path, None, "is not a text log (it holds NUL bytes)")
    text = data.decode("utf-8-sig", errors="replace")
    if not text.strip():
        raise fail(path, None, "is empty")
    lines = text.splitlines()
    return Text(path, lines, not text.endswith(("\n", "\r")))


def _read(body: str, labels: list[str], numeric: Collection[str]) -> pd.DataFrame:
    """Whitespace-separated cells by pandas' C parser: ``numeric`` fields as float64 (a cell that
    is not a number raises ValueError), the others as text; an absent field is NaN."""
    dtypes = {label: (np.float64 if label in numeric else object) for label in labels}
    return pd.read_csv(io.StringIO(body), sep=r"\s+", header=None, names=labels, dtype=dtypes, engine="c",
                       quoting=csv.QUOTE_NONE, keep_default_na=False, na_values=[""], skip_blank_lines=False)


def _first_bad_cell(body: str, labels: list[str], numeric: Collection[str], rows: np.ndarray, text: Text,
                    what: str) -> ClockLogError:
    """The error naming the first cell of a ``numeric`` field that is not a number (the slow path)."""
    cells = _read(body, labels, ())
    for name in (label for label in labels if label in numeric):
        values = pd.to_numeric(cells[name], errors="coerce").to_numpy(dtype=np.float64)
        bad = np.flatnonzero(np.isnan(values) & cells[name].notna().to_numpy())
        if bad.size:
            i = int(bad[0])
            more = f" ({bad.size - 1} more such line(s))" if bad.size > 1 else ""
            return fail(text.path, int(rows[i]) + 1,
                        f"field '{name}' is not a number: {clip(cells[name].iloc[i])}{more}")
    return fail(text.path, None, f"a {what} field cannot be read as a number")  # pragma: no cover


def split_fields(text: Text, rows: Sequence[int] | np.ndarray, names: Sequence[str], required: int,
                 what: str, numeric: Collection[str] = ()) -> Table:
    """The lines ``rows`` (0-based) of ``text`` split on whitespace into cells named ``names``.

    The ``numeric`` fields are float64 (parsed by pandas' C parser, never cell by cell in Python);
    a cell of one that is not a number is an error naming its line and field. Up to
    :data:`EXTRA_FIELDS` fields beyond ``names`` are kept as text, named ``"field N"``. A line with
    fewer than ``required`` fields, or with more than the names and extras, is an error naming
    its file line and the first missing field; except the file's last line when it has no line
    end (a log still being written), which is left out (``Table.unfinished``).
    """
    rows = np.asarray(rows, dtype=np.int64)
    unfinished = bool(text.unfinished and rows.size and rows[-1] == len(text.lines) - 1
                      and len(text.lines[-1].split()) < required)
    if unfinished:
        rows = rows[:-1]
    width = len(names) + EXTRA_FIELDS
    labels = [*names, *(f"field {k}" for k in range(len(names) + 1, width + 1))]
    if rows.size == 0:
        return Table(pd.DataFrame(columns=labels, dtype=object), rows + 1, unfinished)
    body = "\n".join(text.lines[i] for i in rows)
    try:
        cells = _read(body, labels, numeric)
    except pd.errors.ParserError as error:
        match = _EXPECTED.search(str(error))
        if match is None:  # pragma: no cover - pandas words its other errors differently
            raise fail(text.path, None, f"{what} cannot be split into fields: {error}") from None
        line = int(rows[int(match[2]) - 1]) + 1
        raise fail(text.path, line, f"{match[3]} fields, more than the {width} a {what} line may hold") from None
    except ValueError:
        raise _first_bad_cell(body, labels, numeric, rows, text, what) from None
    present = cells.notna().to_numpy()
    counts = present.sum(axis=1)
    short = np.flatnonzero(counts < required)
    if short.size:
        i = int(short[0])
        missing = names[int(counts[i])]
        raise fail(text.path, int(rows[i]) + 1, f"{int(counts[i])} fields where a {what} line has at least "
                                                f"{required}: field '{missing}' is missing")
    extras = [label for label in labels[len(names):] if present[:, labels.index(label)].any()]
    return Table(cells[[*names, *extras]], rows + 1, unfinished)


def numbers(table: Table, name: str, path: Path, optional: bool = False) -> np.ndarray:
    """Field ``name`` of ``table`` as float64; a cell that is not a number is an error naming its line.

    An absent cell (a line without the field) is NaN when ``optional``, else an error; an
    infinite value is an error.
    """
    cells = table.cells[name]
    if cells.dtype == np.float64:
        values, present = cells.to_numpy(), np.zeros(len(cells), dtype=bool)
    else:
        values = pd.to_numeric(cells, errors="coerce").to_numpy(dtype=np.float64)
        present = cells.notna().to_numpy()
    bad = np.isinf(values) | (np.isnan(values) & (present | (not optional)))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        cell = cells.iloc[i]
        problem = "is missing" if pd.isna(cell) else f"is not a number: {clip(cell)}"
        others = int(bad.sum()) - 1
        raise fail(path, int(table.lines[i]), f"field '{name}' {problem}"
                                              f"{f' ({others} more such line(s))' if others else ''}")
    return values


class Source(NamedTuple):
    """One source of a file that interleaves several (:func:`pick_source`)."""

    #: The rows of the source taken (bool, one per row).
    rows: np.ndarray
    #: ``"203.0.113.15 (the most frequent of 2 sources: 6 of 9 records)"`` or ``"... (asked for ...)"``.
    selected: str
    #: Each source's row count, in order of first appearance.
    available: dict[str, int]


def pick_source(keys: np.ndarray, wanted: Any, what: str, path: Path, argument: str = "source") -> Source:
    """The :class:`Source`: the rows of one source among ``keys`` (a source per row), its name and
    every source's count.

    ``wanted`` is a source's name (or a word of it, when that names one source only); None takes
    the source with the most rows (the first in the file on a tie).

    Examples
    --------
    >>> from pathlib import Path
    >>> source = pick_source(np.array(["a", "b", "b"]), None, "peer", Path("peers.log"))
    >>> source.rows.tolist(), source.selected, source.available
    ([False, True, True], 'b (the most frequent of 2 peers: 2 of 3 records; others: a)', {'a': 1, 'b': 2})
    """
    codes, names = pd.factorize(pd.Series(keys, dtype=object))  # in order of first appearance
    available = {str(name): int(count) for name, count in zip(names, np.bincount(codes, minlength=len(names)))}
    if not available:
        raise fail(path, None, f"holds no {what} records")
    listing = ", ".join(f"{name} ({count})" for name, count in available.items())
    if wanted is None:
        name = max(available, key=available.get)  # the first of the largest: dicts keep file order
        reason = f"the only {what}" if len(available) == 1 else (
            f"the most frequent of {len(available)} {what}s: {available[name]} of {len(keys)} records; "
            f"others: {', '.join(k for k in available if k != name)}")
    else:
        wanted = str(wanted).strip()
        matches = [k for k in available if k.lower() == wanted.lower()] or \
                  [k for k in available if wanted.lower() in k.lower().split()]
        if len(matches) != 1:
            raise fail(path, None, f"{argument}={wanted!r} {'names no' if not matches else 'names more than one'} "
                                   f"{what} of the file; it holds {listing}")
        name = matches[0]
        reason = f"asked for: {available[name]} of {len(keys)} records" + (
            f"; others: {', '.join(k for k in available if k != name)}" if len(available) > 1 else "")
    return Source(codes == list(available).index(name), f"{name} ({reason})", available)
