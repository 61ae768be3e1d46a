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

import io
import os
import sys
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from avar.cli.common import UsageError

__all__ = ["OutputPlan", "Written", "figure_formats", "plan_outputs", "report"]

STDOUT = "-"
#: Formats that need more than matplotlib (a LaTeX installation) are not offered.
EXCLUDED_FORMATS = frozenset({"pgf"})

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


def check_output_path(option: str, text: str, inputs: Sequence[Path], force: bool) -> Path:
    if not text:
        raise UsageError(f"{option} needs a file name")
    path = Path(text)
    if path.is_dir():
        raise UsageError(f"{option} {text!r} is a directory; give a file name, e.g. {path / 'out'}")
    folder = path.parent
    if not folder.is_dir():
        raise UsageError(f"{option} {text!r}: the folder {str(folder)!r} does not exist")
    for source in inputs:
        if _same_file(path, source):
            raise UsageError(f"{option} {text!r} is the input file; the input is never overwritten "
                             "(choose another name)")
    if path.exists() and not force:
        raise UsageError(f"{option} {text!r} exists; pass --force to replace it, or choose another name")
    return path


@dataclass(frozen=True)
class Written:
    """What :meth:`OutputPlan.write` did: the files written and the CSV text for stdout."""

    files: tuple[str, ...]
    stdout_csv: str | None


@dataclass(frozen=True)
class OutputPlan:
    """Checked output paths: ``csv`` (None, a path, or ``"-"`` = stdout) and ``figure``."""

    csv: Path | str | None
    figure: Path | None
    figure_format: str | None

    def write(self, csv: Callable[[], str] | None = None, figure: Callable[[], object] | None = None,
              metadata: dict[str, str] | None = None) -> Written:
        """Render the outputs in memory, then write each to a temporary file and rename it.

        ``csv`` returns the CSV text and ``figure`` a matplotlib Figure; each is
        called only if its output was requested. ``metadata`` goes into the figure
        file (PNG text chunks, PDF/SVG metadata) as matplotlib's ``savefig`` writes it.
        """
        contents: list[tuple[Path, bytes]] = []
        stdout_csv = None
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
        for path, data in contents:
            write_atomically(path, data)
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
            got = f"extension {figure_path.suffix!r}" if figure_format else "no extension"
            raise UsageError(f"{figure_option} {figure!r} has {got}; name a figure format by its "
                             f"extension: {', '.join(formats)} (e.g. {figure_path.stem or 'figure'}.png)")
        if isinstance(csv_path, Path) and _same_file(csv_path, figure_path):
            raise UsageError(f"{csv_option} and {figure_option} are the same file {figure!r}; "
                             "give them different names")
    return OutputPlan(csv_path, figure_path, figure_format)


def _mode() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask


def write_atomically(path: Path, data: bytes) -> None:
    """Write ``data`` to a temporary file next to ``path``, then rename it to ``path``."""
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".part")
    PENDING.add(temporary)
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        os.chmod(temporary, _mode())
        os.replace(temporary, path)
    finally:
        PENDING.discard(temporary)
        if os.path.exists(temporary):
            os.unlink(temporary)


def report(written: Written, text: str) -> None:
    """Print ``text`` (the table) and a line per written file, after the files are written.

    With ``--output -`` stdout holds the CSV alone: ``text`` is left out and the
    file lines go to stderr.
    """
    if written.stdout_csv is not None:
        sys.stdout.write(written.stdout_csv)
        sys.stdout.flush()
        for name in written.files:
            print(f"Wrote {name}", file=sys.stderr)
        return
    print(text)
    for name in written.files:
        print(f"Wrote {name}")
    sys.stdout.flush()


def remove_pending() -> None:
    """Remove temporary files of an interrupted write."""
    for temporary in list(PENDING):
        try:
            os.unlink(temporary)
        except OSError:
            pass
        PENDING.discard(temporary)
