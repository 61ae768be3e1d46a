"""Parallel work without numba's parfors: compiled task kernels called from a few Python threads.

With ``parallel=True`` numba compiles every ``prange`` loop, and every array expression of
the function, into a gufunc of its own that links in the loop's whole body, and optimizes
it all once more: seconds of compilation per kernel, which every machine pays on its first
run. A task kernel here is a plain ``njit(nogil=True)`` function that does one task (a
column and a run of blocks, a residue class, ...) and writes its own slot of the output;
:func:`run_tasks` calls it for every task on up to ``numba.get_num_threads()`` threads
(the GIL is released while a task runs). Tasks are handed out one at a time, so a thread
slowed down by another process holds back no other thread, and each task's result goes to
its own slot: the caller adds them in a fixed order and the bits do not depend on the
number of threads. The first task runs in the calling thread, so a kernel compiles there
(the first-run notice of :mod:`avar.cli.first_run` looks at the compiling thread's name).
"""

from __future__ import annotations

import threading
from collections.abc import Callable

__all__ = ["run_tasks", "threads"]


def threads() -> int:
    """The number of threads numba may use (``NUMBA_NUM_THREADS``, ``numba.set_num_threads``)."""
    import numba

    return int(numba.get_num_threads())


def run_tasks(n_tasks: int, task: Callable[[int], object]) -> None:
    """Call ``task(i)`` for ``i in range(n_tasks)``, each once, on up to :func:`threads` threads.

    ``task`` calls a ``nogil`` kernel that writes its own part of the output. The first
    exception raised by a task is raised here, after every thread has stopped.

    >>> done = []
    >>> run_tasks(5, done.append)
    >>> sorted(done)
    [0, 1, 2, 3, 4]
    """
    n_tasks = int(n_tasks)
    if n_tasks <= 0:
        return
    task(0)  # compiles the kernel, if it must, in the calling thread
    workers = min(threads(), n_tasks - 1)
    if workers <= 1:
        for i in range(1, n_tasks):
            task(i)
        return
    lock = threading.Lock()
    state = {"next": 1, "error": None}

    def work() -> None:
        while True:
            with lock:
                i = state["next"]
                if i >= n_tasks or state["error"] is not None:
                    return
                state["next"] = i + 1
            try:
                task(i)
            except BaseException as error:  # handed to the calling thread
                with lock:
                    if state["error"] is None:
                        state["error"] = error
                return

    helpers = [threading.Thread(target=work, name="avar-kernel", daemon=True) for _ in range(workers - 1)]
    for helper in helpers:
        helper.start()
    work()
    for helper in helpers:
        helper.join()
    if state["error"] is not None:
        raise state["error"]
