"""The first run's notice: numba compiles the kernels once per machine, and the command says so.

The kernels are compiled on first use and stored in numba's cache (see
:mod:`avar._kernels.runtime.cache`); later runs load them in milliseconds. A cold cache
makes the first run several times slower, which a user would otherwise take for a
hang. The notice is printed once, on stderr, when numba actually starts compiling:
numba announces a ``"numba:compile"`` event exactly when a kernel is not found in its
cache (a cache hit loads the code without it), so the test is numba's own, for the
kernels and signatures this run uses, whatever the cache's location, CPU or version.
"""

from __future__ import annotations

import os
import sys
import threading
from contextlib import contextmanager

__all__ = ["COMPILE_SECONDS", "NOTICE_START", "QUIET_THREADS", "CompileNotice", "compile_notice", "notice_text"]

#: How the notice begins (a stable prefix for whoever filters stderr).
NOTICE_START = "avar: compiling the numerical kernels"
#: Threads whose compilations are speculative (``avar compute``'s warm-up while the file
#: is read) and do not make the run say it compiles.
QUIET_THREADS = frozenset({"avar-warm-up"})

#: Rough compile time of each subcommand's kernels on one idle core, seconds: the CPU time
#: of a cold run less a warm one in benchmarks/bench_cli_startup.py (demo 3.9 s, report of
#: a 2 h 200 Hz 6-axis log 3.7 s); compute and fit of a log beyond 2**22 samples also
#: compile the streaming sweep (about 5 s more).
COMPILE_SECONDS = {"demo": 5, "compute": 10, "fit": 10, "report": 5, "deviation": 15, "warmup": 120}


def notice_text(command: str) -> str:
    """The one line printed when the first kernel of ``command`` compiles.

    >>> print(notice_text("report"))  # doctest: +ELLIPSIS
    avar: compiling the numerical kernels for this machine (first run only; up to about 5 s); later runs load them ...
    """
    seconds = COMPILE_SECONDS.get(command, 10)
    where = os.environ.get("NUMBA_CACHE_DIR")
    later = f"later runs load them from {where}" if where else "later runs load them from numba's cache"
    return f"{NOTICE_START} for this machine (first run only; up to about {seconds} s); {later}"


class CompileNotice:
    """Prints :func:`notice_text` at the first compilation and counts the compilations."""

    def __init__(self, command: str, stream=None) -> None:
        self.command = command
        self.stream = stream
        self.compiled = 0  # kernels (signatures) compiled during the run
        self._lock = threading.Lock()

    def on_start(self, event) -> None:
        if threading.current_thread().name in QUIET_THREADS:
            return
        with self._lock:
            self.compiled += 1
            if self.compiled > 1:
                return
        print(notice_text(self.command), file=self.stream or sys.stderr, flush=True)

    def on_end(self, event) -> None:
        pass


@contextmanager
def compile_notice(command: str, stream=None):
    """Within the block, the first kernel numba compiles (a cache miss) prints the notice.

    >>> from numba import njit
    >>> import io
    >>> out = io.StringIO()
    >>> with compile_notice("demo", out) as notice:
    ...     twice = njit(lambda x: 2 * x)  # a new function: not in any cache
    ...     _ = twice(1.0), twice(2), twice(3.0)  # two signatures compiled, one notice
    >>> notice.compiled, out.getvalue().count("compiling")
    (2, 1)
    """
    from numba.core import event

    class Listener(CompileNotice, event.Listener):  # numba accepts its own Listener class only
        pass

    listener = Listener(command, stream)
    event.register("numba:compile", listener)
    try:
        yield listener
    finally:
        event.unregister("numba:compile", listener)
