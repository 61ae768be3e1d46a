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
(the first-run notice of :mod:`avar.cli.first_run` looks at the compiling thread's name),
and the calling thread works on the tasks too. The helper threads are started once and
wait for work in between (starting threads on every call would cost more than a short
call's work).
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable

__all__ = ["run_concurrently", "run_ranges", "run_tasks", "threads"]

#: Jobs for the helper threads: each takes tasks of one :func:`run_tasks` call until none is left.
_JOBS: queue.SimpleQueue = queue.SimpleQueue()
_HELPERS: list[threading.Thread] = []
_START = threading.Lock()


def threads() -> int:
    """The number of threads numba may use (``NUMBA_NUM_THREADS``, ``numba.set_num_threads``)."""
    import numba

    return int(numba.get_num_threads())


def _helper() -> None:
    while True:
        _JOBS.get()()


def _ensure_helpers(count: int) -> None:
    with _START:
        while len(_HELPERS) < count:
            helper = threading.Thread(target=_helper, name=f"avar-kernel-{len(_HELPERS) + 1}", daemon=True)
            helper.start()
            _HELPERS.append(helper)


class _Call:
    """The tasks of one :func:`run_tasks` call, handed out one at a time."""

    def __init__(self, n_tasks: int, task: Callable[[int], object]) -> None:
        self.n_tasks = n_tasks
        self.task = task
        self.next = 1  # task 0 ran in the calling thread
        self.busy = 0  # tasks taken and not finished
        self.error: BaseException | None = None
        self.changed = threading.Condition()

    def work(self) -> None:
        while True:
            with self.changed:
                if self.next >= self.n_tasks or self.error is not None:
                    return
                i = self.next
                self.next += 1
                self.busy += 1
            try:
                self.task(i)
            except BaseException as error:  # noqa: BLE001 - handed to the calling thread
                with self.changed:
                    self.error = self.error or error
            finally:
                with self.changed:
                    self.busy -= 1
                    self.changed.notify_all()

    def wait(self) -> None:
        with self.changed:
            while self.busy:
                self.changed.wait()
        if self.error is not None:
            raise self.error


#: The code of the tasks whose first call ran (so compiled their kernels) in the calling thread:
#: later calls start the helpers at once rather than after task 0 (else a call of two tasks
#: runs them one after the other).
_WARM: set = set()


def run_tasks(n_tasks: int, task: Callable[[int], object]) -> None:
    """Call ``task(i)`` for ``i in range(n_tasks)``, each once, on up to :func:`threads` threads.

    ``task`` calls a ``nogil`` kernel that writes its own part of the output. The first
    exception raised by a task is raised here, once no task is running any more.

    >>> done = []
    >>> run_tasks(5, done.append)
    >>> sorted(done)
    [0, 1, 2, 3, 4]
    """
    n_tasks = int(n_tasks)
    if n_tasks <= 0:
        return
    code = getattr(task, "__code__", None)
    first = 0 if code in _WARM else 1  # warm: the helpers start at once (two tasks run side by side)
    if first:
        task(0)  # compiles the kernel, if it must, in the calling thread
        if code is not None:
            _WARM.add(code)
    helpers = min(threads(), n_tasks - first) - 1
    if helpers <= 0:
        for i in range(first, n_tasks):
            task(i)
        return
    call = _Call(n_tasks, task)
    call.next = first
    _ensure_helpers(helpers)
    for _ in range(helpers):
        _JOBS.put(call.work)
    call.work()
    call.wait()


#: Parts per thread of :func:`run_ranges` (more parts balance uneven items better).
PARTS_PER_THREAD = 4


def run_ranges(n_items: int, work: Callable[[int, int], object]) -> None:
    """Call ``work(first, stop)`` on consecutive ranges covering ``range(n_items)``, on the threads.

    For many small independent items (each writes its own slot): one kernel call per
    range rather than per item. The ranges depend on the thread count, so ``work`` must
    not make an item's result depend on its range.

    >>> seen = []
    >>> run_ranges(10, lambda first, stop: seen.extend(range(first, stop)))
    >>> sorted(seen) == list(range(10))
    True
    """
    n_items = int(n_items)
    parts = max(1, min(n_items, PARTS_PER_THREAD * threads()))
    bounds = [n_items * p // parts for p in range(parts + 1)]
    run_tasks(parts, lambda p: work(bounds[p], bounds[p + 1]))


def run_concurrently(*calls: Callable[[], object]) -> list:
    """Call each of ``calls`` once, at the same time on up to :func:`threads` threads; their results in order.

    For a few unequal, independent pieces of work (FFT products, ``nogil`` kernels) rather than
    many like ones. The first runs in the calling thread, which then takes the others still
    waiting; each result is computed as it would be alone, so the bits do not depend on the
    number of threads. Calls may nest: a calling thread never waits for work it could do. The
    first exception a call raises is raised here once no call is running; the calls not
    started by then are not started.

    >>> run_concurrently(lambda: 1 + 1, lambda: "b", lambda: None)
    [2, 'b', None]
    """
    results: list = [None] * len(calls)

    def task(i: int) -> None:
        results[i] = calls[i]()

    helpers = min(threads(), len(calls)) - 1
    if helpers <= 0:
        for i in range(len(calls)):
            task(i)
        return results
    call = _Call(len(calls), task)
    _ensure_helpers(helpers)
    for _ in range(helpers):
        _JOBS.put(call.work)
    try:
        task(0)
    finally:
        call.work()
        call.wait()
    return results
