"""Progress bars for long reads: on stderr, only when it is a terminal and the input is large."""

from __future__ import annotations

import sys
from typing import Any

#: Inputs with more values than this show a progress bar on a terminal.
PROGRESS_VALUES = 10_000_000


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
