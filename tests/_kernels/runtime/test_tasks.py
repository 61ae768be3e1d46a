"""The task threads of avar._kernels.runtime.tasks: every call runs once, results in order, errors reach the caller."""

from __future__ import annotations

import threading

import pytest

from avar._kernels.runtime.tasks import run_concurrently, run_tasks


def test_run_concurrently_returns_each_result_in_order_and_nests():
    thread_of = {}

    def inner(k: int):
        thread_of[k] = threading.current_thread().name
        return run_concurrently(*(lambda j=j: (k, j) for j in range(3)))

    results = run_concurrently(*(lambda k=k: inner(k) for k in range(4)))
    assert results == [[(k, j) for j in range(3)] for k in range(4)]
    assert sorted(thread_of) == [0, 1, 2, 3] and thread_of[0] == threading.current_thread().name  # the first: here


def test_an_error_in_any_call_reaches_the_caller_once_no_call_runs():
    running, finished = [0], []
    lock = threading.Lock()

    def slow():
        with lock:
            running[0] += 1
        threading.Event().wait(0.05)
        with lock:
            running[0] -= 1
            finished.append("slow")
        return 1

    def failing():
        raise RuntimeError("task 1 failed")

    with pytest.raises(RuntimeError, match="task 1 failed"):
        run_concurrently(slow, failing, slow, slow)
    assert running == [0] and 1 <= len(finished) <= 3  # none still running; those not started never start
    with pytest.raises(ZeroDivisionError):
        run_concurrently(lambda: 1 / 0, slow)


def test_run_tasks_calls_every_task_once():
    counts = [0] * 50
    lock = threading.Lock()

    def task(i: int) -> None:
        with lock:
            counts[i] += 1

    run_tasks(50, task)
    assert counts == [1] * 50


def test_a_warm_call_of_two_tasks_runs_them_side_by_side():
    """The first call of a task runs task 0 alone in the calling thread (a kernel compiles
    there); later calls of the same task code start the helpers at once, so two tasks overlap
    (each waits for the other to have started)."""
    numba = pytest.importorskip("numba")
    if numba.get_num_threads() < 2:
        pytest.skip("one thread")
    started = [threading.Event(), threading.Event()]
    overlapped = []

    def call() -> None:
        for event in started:
            event.clear()

        def task(i: int) -> None:
            started[i].set()
            overlapped.append(started[1 - i].wait(timeout=1.0))

        run_tasks(2, task)

    call()
    assert overlapped == [False, True]  # cold: task 0 alone, then task 1
    overlapped.clear()
    call()
    assert sorted(overlapped) == [True, True]
