"""Writing an export: whole or not at all, never over the input, never over a link or a device."""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path
from typing import Any

__all__ = ["write_text"]


def write_text(text: str, path: Any, force: bool = False, source: Any = None, what: str = "export") -> Path:
    """Write ``text`` (UTF-8) to ``path`` through a temporary file in its folder and a rename; returns the path.

    A failure never leaves a half-written file; the mode follows the umask (0o666 & ~umask, as any
    file the user creates). An existing file is refused unless ``force=True``, and only a regular
    file is ever replaced (a directory, FIFO, device or symbolic link is refused). ``source`` (the
    input file) is never overwritten. Errors name ``path``, never the temporary file.
    """
    data = text.encode("utf-8")
    target = Path(path)
    try:
        info = os.lstat(target)
    except FileNotFoundError:
        info = None
    if info is not None and not stat.S_ISREG(info.st_mode):
        raise ValueError(f"path {str(target)!r} exists and is not a regular file (a directory, link, FIFO or "
                         "device); give a file name")
    if info is not None and not force:
        raise FileExistsError(f"{target} exists; pass force=True to overwrite it")
    if source is not None and target.resolve() == Path(source).resolve():
        raise ValueError(f"{target} is the input file; choose another path")
    umask = os.umask(0)
    os.umask(umask)
    temporary = None
    try:
        handle, temporary = tempfile.mkstemp(dir=target.parent if str(target.parent) else ".", prefix=".avar.",
                                             suffix=".part")
        with os.fdopen(handle, "wb") as out:
            out.write(data)
        os.chmod(temporary, 0o666 & ~umask)
        os.replace(temporary, target)
    except OSError as error:
        raise OSError(error.errno, f"{target}: cannot write the {what} ({error.strerror})") from None
    finally:
        if temporary is not None and os.path.exists(temporary):
            os.unlink(temporary)
    return target
