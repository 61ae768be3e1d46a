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

import logging
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


#: Least samples per chunk of the chunk-by-chunk path: finer input chunks are merged (rechunked),
#: so that the graph holds at most about N / MIN_CHUNK tasks per level.
MIN_CHUNK = 1 << 22
#: Most (chunk, level) tasks of one graph; a finer grid on a series larger than memory is refused.
MAX_TASKS = 200_000
#: A Dask array of at most this many bytes (and a quarter of the free memory) is computed into memory.
IN_MEMORY_BYTES = 1 << 30


def _free_memory() -> float:
    try:
        import os

        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return float("inf")


def fits_in_memory(x: Any) -> bool:
    """Whether the float64 copy of ``x`` fits comfortably in memory (<= :data:`IN_MEMORY_BYTES` and a
    quarter of the free memory): then it is computed once and the NumPy kernels run on it."""
    size = float(np.prod(x.shape)) * 8.0
    return size <= min(IN_MEMORY_BYTES, _free_memory() / 4.0)


def known_chunks(x: Any) -> Any:
    """``x`` with its chunk sizes known (a Dask array from e.g. boolean indexing has NaN sizes:
    they are computed, one pass over the data)."""
    if any(np.isnan(size) for sizes in x.chunks for size in sizes):
        x = x.compute_chunk_sizes()
    return x


def allan_variance_dask(array: Any, factors: Any, type: str = "mo", min_chunk: int | None = None) -> np.ndarray:
    """Allan variance of a 1-D or 2-D ``dask.array`` (time along axis 0), shape (C, L).

    Computed on whatever dask scheduler is active (threads, processes or a
    ``distributed.Client``). Chunks smaller than ``min_chunk`` samples (default
    :data:`MIN_CHUNK`) are
    merged first, so the graph is bounded whatever the input's chunks (at most
    :data:`MAX_TASKS` tasks). Data so large that the sums overflow are scaled by
    a power of two (exact) and computed again. The NumPy path and this one agree
    to ~1e-15 relative: each partial sum is the streaming kernel's exact result
    on a sub-series, and the partial sums (all non-negative) are added in chunk
    order.
    """
    import dask.array as da

    x = array if isinstance(array, da.Array) else da.from_array(np.asarray(array))
    if x.ndim == 1:
        x = x[:, None]
    x = known_chunks(x)
    min_chunk = MIN_CHUNK if min_chunk is None else min_chunk
    if min(x.chunks[0]) < min_chunk and len(x.chunks[0]) > 1:
        x = x.rechunk({0: max(min_chunk, max(x.chunks[0])), 1: -1})
    factors = np.asarray(factors, dtype=np.int64).reshape(-1)
    tasks = len(x.chunks[0]) * factors.size
    if tasks > MAX_TASKS:
        raise ValueError(f"taus: {factors.size} levels on {len(x.chunks[0])} chunks make {tasks} tasks, more than "
                         f"{MAX_TASKS}; give a coarser grid (taus='octave' or 'decade') for a series larger than memory")
    out = _allan_of_chunks(x, factors, type)
    valid = (factors >= 1) & (factors <= x.shape[0] // 2)
    if np.isfinite(out[:, valid]).all():
        return out
    if not bool(da.isfinite(x).all().compute()):
        raise ValueError("x (a Dask array) holds NaN or infinite values; fill or cut them, "
                         "or compute it and use nan_policy='omit'")
    big = float(da.max(abs(x)).compute())  # finite data whose sums overflow: scale by 2**-e and add 2e to AV's
    exponent = int(np.frexp(big)[1])
    out = _allan_of_chunks(x * 2.0 ** -exponent, factors, type)
    with np.errstate(over="ignore"):
        return out * 4.0 ** exponent


def _window_sum(blocks: list, offset: int, length: int, m: int, type: str, count: int) -> np.ndarray:
    """:func:`_partial_sum` of the ``length`` samples from ``offset`` in the joined ``blocks``."""
    joined = blocks[0] if len(blocks) == 1 else np.concatenate(blocks)
    return _partial_sum(np.ascontiguousarray(joined[offset : offset + length]), m, type, count)


def _allan_of_chunks(x: Any, factors: np.ndarray, type: str) -> np.ndarray:
    import dask

    n, channels = int(x.shape[0]), int(x.shape[1])
    edges = np.concatenate(([0], np.cumsum(x.chunks[0])))
    bounds = [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]
    blocks = list(x.to_delayed().ravel())  # one delayed block per chunk: a window joins the blocks it spans
    tasks, owners = [], []
    for k, m in enumerate(map(int, factors)):
        if m < 1 or m > n // 2:
            continue
        for i, start, stop, count in _windows(n, bounds, m, type):
            first = int(np.searchsorted(edges, start, side="right")) - 1
            last = int(np.searchsorted(edges, stop, side="left"))
            part = dask.delayed(_window_sum)(blocks[first:last], start - int(edges[first]), stop - start, m, type,
                                             count)
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


class WorkerLost(RuntimeError):
    """A task whose worker process died (killed, e.g. out of memory) as often as the scheduler allows."""


def _raise_task_error(future: Any, item: Any) -> None:
    """The task's own error, or :class:`WorkerLost` in one line when its worker kept dying."""
    from distributed import KilledWorker

    try:
        future.result()
    except KilledWorker:
        raise WorkerLost(f"the worker process computing {item} died repeatedly (killed by the system, e.g. out "
                         "of memory); compute it with fewer workers, or alone") from None


@contextmanager
def cluster_client(scheduler: Any = None, workers: int = 2, timeout: float | None = None) -> Iterator[Any]:
    """A ``distributed.Client``: ``scheduler`` itself (a Client, left open), one connected to an address
    (closed afterwards), or one of a new ``LocalCluster`` of ``workers`` single-threaded worker
    processes (both closed afterwards). ``timeout``: seconds to wait for a scheduler at an address."""
    from dask.distributed import Client, LocalCluster

    if scheduler is None:
        # ":0": the scheduler's HTTP server (dashboard, metrics) on a free port; None would still
        # take 8787 and warn when another cluster (another avar run) holds it.
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                          silence_logs=logging.CRITICAL) as cluster:
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
                    _raise_task_error(future, items[futures.index(future)])
                if bar is not None:
                    bar.update(1)
            return client.gather(futures)
        finally:
            if bar is not None:
                bar.close()
            client.cancel([future for future in futures if not future.done()])
