"""Where numba keeps the compiled kernels: next to the package, else the user's cache.

numba compiles each kernel on first use and, with ``cache=True``, stores the machine
code in ``__pycache__`` beside the source, so later runs load it in milliseconds. An
installed package is often read-only (a system or shared site-packages); then the
kernels go to a per-user directory instead: ``$XDG_CACHE_HOME/avar/numba``, else
``~/.cache/avar/numba``. :func:`configure` sets ``NUMBA_CACHE_DIR`` to it before
numba loads (:mod:`avar._kernels` calls it first), and only when the user has not set
``NUMBA_CACHE_DIR`` (their choice always wins) and the package folder is not writable.
"""

from __future__ import annotations

import os
import sys
import tempfile
from collections.abc import MutableMapping
from pathlib import Path

__all__ = ["cached_for_this_machine", "choose_cache_dir", "configure", "user_cache_dir", "writable"]

#: The package of the kernels: numba uses the ``__pycache__`` of each of its folders by default.
KERNELS = Path(__file__).resolve().parents[1]


def user_cache_dir(environ: MutableMapping[str, str] = os.environ) -> Path:
    """``$XDG_CACHE_HOME/avar/numba``, else ``~/.cache/avar/numba`` (XDG base directories).

    >>> str(user_cache_dir({"XDG_CACHE_HOME": "/tmp/c"})).replace(os.sep, "/")
    '/tmp/c/avar/numba'
    """
    base = environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "avar" / "numba"


def writable(folder: Path) -> bool:
    """Whether numba can write its cache to ``__pycache__`` in ``folder`` and in each of its
    package folders (created when missing).

    The test is the one that matters: creating the folder and a file in it (file modes
    alone do not tell, e.g. for root, on a read-only mount or with ACLs).
    """
    folders = [Path(folder), *(init.parent for init in Path(folder).glob("*/__init__.py"))]
    for each in folders:
        cache = each / "__pycache__"
        try:
            cache.mkdir(exist_ok=True)
            with tempfile.TemporaryFile(dir=cache):
                pass
        except OSError:
            return False
    return True


def choose_cache_dir(folder: Path = KERNELS, environ: MutableMapping[str, str] = os.environ) -> Path | None:
    """The ``NUMBA_CACHE_DIR`` to set, or None: the user set one, or ``folder`` is writable.

    >>> choose_cache_dir(environ={"NUMBA_CACHE_DIR": "/mine"}) is None
    True
    """
    if environ.get("NUMBA_CACHE_DIR"):
        return None
    return None if writable(folder) else user_cache_dir(environ)


def configure(folder: Path = KERNELS, environ: MutableMapping[str, str] = os.environ) -> Path | None:
    """Point numba's cache at the user's cache directory when ``folder`` is not writable.

    Sets ``NUMBA_CACHE_DIR`` (read by numba when it loads, and inherited by worker
    processes) and, when numba is already loaded, its ``config.CACHE_DIR`` (read when
    a kernel is defined). Returns the directory chosen, or None when nothing changed.
    """
    chosen = choose_cache_dir(folder, environ)
    if chosen is None:
        return None
    environ["NUMBA_CACHE_DIR"] = str(chosen)
    config = sys.modules.get("numba.core.config")
    if config is not None and environ is os.environ:
        config.CACHE_DIR = str(chosen)
    return chosen


def cached_for_this_machine(dispatcher, first=None) -> bool:
    """Whether numba's cache holds code of ``dispatcher`` compiled for this CPU and source
    (with ``first``, a numba type, as the type of its first argument).

    Reads the kernel's cache index (numba returns it empty when missing or stale) and
    looks for an entry whose code-generation key (CPU name and features) is this
    machine's. Never compiles; False when numba's cache layout is not the expected one.
    """
    try:
        magic = dispatcher.targetctx.codegen().magic_tuple()
        return any(key[1] == magic and (first is None or key[0][0] == first)
                   for key in dispatcher._cache._cache_file._load_index())
    except Exception:  # numba internals changed: assume nothing is cached
        return False
