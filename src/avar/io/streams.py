"""A file's bytes as a reader takes them: decompressed as they stream, measured, bounded.

* :func:`compression_of`, :func:`open_bytes`: gzip, bzip2 and xz, found by their first bytes,
  decompressed as they stream (never whole in memory);
* :func:`count_preamble`: the blank and ``#`` comment lines before a text table's data, counted a
  block at a time (NumPy classifies the lines), never kept: any number of them in bounded memory;
* :func:`measure`: one pass over the (decompressed) bytes of a text file, in blocks: its lines,
  where its last line holding anything ends (blank lines after it are never parsed), a last line
  without a line end (a file still being written: left out), the first NUL byte;
* :func:`open_text_bytes`, :class:`Snapshot`: the text as UTF-8 bytes (UTF-16/32 transcoded as it
  streams), and only the bytes :func:`measure` saw from the first data line on: the parser skips no
  lines itself, and reads the file as it was measured even while it grows;
* :func:`memory_limit`, :func:`check_memory`: the bytes a reader may allocate, checked before it
  allocates: the memory available to this process (``MemAvailable``, a cgroup's or
  ``RLIMIT_AS``/``RLIMIT_DATA``'s room), or ``AVAR_MAX_INPUT_BYTES``; beyond it, one line names
  the file, the size and the limit;
* :func:`progress_enabled`, :class:`CountingReader`: a progress bar on stderr for long reads.
"""

from __future__ import annotations

import bz2
import contextlib
import gzip
import io
import lzma
import os
import re
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any, BinaryIO, NamedTuple

import numpy as np

#: Inputs with more values than this show a progress bar on a terminal.
PROGRESS_VALUES = 10_000_000
#: The environment variable that sets the memory a reader may allocate (bytes; ``8G``, ``512M`` too).
MEMORY_VARIABLE = "AVAR_MAX_INPUT_BYTES"
#: Bytes read at a time by :func:`measure`.
BLOCK_BYTES = 1 << 24
#: Longest line of a text table (characters): a longer one is refused, never cut.
MAX_LINE_CHARS = 1 << 26
#: Characters read at a time while counting the blank and comment lines before the data.
SKIP_CHARS = 1 << 20
#: Blank and ``#`` comment lines, each ended (LF, CR LF or CR); one line end.
_SKIPPABLE = re.compile(r"(?:[^\S\r\n]*(?:#[^\r\n]*)?(?:\r\n?|\n))*")
_LINE_END = re.compile(r"\r\n?|\n")
#: First bytes of the compressed files read as their text.
_COMPRESSED = ((b"\x1f\x8b", gzip), (b"BZh", bz2), (b"\xfd7zXZ\x00", lzma))
_SIZE = re.compile(r"(\d+(?:\.\d*)?(?:[eE]\d+)?)\s*([kKmMgGtT]?)(i?[bB])?")


def compression_of(path: Path):
    """The module (gzip, bz2, lzma) that decompresses ``path``, by its first bytes, else None."""
    with path.open("rb") as handle:
        magic = handle.read(6)
    return next((module for prefix, module in _COMPRESSED if magic.startswith(prefix)), None)


@contextlib.contextmanager
def open_bytes(path: Path, raw: BinaryIO | None = None) -> Iterator[BinaryIO]:
    """The bytes of ``path`` (or of ``raw``, its opened file), decompressed if it is compressed."""
    module = compression_of(path)
    with contextlib.ExitStack() as stack:
        if raw is None:
            raw = stack.enter_context(path.open("rb"))
        yield raw if module is None else stack.enter_context(module.open(raw, "rb"))


def line_too_long(path: Path, line: int) -> ValueError:
    return ValueError(f"{path}: line {line} is longer than {MAX_LINE_CHARS:,} characters; a text table's lines "
                      "must be shorter")


class Preamble(NamedTuple):
    """The blank and ``#`` comment lines before a text table's data, as :func:`count_preamble` finds them."""

    lines: int  # how many (counted, never kept)
    comment: str | None  # the last comment line, without its ``#`` (a header candidate)
    rest: str  # the text read after them: the start of the first data line


def _ascii_skippable(block: str, position: int) -> tuple[int, int, int | None]:
    """Complete lines from ``position`` on that are blank or ``#`` comments by ASCII whitespace, found
    with NumPy (a million one-character lines in milliseconds): their count, the offset past them,
    and the start of the last comment line among them (None)."""
    text = block[position:]
    codes = np.frombuffer(text.encode("ascii") if text.isascii() else text.encode("utf-32-le"),
                          dtype=np.uint8 if text.isascii() else np.uint32)
    ends = (codes == 10) | (codes == 13)
    ends[:-1] &= ~((codes[:-1] == 13) & (codes[1:] == 10))  # CR LF: the LF ends the line
    last_chars = np.flatnonzero(ends)
    marks = np.flatnonzero((codes != 32) & ((codes < 9) | (codes > 13)))  # neither blank nor a line end
    lines = (np.cumsum(ends, dtype=np.int64) - ends)[marks]  # the line of every mark
    leading = np.ones(marks.size, dtype=bool)
    leading[1:] = lines[1:] != lines[:-1]
    firsts, first_lines = marks[leading], lines[leading]  # each marked line's first mark
    hashes = codes[firsts] == 35
    data = first_lines[~hashes]
    n = int(data[0]) if data.size else last_chars.size
    comments = first_lines[hashes & (first_lines < n)]
    last = None if comments.size == 0 else position + (int(last_chars[comments[-1] - 1]) + 1 if comments[-1] else 0)
    return n, position + (int(last_chars[n - 1]) + 1 if n else 0), last


def _comment_text(block: str, position: int, at: int) -> str:
    """The comment of the line of ``block`` holding offset ``at`` (which starts at ``position`` or later)."""
    start = max(block.rfind("\n", position, at), block.rfind("\r", position, at), position - 1) + 1
    return block[start : _LINE_END.search(block, at).start()].lstrip()[1:].strip()


def count_preamble(handle, path: Path) -> Preamble:
    """Count the blank and ``#`` comment lines at the start of the text ``handle``, a block at a time:
    a gigabyte of them takes seconds and no memory (NumPy classifies the lines of a block; a regular
    expression settles the Unicode whitespace NumPy leaves)."""
    skip, comment, partial, length = 0, None, None, 0  # partial: the pieces of a comment line not yet ended
    while block := handle.read(SKIP_CHARS):
        while block.endswith("\r") and (extra := handle.read(1)):  # keep a CR LF together
            block += extra
        position = 0
        if partial is None and block.isspace():  # blank lines only: counted at once
            skip += line_ends(block)
            continue
        if partial is not None:  # the end of a comment line begun in an earlier block
            end = _LINE_END.search(block)
            piece = block if end is None else block[: end.start()]
            length += len(piece)
            if length > MAX_LINE_CHARS:
                raise line_too_long(path, skip + 1)
            partial.append(piece)
            if end is None:
                continue
            skip, comment, partial, position = skip + 1, "".join(partial).lstrip()[1:].strip(), None, end.end()
        counted, stop, last = _ascii_skippable(block, position)
        if last is not None:
            comment = _comment_text(block, position, last)
        matched = _SKIPPABLE.match(block, stop).end()  # lines NumPy left: Unicode whitespace, as str.strip sees it
        skip += counted + line_ends(block, stop, matched)
        if (at := block.rfind("#", stop, matched)) >= 0:
            comment = _comment_text(block, stop, at)
        rest = block[matched:]
        if _LINE_END.search(rest) is None:  # a line that ends in a later block
            if not rest.strip():
                continue  # blank so far: nothing to keep
            if rest.lstrip().startswith("#"):
                partial, length = [rest], len(rest)
                continue
        return Preamble(skip, comment, rest)
    if partial is not None:  # a last comment line without a line end
        skip, comment = skip + 1, "".join(partial).lstrip()[1:].strip()
    return Preamble(skip, comment, "")


class Transcoded(io.RawIOBase):
    """The text of a binary stream in ``encoding`` (UTF-16, UTF-32) as UTF-8 bytes, as it streams."""

    def __init__(self, stream: BinaryIO, encoding: str) -> None:
        super().__init__()
        self.text = io.TextIOWrapper(stream, encoding=encoding, newline="")
        self.pending = b""

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:
        view = memoryview(buffer).cast("B")
        while not self.pending:
            chunk = self.text.read(max(len(view) // 4, 1))
            if not chunk:
                return 0
            self.pending = chunk.encode("utf-8", "surrogatepass")
        n = min(len(view), len(self.pending))
        view[:n], self.pending = self.pending[:n], self.pending[n:]
        return n


@contextlib.contextmanager
def open_text_bytes(path: Path, encoding: str, raw: BinaryIO | None = None) -> Iterator[BinaryIO]:
    """The text of ``path`` (or of ``raw``, its opened file) as UTF-8 bytes: decompressed, and
    transcoded from UTF-16/32 (``encoding`` from :func:`detect_encoding`); a UTF-8 file as it is."""
    with open_bytes(path, raw) as stream:
        if encoding.replace("-", "").lower() in ("utf8", "utf8sig"):
            yield stream
        else:
            yield io.BufferedReader(Transcoded(stream, encoding), buffer_size=1 << 20)


class Extent(NamedTuple):
    """What :func:`measure` found in a text file's bytes (UTF-8, decompressed)."""

    size: int  # bytes
    start: int  # where line ``skip + 1`` starts: the bytes before it are never parsed
    end: int  # bytes to parse: up to the last byte that is not blank, a last line without a line end left out
    lines: int  # lines up to ``end``
    cut_line: int | None  # 1-based line of a last line without a line end (left out), else None
    nul_line: int | None  # 1-based line of the first NUL byte, else None


def line_ends(text: bytes | str, start: int = 0, stop: int | None = None) -> int:
    """Line ends (LF, CR LF, CR) in ``text[start:stop]`` (bytes or str).

    >>> line_ends(b"a\\r\\nb\\rc\\n"), line_ends("a\\r\\nb", 3)
    (3, 0)
    """
    lf, cr, crlf = ("\n", "\r", "\r\n") if isinstance(text, str) else (b"\n", b"\r", b"\r\n")
    return text.count(lf, start, stop) + text.count(cr, start, stop) - text.count(crlf, start, stop)


def _after_line_end(block: bytes, k: int) -> int:
    """The offset just past the ``k``-th (1-based) line end of ``block`` (a CR at its end counts)."""
    codes = np.frombuffer(block, dtype=np.uint8)
    ends = (codes == 10) | (codes == 13)
    ends[:-1] &= ~((codes[:-1] == 13) & (codes[1:] == 10))  # CR LF: the LF ends the line
    return int(np.flatnonzero(ends)[k - 1]) + 1


def measure(path: Path, encoding: str = "utf-8-sig", skip: int = 0) -> Extent:
    """One pass over the text of ``path`` (decompressed, as UTF-8), a block at a time, kept nowhere:
    its size, where line ``skip + 1`` starts, where the last line holding anything ends, a last line
    without a line end, the first NUL byte."""
    size = lines = 0
    start = 0 if skip == 0 else None
    last_end = 0  # just past the last line end
    content_end = content_start = content_before = 0  # the last non-blank byte: past it, its line's start, line ends before it
    nul_line = None
    pending_cr = False
    with open_text_bytes(path, encoding) as handle:
        while block := handle.read(BLOCK_BYTES):
            joined = int(pending_cr and block[:1] == b"\n")  # a CR LF split by the blocks: one line end
            if joined and start == size:
                start += 1
            count = line_ends(block) - joined
            if start is None and lines + count >= skip:
                start = size + _after_line_end(block, skip - lines + joined)
            stripped = len(block.rstrip())
            if stripped:
                at = max(block.rfind(b"\n", 0, stripped), block.rfind(b"\r", 0, stripped))
                content_end, content_before = size + stripped, lines + line_ends(block, 0, stripped) - joined
                content_start = size + at + 1 if at >= 0 else last_end
            if nul_line is None and (at := block.find(b"\0")) >= 0:
                nul_line = lines + line_ends(block, 0, at) - (joined if at else 0) + 1
            at = max(block.rfind(b"\n"), block.rfind(b"\r"))
            if at >= 0:
                last_end = size + at + 1
            lines += count
            pending_cr = block.endswith(b"\r")
            size += len(block)
    start = size if start is None else start
    if content_end > last_end:  # the last line holding anything has no line end
        return Extent(size, start, max(content_start, start), content_before, content_before + 1, nul_line)
    return Extent(size, start, max(content_end, start), content_before + 1 if content_end else 0, None, nul_line)


class Snapshot(io.RawIOBase):
    """Bytes ``start`` to ``end`` of the binary stream ``stream`` (wrap it in :class:`io.BufferedReader`)."""

    def __init__(self, stream: BinaryIO, start: int, end: int) -> None:
        super().__init__()
        self.stream, self.skip, self.left = stream, start, end - start

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: Any) -> int:
        while self.skip > 0 and (dropped := len(self.stream.read(min(self.skip, BLOCK_BYTES)))):
            self.skip -= dropped
        view = memoryview(buffer).cast("B")[: max(0, self.left)]
        data = self.stream.read(len(view)) if len(view) else b""
        view[: len(data)] = data
        self.left -= len(data)
        return len(data)


def parse_bytes(text: str, name: str = MEMORY_VARIABLE) -> int:
    """A size in bytes: ``2000000000``, ``2e9``, ``512M``, ``8G``, ``1.5GiB`` (powers of 1024).

    >>> parse_bytes("8G"), parse_bytes("1e6"), parse_bytes("512 MiB")
    (8589934592, 1000000, 536870912)
    """
    match = _SIZE.fullmatch(text.strip())
    if match is None or float(match.group(1)) <= 0:
        raise ValueError(f"{name} must be a number of bytes > 0, such as 2000000000, 512M or 8G; got {text!r}")
    return int(float(match.group(1)) * 1024 ** " KMGT".index(match.group(2).upper() or " "))


def _first_number(path: str, field: int = 0) -> int | None:
    try:
        with open(path) as handle:
            return int(handle.read().split()[field])
    except (OSError, ValueError, IndexError):
        return None


def _available_memory() -> int | None:
    """``MemAvailable`` (Linux), else the free physical pages; less a cgroup's room when smaller."""
    available = None
    try:
        with open("/proc/meminfo") as handle:
            for line in handle:
                if line.startswith("MemAvailable:"):
                    available = int(line.split()[1]) * 1024
                    break
    except (OSError, ValueError):
        pass
    if available is None:
        try:
            available = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (AttributeError, OSError, ValueError):
            return None
    cap, used = _first_number("/sys/fs/cgroup/memory.max"), _first_number("/sys/fs/cgroup/memory.current")
    if cap is not None and used is not None:
        available = min(available, max(cap - used, 0))
    return available


def _address_space_room() -> int | None:
    """What ``RLIMIT_AS`` and ``RLIMIT_DATA`` leave of this process's address space, if they are set."""
    try:
        import resource
    except ImportError:  # not a POSIX system
        return None
    page = os.sysconf("SC_PAGE_SIZE") if hasattr(os, "sysconf") else 4096
    rooms = []
    for limit, field in ((resource.RLIMIT_AS, 0), (getattr(resource, "RLIMIT_DATA", None), 5)):
        if limit is None:
            continue
        soft = resource.getrlimit(limit)[0]
        used = _first_number("/proc/self/statm", field)
        if soft != resource.RLIM_INFINITY and used is not None:
            rooms.append(max(soft - used * page, 0))
    return min(rooms) if rooms else None


class MemoryLimit(NamedTuple):
    """The bytes a reader may allocate for a file's data, and what that limit is (for messages)."""

    size: int
    meaning: str


def memory_limit() -> MemoryLimit:
    """The bytes a reader may allocate for a file's data, and what that limit is (for messages)."""
    text = os.environ.get(MEMORY_VARIABLE, "").strip()
    if text:
        return MemoryLimit(parse_bytes(text), f"the limit set by {MEMORY_VARIABLE}={text}; raise it to read the file")
    known = [room for room in (_available_memory(), _address_space_room()) if room is not None]
    if not known:
        return MemoryLimit(sys.maxsize, "no limit")
    return MemoryLimit(min(known), f"the memory available to this process; set {MEMORY_VARIABLE} (bytes, e.g. 16G) "
                                   "to try anyway")


def format_bytes(size: float) -> str:
    """``1.5 GiB``, ``12 MiB``, ``800 bytes``.

    >>> format_bytes(3 * 2**29), format_bytes(800)
    ('1.5 GiB', '800 bytes')
    """
    for unit, scale in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if size >= scale:
            return f"{size / scale:.3g} {unit}"
    return f"{int(size)} bytes"


def check_memory(path: Path, needed: int, what: str) -> None:
    """A ValueError naming ``path``, the size and the limit when ``needed`` bytes exceed :func:`memory_limit`."""
    limit = memory_limit()
    if needed > limit.size:
        raise ValueError(f"{path}: {what} would take {format_bytes(needed)} of memory, more than "
                         f"{format_bytes(limit.size)} ({limit.meaning})")


def progress_enabled(progress: bool | None, values: float) -> bool:
    """A bar when asked, or by default when stderr is a terminal and the input is large.

    >>> progress_enabled(True, 10), progress_enabled(False, 1e9)
    (True, False)
    """
    if progress is not None:
        return bool(progress)
    return values > PROGRESS_VALUES and sys.stderr.isatty()


class CountingReader:
    """A binary file whose reads advance a tqdm bar by the bytes read (pandas reads it in blocks)."""

    def __init__(self, raw, bar) -> None:
        self.raw, self.bar = raw, bar

    def read(self, size: int = -1) -> bytes:
        chunk = self.raw.read(size)
        self.bar.update(len(chunk))
        return chunk

    def __iter__(self):
        return iter(self.raw)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.raw, name)
