"""Safe output files of the subcommands: checked first, written whole, never lost.

The rules (DESIGN.md, "Reading real data"):

* every output path is checked before anything is read or computed: it is not
  an input file, not another output, not a directory, its folder exists, a
  figure's extension names a format matplotlib writes, and an existing file is
  refused unless ``--force``;
* ``--output -`` sends the CSV table to stdout;
* the figure is rendered to bytes and the CSV to text in memory, then each is
  written to a temporary file in the target folder and renamed over the target
  (``os.replace``): a reader never sees half a file, and an interrupted run
  leaves the old file in place;
* all files are written before anything is printed, so a closed stdout pipe
  (``| head -1``) or Ctrl-C while printing cannot lose them.
"""

from __future__ import annotations

import errno
import io
import os
import stat
import sys
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from avar._escape import terminal_lines
from avar.cli.common import UsageError, display, printable

__all__ = ["OutputPlan", "Written", "csv_text", "figure_formats", "plan_outputs", "rename_no_replace", "report",
           "write_all", "write_atomically"]

STDOUT = "-"
#: Formats that need more than matplotlib (a LaTeX installation) are not offered.
EXCLUDED_FORMATS = frozenset({"pgf"})

#: Least free space (bytes) an output folder must have before the run computes.
MIN_FREE_BYTES = 1 << 16
#: Temporary files being written, removed if the run is interrupted.
PENDING: set[str] = set()


def figure_formats() -> list[str]:
    """File extensions matplotlib can write (``png``, ``pdf``, ``svg`` ...)."""
    from matplotlib.backend_bases import FigureCanvasBase

    return sorted(set(FigureCanvasBase.get_supported_filetypes()) - EXCLUDED_FORMATS)


def _same_file(a: Path, b: Path) -> bool:
    if a.exists() and b.exists():
        return os.path.samefile(a, b)
    return a.resolve() == b.resolve()


def _kind(path: Path) -> str | None:
    """What ``path`` is when it is not a regular file or a new name ("a FIFO", ...), else None."""
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        return None
    except OSError as error:
        return f"unreadable ({error.strerror})"
    if stat.S_ISREG(info.st_mode):
        return None
    if stat.S_ISLNK(info.st_mode):
        return f"a symbolic link (to {os.readlink(path)!r})"
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(info.st_mode):
            return name
    return "not a regular file"


def _name_limit(folder: Path) -> int:
    try:
        return int(os.pathconf(folder, "PC_NAME_MAX"))
    except (OSError, ValueError, AttributeError):
        return 255


def check_output_path(option: str, text: str, inputs: Sequence[Path], force: bool) -> Path:
    """The checked path of an output, or :class:`UsageError` (exit 2) before any work.

    Only a new name or a regular file (with ``force``) is accepted: a directory,
    FIFO, device, socket or symbolic link is refused even with ``--force`` (the
    run would replace the link or the node itself with a file). The folder must be
    writable and the name (and so the temporary name, whose length is bounded) not
    longer than the file system allows.
    """
    if not text:
        raise UsageError(f"{option} needs a file name")
    if text == STDOUT:
        raise UsageError(f"{option} writes a file; '-' (stdout) is not a file name here (give e.g. ./out)")
    path = Path(text)
    shown = display(text)
    limit = _name_limit(path.parent)
    if len(os.fsencode(path.name)) > limit:
        raise UsageError(f"{option}: the file name is {len(os.fsencode(path.name))} bytes long, more than the "
                         f"{limit} its folder allows; choose a shorter name")
    if path.is_dir() and not path.is_symlink():
        raise UsageError(f"{option} {shown} is a directory; give a file name, e.g. {display(str(path / 'out'))}")
    folder = path.parent
    if not folder.is_dir():
        raise UsageError(f"{option} {shown}: the folder {display(str(folder))} does not exist")
    for source in inputs:
        if _same_file(path, source):
            raise UsageError(f"{option} {shown} is the input file; the input is never overwritten "
                             "(choose another name)")
    kind = _kind(path)
    if kind is not None:
        raise UsageError(f"{option} {shown} is {kind}; only a regular file (or a new name) is written, "
                         "even with --force: give a file name")
    if os.path.lexists(path) and not force:
        raise UsageError(f"{option} {shown} exists; pass --force to replace it, or choose another name")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise UsageError(f"{option} {shown}: the folder {display(str(folder))} is not writable; "
                         "choose another folder")
    try:
        space = os.statvfs(folder)
    except (OSError, AttributeError):
        space = None
    if space is not None and space.f_bavail * space.f_frsize < MIN_FREE_BYTES:
        raise UsageError(f"{option} {shown}: the folder {display(str(folder))} has no free space left "
                         f"({space.f_bavail * space.f_frsize} bytes); free some or choose another folder")
    return path


@dataclass(frozen=True)
class Written:
    """What :meth:`OutputPlan.write` did: the files written and the CSV text for stdout."""

    files: tuple[str, ...]
    stdout_csv: str | None


@dataclass(frozen=True)
class OutputPlan:
    """Checked output paths: ``csv`` (None, a path, or ``"-"`` = stdout) and ``figure``.

    ``force``: an existing regular file may be replaced; without it the final
    rename refuses a file that appeared while the run computed.
    """

    csv: Path | str | None
    figure: Path | None
    figure_format: str | None
    force: bool = False

    def write(self, csv: Callable[[], str] | None = None, figure: Callable[[], object] | None = None,
              extra: Sequence[tuple[Path, Callable[[], bytes]]] = (),
              metadata: dict[str, str] | None = None) -> Written:
        """Render every output in memory, then write each to a temporary file and rename it.

        ``csv`` returns the CSV text and ``figure`` a matplotlib Figure; each is
        called only if its output was requested. ``extra``: (path, bytes) of
        further files (a Kalibr yaml). ``metadata`` goes into the figure file
        (PNG text chunks, PDF/SVG metadata) as matplotlib's ``savefig`` writes
        it. Nothing is written unless every output rendered.
        """
        contents: list[tuple[Path, bytes]] = []
        stdout_csv = None
        for path, render in extra:
            contents.append((path, render()))
        if self.csv is not None and csv is not None:
            text = csv()
            if self.csv == STDOUT:
                stdout_csv = text
            else:
                contents.append((Path(self.csv), text.encode("utf-8")))
        if self.figure is not None and figure is not None:
            buffer = io.BytesIO()
            figure().savefig(buffer, format=self.figure_format, dpi=110, metadata=metadata)
            contents.append((self.figure, buffer.getvalue()))
        write_all(contents, self.force)
        return Written(tuple(str(path) for path, _ in contents), stdout_csv)


def plan_outputs(
    csv: str | None = None, figure: str | None = None, inputs: Sequence[str] = (), force: bool = False,
    csv_option: str = "--output", figure_option: str = "--plot",
) -> OutputPlan:
    """Check the output paths before any work; raise :class:`UsageError` (exit 2) if one is unsafe.

    >>> plan_outputs(csv="-").csv
    '-'
    """
    sources = [Path(p) for p in inputs if p]
    csv_path: Path | str | None = None
    if csv is not None:
        csv_path = STDOUT if csv == STDOUT else check_output_path(csv_option, csv, sources, force)
    figure_path = figure_format = None
    if figure is not None:
        if figure == STDOUT:
            raise UsageError(f"{figure_option} writes a file; '-' (stdout) is only for {csv_option}")
        figure_path = check_output_path(figure_option, figure, sources, force)
        figure_format = figure_path.suffix[1:].lower()
        formats = figure_formats()
        if figure_format not in formats:
            got = f"extension {display(figure_path.suffix)}" if figure_format else "no extension"
            raise UsageError(f"{figure_option} {display(figure)} has {got}; name a figure format by its "
                             f"extension: {', '.join(formats)} (e.g. {printable(figure_path.stem or 'figure')}.png)")
        if isinstance(csv_path, Path) and _same_file(csv_path, figure_path):
            raise UsageError(f"{csv_option} and {figure_option} are the same file {display(figure)}; "
                             "give them different names")
    return OutputPlan(csv_path, figure_path, figure_format, force)


#: Formula triggers of spreadsheets (OWASP "CSV injection"): a text cell starting with one is prefixed by "'".
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def _defuse(value: object) -> object:
    if isinstance(value, str) and value.startswith(FORMULA_STARTS):
        return "'" + value
    return value


def csv_text(frame: Any, index: bool = False) -> str:
    """``frame.to_csv()`` with text cells and names that a spreadsheet would run as a formula
    (``=HYPERLINK(...)``, ``@SUM(...)``) prefixed by a single quote, as OWASP recommends;
    numbers (``-1.5``) stay numbers.

    >>> import pandas as pd
    >>> csv_text(pd.DataFrame({"=cmd()": ["-x", "a"], "v": [-1.5, 2.0]})).splitlines()
    ["'=cmd(),v", "'-x,-1.5", 'a,2.0']
    """
    frame = frame.rename(columns=_defuse)
    if index:
        frame = frame.rename(index=_defuse)
        frame.index.names = [_defuse(name) for name in frame.index.names]
    for name in frame.columns:
        if frame[name].dtype.kind in "OSU" or str(frame[name].dtype) == "str":
            frame[name] = frame[name].map(_defuse)
    return frame.to_csv(index=index)


def _mode() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def _stage(path: Path, data: bytes) -> str:
    """``data`` in a new temporary file next to ``path`` (mode by the umask); its name.

    The temporary name is short whatever ``path``'s length (``.`` + at most 40
    characters of the name + 8 random + ``.part``), and errors name ``path``.
    """
    try:
        handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name[:40]}.", suffix=".part")
    except OSError as error:
        raise OSError(error.errno, f"{path}: cannot write ({error.strerror})") from None
    PENDING.add(temporary)
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        os.chmod(temporary, _mode())
    except OSError as error:
        _discard(temporary)
        raise OSError(error.errno, f"{path}: cannot write ({error.strerror})") from None
    return temporary


def _discard(temporary: str) -> None:
    PENDING.discard(temporary)
    try:
        os.unlink(temporary)
    except OSError:
        pass


_RENAME_NOREPLACE = 1
_AT_FDCWD = -100


def _renameat2(source: str, target: Path) -> bool:
    """``renameat2(RENAME_NOREPLACE)`` through ctypes: True if done, False if the system lacks it;
    FileExistsError if ``target`` exists."""
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        function = libc.renameat2
    except (OSError, AttributeError):
        return False
    function.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    if function(_AT_FDCWD, os.fsencode(source), _AT_FDCWD, os.fsencode(str(target)), _RENAME_NOREPLACE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise OSError(code, os.strerror(code), str(target))


def rename_no_replace(source: str, target: Path) -> None:
    """Rename ``source`` to ``target`` only if ``target`` does not exist, atomically.

    ``renameat2(RENAME_NOREPLACE)`` where the system has it, else a hard link
    (which fails on an existing name) and the unlink of ``source``; raises
    FileExistsError when another program created ``target`` meanwhile.
    """
    if _renameat2(source, target):
        return
    try:
        os.link(source, target)
    except FileExistsError:
        raise
    except OSError:  # no hard links on this file system: the closest check
        if os.path.lexists(target):
            raise FileExistsError(errno.EEXIST, "File exists", str(target)) from None
        os.replace(source, target)
        return
    os.unlink(source)


class OutputRace(UsageError):
    """An output that did not exist when checked was created by another program meanwhile."""


def write_all(contents: Sequence[tuple[Path, bytes]], force: bool = False) -> None:
    """Write every (path, data) atomically: all staged first, then each renamed into place.

    Without ``force`` an output created meanwhile by another run is never
    replaced: the rename refuses it (:func:`rename_no_replace`), the outputs this
    run had already put in place are removed again and :class:`OutputRace` is
    raised. With ``force`` only a regular file is replaced.
    """
    staged = []
    try:
        for path, data in contents:
            staged.append((path, _stage(path, data)))
        done: list[Path] = []
        for path, temporary in staged:
            try:
                if force:
                    kind = _kind(path)
                    if kind is not None:
                        raise OutputRace(f"{display(str(path))} became {kind} while the run computed; "
                                         "it is left as it is")
                    os.replace(temporary, path)
                else:
                    rename_no_replace(temporary, path)
            except FileExistsError:
                for written in done:
                    if not force:
                        _unlink_quietly(written)
                raise OutputRace(f"{display(str(path))} was created by another program while this run computed; "
                                 "it is left as it is and nothing was written (pass --force to replace it)") from None
            except OSError as error:
                raise OSError(error.errno, f"{path}: cannot write ({error.strerror})") from None
            PENDING.discard(temporary)
            done.append(path)
    finally:
        for _, temporary in staged:
            if temporary in PENDING or os.path.exists(temporary):
                _discard(temporary)


def _unlink_quietly(path: Path) -> None:
    try:
        os.unlink(path)
    except OSError:
        pass


def write_atomically(path: Path, data: bytes, force: bool = True) -> None:
    """Write ``data`` to a temporary file next to ``path``, then rename it to ``path``
    (replacing a regular file only with ``force``)."""
    write_all([(path, data)], force)


def report(written: Written, text: str) -> None:
    """Print ``text`` (the table; control characters escaped, line breaks kept) and a line per
    written file, after the files are written.

    With ``--output -`` stdout holds the CSV alone: ``text`` is left out and the
    file lines go to stderr.
    """
    if written.stdout_csv is not None:
        sys.stdout.write(written.stdout_csv)
        sys.stdout.flush()
        for name in written.files:
            print(f"Wrote {printable(name)}", file=sys.stderr)
        return
    print(terminal_lines(text))  # names in it are escaped where formatted; this is the net for the rest
    for name in written.files:
        print(f"Wrote {printable(name)}")
    sys.stdout.flush()


def remove_pending() -> None:
    """Remove temporary files of an interrupted write."""
    for temporary in list(PENDING):
        try:
            os.unlink(temporary)
        except OSError:
            pass
        PENDING.discard(temporary)
