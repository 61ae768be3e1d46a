"""Text tables: CSV, TSV, semicolon (decimal commas), whitespace-separated columns.

The layout is sniffed from the first lines (a UTF-8 byte-order mark is not data); the
numbers are parsed by pandas' C engine in one pass, never cell by cell in Python:

* the separator: ``;``, tab, ``,`` or runs of whitespace;
* the header: a first line that is not all numbers, or a ``#`` comment line just before
  the data with one name per column (``# time gx gy``, as ``numpy.savetxt`` writes);
  without one, columns are ``x`` (one column) or ``x1, x2, ...``;
* decimal commas (``0,5``) when the separator is not a comma;
* a trailing separator on every line adds no column;
* a gzip, bzip2 or xz compressed file (``log.csv.gz``) is read as its text, found by its
  first bytes, decompressed as it streams (never whole in memory);
* blank and ``#`` comment lines before the data are counted, never kept (any number of them);
  the parser reads up to the last line holding anything; a last line without a line end (a file
  still being written) is left out with a warning, NUL bytes are an error naming their line, and
  the columns' memory is checked before they are allocated (:mod:`avar.io.streams`).

Integer columns stay int64, exact even beyond 2**53. Cells that are not numbers are
reported with their row and line (clipped to a readable length).
"""

from __future__ import annotations

import codecs
import csv
import io
import re
import warnings
from pathlib import Path
from typing import BinaryIO, NamedTuple

import numpy as np
import pandas as pd

from avar.io.streams import (
    MAX_LINE_CHARS,
    Snapshot,
    check_memory,
    count_preamble,
    line_too_long,
    measure,
    open_bytes,
    open_text_bytes,
)

#: Characters sniffed for the layout (the header and first data line are always read whole).
SNIFF_BYTES = 1 << 16
#: Longest excerpt of a cell or line quoted in a message.
QUOTE_LIMIT = 200
_NUMBER = re.compile(r"[-+]?(\d+([.,]\d*)?|[.,]\d+)([eE][-+]?\d+)?|[-+]?(nan|inf|infinity)", re.I)
_DECIMAL_COMMA = re.compile(r"\d,\d")


def clip(value: object, limit: int = QUOTE_LIMIT) -> str:
    """``repr(value)``, cut to about ``limit`` characters with the full length said."""
    text = repr(value)
    if len(text) <= limit:
        return text
    length = len(value) if isinstance(value, (str, list, tuple)) else len(text)
    return f"{text[:limit]}... ({length} {'characters' if isinstance(value, str) else 'items'})"


class Layout:
    """What the first lines of a text table say about it."""

    def __init__(
        self, separator: str, decimal: str, names: list[str], header_row: bool, skip: int, trailing: bool = False,
        encoding: str = "utf-8-sig",
    ) -> None:
        self.encoding = encoding  # "utf-8-sig", or UTF-16/32 found by detect_encoding
        self.separator = separator  # ";", "\t", ",", or r"\s+"
        self.trailing = trailing  # whether lines end with a separator (an empty last field)
        self.decimal = decimal
        self.names = names  # column names when they are not read from a header row
        self.header_row = header_row  # whether pandas reads the names from the first line after `skip`
        self.skip = skip  # lines before the header row (or the first data row)

    @property
    def first_data_line(self) -> int:
        """1-based file line of the first data row."""
        return self.skip + (2 if self.header_row else 1)


def _split(line: str, separator: str) -> list[str]:
    if separator == r"\s+":
        return line.split()
    return [token.strip() for token in next(csv.reader([line], delimiter=separator))]


def _is_number(token: str) -> bool:
    return bool(_NUMBER.fullmatch(token.strip().strip('"')))


def detect_encoding(path: Path) -> str:
    """The text encoding of ``path``: from its byte-order mark, or UTF-16/32 recognised without one
    by the zero bytes of ASCII text; else UTF-8 (a UTF-8 byte-order mark skipped)."""
    with open_bytes(path) as handle:
        head = handle.read(4096)
    if head.startswith((codecs.BOM_UTF32_LE, codecs.BOM_UTF32_BE)):
        return "utf-32"
    if head.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        return "utf-16"
    size = len(head) - len(head) % 4
    if size >= 4 and head.count(0, 0, size) >= size // 2:
        zeros = [head[i:size:4].count(0) for i in range(4)]
        quarter = size // 4
        if zeros[1] == zeros[2] == zeros[3] == quarter and zeros[0] < quarter:
            return "utf-32-le"
        if zeros[0] == zeros[1] == zeros[2] == quarter and zeros[3] < quarter:
            return "utf-32-be"
        if zeros[1] + zeros[3] == 2 * quarter and zeros[0] + zeros[2] < 2 * quarter:
            return "utf-16-le"
        if zeros[0] + zeros[2] == 2 * quarter and zeros[1] + zeros[3] < 2 * quarter:
            return "utf-16-be"
        raise ValueError(f"{path}: not a text table (binary data: {head.count(0)} zero bytes in the first "
                         f"{len(head)}); give a CSV/text file in UTF-8, UTF-16 or UTF-32 (gzip/bzip2/xz compressed or not), or a "
                         ".npy/.npz array")
    return "utf-8-sig"


class Head(NamedTuple):
    """The start of a text table, as :func:`sniff` reads it."""

    skip: int  # blank and ``#`` comment lines before the first data line: counted, never kept
    comment: str | None  # the last of those comment lines, without its ``#`` (a header candidate)
    lines: list[str]  # the first data line and the lines after it, up to SNIFF_BYTES (two whatever their length)


def _head(path: Path, encoding: str) -> Head:
    """The first lines of the file: the blank and comment lines before the data counted (never kept),
    the first two data lines whatever their length (a 10,000-column header is read whole), then more
    up to :data:`SNIFF_BYTES`."""
    lines: list[str] = []
    total = content = 0
    with open_bytes(path) as raw, io.TextIOWrapper(raw, encoding=encoding, errors="replace", newline="") as handle:
        skip, comment, rest = count_preamble(handle, path)
        buffered = io.StringIO(rest, newline="")
        while True:
            line = buffered.readline() or handle.readline(MAX_LINE_CHARS + 1)
            if line and not line.endswith(("\n", "\r")):
                line += handle.readline(MAX_LINE_CHARS + 1)  # a line cut by the end of a block
            if not line:
                break
            if len(line) > MAX_LINE_CHARS and not line.endswith(("\n", "\r")):
                raise line_too_long(path, skip + len(lines) + 1)
            lines.append(line.rstrip("\r\n"))
            total += len(line)
            if line.strip() and not line.lstrip().startswith("#"):
                content += 1
            if content >= 2 and total >= SNIFF_BYTES:
                break
    return Head(skip, comment, lines)


def sniff(path: Path, encoding: str = "utf-8-sig") -> Layout:
    """The separator, decimal mark and header of a text table, from its first lines."""
    skip, comment, lines = _head(path, encoding)
    if not lines:
        raise ValueError(f"the file holds no data (only blank or # comment lines: {skip:,})")
    first = lines[0]
    if ";" in first:
        separator = ";"
    elif "\t" in first:
        separator = "\t"
    elif "," in first and not re.fullmatch(r"\s*[-+]?\d+,\d+([eE][-+]?\d+)?(\s+[-+]?\d+,\d+([eE][-+]?\d+)?)+\s*", first):
        separator = ","
    else:
        separator = r"\s+"
    data_lines = "\n".join(lines)
    decimal = "," if separator != "," and _DECIMAL_COMMA.search(data_lines) else "."
    tokens = _split(first, separator)
    trailing = len(tokens) > 1 and tokens[-1] == "" and separator != r"\s+"
    if trailing:
        tokens.pop()  # a separator at the end of the line
    if all(_is_number(token) for token in tokens if token):
        names = None
        if comment is not None:
            candidate = _split(comment, separator)
            if len(candidate) == len(tokens) and not all(_is_number(token) for token in candidate):
                names = candidate  # "# time gx gy" written by numpy.savetxt
        if names is None:
            names = [f"x{i + 1}" for i in range(len(tokens))] if len(tokens) > 1 else ["x"]
        return Layout(separator, decimal, names, header_row=False, skip=skip, trailing=trailing, encoding=encoding)
    names = [token.strip('"') for token in tokens]
    return Layout(separator, decimal, names, header_row=True, skip=skip, trailing=trailing, encoding=encoding)


def _check_names(names: list[str], path: Path) -> list[str]:
    names = [str(name).strip() for name in names]
    empty = [i + 1 for i, name in enumerate(names) if not name]
    if empty:
        raise ValueError(f"{path}: column(s) {clip(empty)} of the header have no name; name every column")
    counts: dict[str, int] = {}
    for name in names:
        counts[name] = counts.get(name, 0) + 1
    seen = sorted(name for name, count in counts.items() if count > 1)
    if seen:
        raise ValueError(f"{path}: duplicate column names {clip(seen)} in the header; names must be distinct")
    return names


#: Rows parsed per chunk: the columns are filled chunk by chunk into arrays sized once, so the
#: peak memory is the columns plus one chunk (pandas alone holds the table about three times).
CHUNK_ROWS = 1 << 18


def _column_arrays(chunk: pd.DataFrame):
    """(name, array) of every column; the numeric columns of one dtype in one pass (a 10**6-column
    table would spend minutes in a per-column lookup)."""
    dtypes = chunk.dtypes.to_numpy()
    numeric = np.array([getattr(dtype, "kind", "O") in "iuf" for dtype in dtypes], dtype=bool)
    for dtype in {dtype for dtype, keep in zip(dtypes, numeric) if keep}:
        chosen = np.flatnonzero(numeric & (dtypes == dtype))
        block = chunk.iloc[:, chosen].to_numpy(dtype=dtype)
        yield from zip(chunk.columns[chosen], block.T)
    for j in np.flatnonzero(~numeric):
        yield chunk.columns[j], chunk.iloc[:, j].to_numpy()


class _Columns:
    """Column arrays allocated once and filled chunk by chunk; a column's type widens if a chunk needs it.

    int64 stays int64 (exact); ints and floats widen to float64; a chunk of text (decimal
    commas, date-times, a bad cell) turns the column into an object array for
    :func:`numeric_column` to convert or report.
    """

    def __init__(self, capacity: int) -> None:
        self.capacity = max(capacity, 1)
        self.arrays: dict[str, np.ndarray] = {}
        self.n = 0

    @staticmethod
    def _kind(values: np.ndarray) -> str:
        return values.dtype.kind if values.dtype.kind in "iuf" else "O"

    def add(self, chunk: pd.DataFrame) -> None:
        rows = len(chunk)
        if self.n + rows > self.capacity:  # more rows than newlines counted (e.g. a file still growing)
            self.capacity = max(2 * self.capacity, self.n + rows)
            for name, array in self.arrays.items():
                grown = np.empty(self.capacity, dtype=array.dtype)
                grown[: self.n] = array[: self.n]
                self.arrays[name] = grown
        arrays = dict(_column_arrays(chunk))
        for name in chunk.columns:  # in the file's order
            values = arrays[name]
            kind = self._kind(values)
            target = self.arrays.get(name)
            if target is None:
                dtype = {"i": np.int64, "u": np.uint64, "f": np.float64, "O": object}[kind]
                target = self.arrays[name] = np.empty(self.capacity, dtype=dtype)
            elif kind != self._kind(target):
                wider = object if "O" in (kind, self._kind(target)) else np.float64
                if target.dtype != wider:
                    target = self.arrays[name] = target.astype(wider)
            target[self.n : self.n + rows] = values
        self.n += rows

    def finish(self) -> dict[str, np.ndarray]:
        """The filled rows, without the blank lines that end the file."""
        arrays = {name: array[: self.n] for name, array in self.arrays.items()}
        last = self.n
        window = 4096
        while last > 0:
            start = max(0, last - window)
            filled = np.zeros(last - start, dtype=bool)
            for array in arrays.values():
                filled |= ~pd.isna(array[start:last])
            if filled.any():
                last = start + int(np.flatnonzero(filled)[-1]) + 1
                break
            last, window = start, window * 4
        return {name: array[:last] for name, array in arrays.items()}


class Table(NamedTuple):
    """A text table as read (:func:`read_columns`)."""

    #: Every column by name: numbers where they parse, else text.
    columns: dict[str, np.ndarray]
    #: How the file is laid out (separator, decimal mark, header, comment lines ...).
    layout: Layout


def read_columns(path: Path, raw: BinaryIO | None = None) -> Table:
    """The :class:`Table` of the file's columns as arrays (numbers where they parse, else text), and its layout.

    ``raw`` (the opened file, e.g. counted by a progress bar) is parsed instead of ``path`` when
    given. The parser gets the text as UTF-8 from the first line after the comments on (the
    preamble is skipped as bytes: pandas would hold a set of the lines it skips).
    """
    layout = sniff(path, detect_encoding(path))
    names = _check_names(layout.names, path)
    extra = "\0trailing separator"
    extent = measure(path, layout.encoding, layout.skip)
    if extent.nul_line is not None:
        raise ValueError(f"{path}: line {extent.nul_line:,} holds NUL bytes (\\0), not text: the end of a file cut "
                         f"short (a crash while writing, a preallocated file); cut the file before line "
                         f"{extent.nul_line:,}")
    if extent.cut_line is not None and extent.cut_line >= layout.first_data_line:
        warnings.warn(f"{path}: the last line (line {extent.cut_line:,}) has no line end, as in a file still being "
                      f"written; read up to line {extent.cut_line - 1:,}, its last complete line", stacklevel=4)
    rows = max(extent.lines + 1 - layout.skip, 1)
    check_memory(path, 8 * rows * len(names), f"{rows:,} rows x {len(names):,} column(s)")
    columns = _Columns(rows)
    try:
        with warnings.catch_warnings():
            # A column whose blocks parse to different types is object here; numeric_column then
            # parses it or names its first non-number, so pandas' DtypeWarning would only be noise.
            warnings.simplefilter("ignore", pd.errors.DtypeWarning)
            with open_text_bytes(path, layout.encoding, raw) as source:
                snapshot = io.BufferedReader(Snapshot(source, extent.start, extent.end), buffer_size=1 << 20)
                _read_chunks(snapshot, layout, names, extra, columns, path)  # the bytes measure saw
    except pd.errors.EmptyDataError:
        raise ValueError(f"{path}: the file holds a header but no data") from None
    except pd.errors.ParserWarning:
        raise ValueError(f"{path}: a line holds more values than the header's {len(names)} columns; every line "
                         "must have the same number of columns") from None
    except (pd.errors.ParserError, UnicodeDecodeError) as error:
        message = clip(str(error).splitlines()[0] if str(error) else type(error).__name__)
        raise ValueError(f"{path}: not a readable CSV/text table ({message})") from None
    if not columns.arrays:
        raise ValueError(f"{path}: the file holds a header but no data")
    return Table(columns.finish(), layout)


def _read_chunks(source, layout: Layout, names: list[str], extra: str, columns: _Columns, path: Path) -> None:
    """Parse the table with pandas' C engine, chunk by chunk, into ``columns``."""
    with pd.read_csv(
        source,
        sep=layout.separator,
        decimal=layout.decimal,
        header=None,
        names=[*names, extra] if layout.trailing else names,
        skiprows=1 if layout.header_row else 0,  # the source starts after the comment lines
        index_col=False,
        engine="c",
        encoding="utf-8-sig" if layout.encoding == "utf-8-sig" else "utf-8",  # transcoded by open_text_bytes
        skip_blank_lines=False,  # a blank line inside the data is a missing sample, not nothing
        quotechar='"',
        chunksize=CHUNK_ROWS,
    ) as chunks, warnings.catch_warnings():
        warnings.simplefilter("error", pd.errors.ParserWarning)  # pandas would drop the extra fields
        for chunk in chunks:
            if layout.trailing:
                spill = chunk[extra].notna().to_numpy()
                if spill.any():
                    row = columns.n + int(np.flatnonzero(spill)[0])
                    raise ValueError(
                        f"{path}: line {row + layout.first_data_line} has a value after the last column "
                        f"({clip(str(chunk[extra].to_numpy()[spill][0]))}); every line must have the "
                        f"header's {len(names)} columns"
                    )
                chunk = chunk.drop(columns=extra)
            columns.add(chunk)


def numeric_column(column: np.ndarray, name: str, layout: Layout, path: Path, gaps: bool = False) -> np.ndarray:
    """A column as float64 or int64 (exact), with the first cell that is not a number named; ``gaps``:
    NaN and empty cells are kept as NaN (``nan_policy="omit"``), else refused."""
    if column.dtype.kind in "iuf":
        values = column
    elif column.dtype.kind == "b":
        raise ValueError(f"{path}: column {name!r} holds true/false values, not numbers")
    else:
        column = pd.Series(column, copy=False)
        text = column.astype("string").str.strip()
        if layout.separator != ",":  # decimal commas that appear only after integer rows
            text = text.str.replace(",", ".", regex=False)
        parsed = pd.to_numeric(text, errors="coerce")
        bad = (parsed.isna() & text.notna()).to_numpy()
        if bad.any():
            row = int(np.flatnonzero(bad)[0])
            cell = str(column.iloc[row])
            what = "a number beyond the float64 range" if _is_number(cell) else clip(cell)
            raise ValueError(
                f"{path}: column {name!r} is not numeric: row {row + 1} (line {row + layout.first_data_line}) "
                f"holds {what}{f' ({clip(cell, 40)})' if _is_number(cell) else ''}"
            )
        values = parsed.to_numpy(dtype=np.float64, na_value=np.nan)
    if values.dtype.kind == "f":
        missing = np.isinf(values) if gaps else ~np.isfinite(values)  # gaps: NaN and empty cells are kept
        if missing.any():
            row = int(np.flatnonzero(missing)[0])
            raise ValueError(
                f"{path}: column {name!r} has {int(missing.sum())} {'infinite' if gaps else 'missing or non-finite'} "
                f"value(s); the first is in row {row + 1} (line {row + layout.first_data_line}); fill or cut them"
                + ("" if gaps else ", or read them as gaps (nan_policy='omit', --nan-policy omit)")
            )
    return values
