"""Out-of-core and distributed Allan variance with Dask (support code).

* :func:`allan_variance_dask`: one long series (or several columns) held as a
  ``dask.array`` chunked along time. Every (chunk, level) task computes the
  sum of squared differences whose *first* window starts in its chunk, from
  the chunk plus the halo of ``2 m - 1`` following samples that level needs
  (dask slicing reads only the chunks that overlap); the driver adds the sums
  in a fixed order, so the result does not depend on the scheduler or on
  which worker ran what.
* :func:`allan_variance_files`: many independent series (files) on a
  ``dask.distributed`` cluster, with a progress bar on a terminal; built on
  :func:`map_on_cluster` (any picklable function of each file, one task per
  file: what ``avar compute FILE... --workers N`` runs).

Dask is imported inside the functions: this module imports without it.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from typing import Any

import numpy as np

from avar._kernels import streaming_allan_variance as allan_variance_columns


def _windows(n: int, bounds: list[tuple[int, int]], m: int, type: str):
    """(chunk, start, stop, n_differences) of the sub-series each chunk owns at level m."""
    for i, (lo, hi) in enumerate(bounds):
        if type == "mo":
            last = min(hi, n - 2 * m + 1)  # differences t in [lo, last)
            if last > lo:
                yield i, lo, last - 1 + 2 * m, last - lo
        else:
            first = -(-lo // m) * m
            stop_b = min(hi, (n // m - 1) * m)  # window starts b = k m in [first, stop_b)
            if stop_b > first:
                count = (stop_b - first + m - 1) // m
                yield i, first, first + (count + 1) * m, count


def _partial_sum(block: np.ndarray, m: int, type: str, count: int) -> np.ndarray:
    """Sum of D**2 / m**2 ... as the kernel's AV times its normalisation (per column)."""
    av = allan_variance_columns(block, np.array([m], dtype=np.int64), type)[:, 0]
    return av * (2.0 * count)


def allan_variance_dask(array: Any, factors: Any, type: str = "mo") -> np.ndarray:
    """Allan variance of a 1-D or 2-D ``dask.array`` (time along axis 0), shape (C, L).

    Computed on whatever dask scheduler is active (threads, processes or a
    ``distributed.Client``). The NumPy path and this one agree to ~1e-15
    relative: each partial sum is the streaming kernel's exact result on a
    sub-series, and the partial sums (all non-negative) are added in chunk
    order.
    """
    import dask
    import dask.array as da

    x = array if isinstance(array, da.Array) else da.from_array(np.asarray(array))
    if x.ndim == 1:
        x = x[:, None]
    factors = np.asarray(factors, dtype=np.int64).reshape(-1)
    n, channels = int(x.shape[0]), int(x.shape[1])
    edges = np.concatenate(([0], np.cumsum(x.chunks[0])))
    bounds = [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]
    tasks, owners = [], []
    for k, m in enumerate(map(int, factors)):
        if m < 1 or m > n // 2:
            continue
        for i, start, stop, count in _windows(n, bounds, m, type):
            part = dask.delayed(_partial_sum)(x[start:stop], m, type, count)
            tasks.append(part)
            owners.append((k, i, count))
    results = dask.compute(*tasks)
    sums = np.zeros((channels, factors.shape[0]))
    counts = np.zeros(factors.shape[0])
    for (k, _, count), value in sorted(zip(owners, results), key=lambda item: item[0][:2]):
        sums[:, k] += value
        counts[k] += count
    with np.errstate(invalid="ignore", divide="ignore"):
        out = sums / (2.0 * counts)
    out[:, counts == 0] = np.nan
    return out


def _one_file(path: Any, reader: Callable[[Any], Any], factors_fn: Callable[[int], Any], type: str):
    data = np.asarray(reader(path))
    factors = np.asarray(factors_fn(data.shape[0]), dtype=np.int64)
    return factors, allan_variance_columns(data, factors, type)


def allan_variance_files(
    paths: Iterable[Any],
    reader: Callable[[Any], Any],
    factors_fn: Callable[[int], Any],
    type: str = "mo",
    scheduler: Any = None,
    workers: int = 2,
    progress: bool | None = None,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Allan variance of many independent series on a ``dask.distributed`` cluster.

    ``reader(path)`` returns an (N,) or (N, C) array (read on the worker, e.g.
    ``np.load(p, mmap_mode="r")``); ``factors_fn(N)`` the cluster sizes.
    ``scheduler``: a ``distributed.Client``, a scheduler address, or None for
    a ``LocalCluster`` of ``workers`` single-threaded worker processes (closed
    afterwards). A tqdm progress bar goes to stderr when it is a terminal
    (``progress`` forces it on or off). Returns ``(factors, allan (C, L))`` per
    path, in the order of ``paths``.
    """
    return map_on_cluster(_one_file, paths, reader, factors_fn, type, scheduler=scheduler, workers=workers,
                          progress=progress, unit="series")


@contextmanager
def cluster_client(scheduler: Any = None, workers: int = 2, timeout: float | None = None) -> Iterator[Any]:
    """A ``distributed.Client``: ``scheduler`` itself (a Client, left open), one connected to an address
    (closed afterwards), or one of a new ``LocalCluster`` of ``workers`` single-threaded worker
    processes (both closed afterwards). ``timeout``: seconds to wait for a scheduler at an address."""
    from dask.distributed import Client, LocalCluster

    if scheduler is None:
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
            with Client(cluster) as client:
                yield client
    elif isinstance(scheduler, str):
        options = {} if timeout is None else {"timeout": timeout}
        with Client(scheduler, **options) as client:
            yield client
    else:
        yield scheduler


def map_on_cluster(
    function: Callable[..., Any],
    items: Iterable[Any],
    *args: Any,
    scheduler: Any = None,
    workers: int = 2,
    progress: bool | None = None,
    unit: str = "file",
    timeout: float | None = None,
) -> list[Any]:
    """``[function(item, *args) for item in items]``, one task per item on a ``dask.distributed`` cluster.

    ``function`` must be picklable (a module-level function) and should return a small
    result: every result travels back to this process. ``scheduler`` and ``workers`` as in
    :func:`allan_variance_files` (``timeout``: see :func:`cluster_client`). The results come
    back in the order of ``items``; the first task to fail raises its error here, and the
    remaining tasks are cancelled. A tqdm bar counts finished tasks on stderr when it is a
    terminal (``progress`` forces it on or off).
    """
    from dask.distributed import as_completed

    items = list(items)
    show = sys.stderr.isatty() if progress is None else progress
    with cluster_client(scheduler, workers, timeout) as client:
        futures = [client.submit(function, item, *args, pure=False) for item in items]
        bar = None
        if show:
            from tqdm import tqdm

            bar = tqdm(total=len(futures), desc="computing", file=sys.stderr, unit=unit)
        try:
            for future in as_completed(futures):
                if future.status == "error":
                    future.result()  # raises the task's error
                if bar is not None:
                    bar.update(1)
            return client.gather(futures)
        finally:
            if bar is not None:
                bar.close()
            client.cancel([future for future in futures if not future.done()])
